// Real polynomials for the models whose projection is a polynomial in an angle
// or a radius (Kannala-Brandt, OCamCalib): evaluation, the first point of an
// interval where a polynomial stops being positive (where a projection folds),
// and a safeguarded Newton solve of a monotone function (its inverse).
//
// p(x) = c[0] + c[1] x + ... + c[n-1] x^(n-1).
#pragma once

#include <algorithm>
#include <cmath>

namespace sphera {
namespace internal {

// Highest number of coefficients the root isolation handles (degree 9).
constexpr int kMaxPolynomialCoeffs = 10;

template <typename T>
T EvaluatePolynomial(const T* coeffs, int num_coeffs, const T& x) {
  T value(0);
  for (int i = num_coeffs - 1; i >= 0; --i) value = value * x + coeffs[i];
  return value;
}

// Bisection of a polynomial that is monotone on [lo, hi] and changes sign
// there (p(lo) and p(hi) of opposite signs, neither zero). Returns the end of
// the final bracket on hi's side, so p(result) has p(hi)'s sign.
inline double BisectSignChange(const double* coeffs, int num_coeffs, double lo,
                               double hi) {
  const bool lo_negative = EvaluatePolynomial(coeffs, num_coeffs, lo) < 0;
  for (int i = 0; i < 2000; ++i) {
    const double mid = lo + 0.5 * (hi - lo);
    if (!(mid > lo && mid < hi)) break;
    if ((EvaluatePolynomial(coeffs, num_coeffs, mid) < 0) == lo_negative) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return hi;
}

// Sorted real roots of p in [lo, hi], at most num_coeffs - 1 of them, written
// to roots. Roots of p' split [lo, hi] into pieces on which p is monotone, so
// each piece holds at most one root, found by bisection; p' is treated the
// same way, down to a linear polynomial. A root where p touches zero without
// changing sign is found only if p evaluates to exactly zero there. A
// polynomial that is identically zero has no isolated roots (returns 0).
inline int PolynomialRootsInInterval(const double* coeffs, int num_coeffs,
                                     double lo, double hi, double* roots) {
  int n = std::min(num_coeffs, kMaxPolynomialCoeffs);
  while (n > 0 && coeffs[n - 1] == 0) --n;
  if (n <= 1 || !(lo <= hi)) return 0;
  if (n == 2) {
    const double root = -coeffs[0] / coeffs[1];
    if (!(root >= lo && root <= hi)) return 0;
    roots[0] = root;
    return 1;
  }
  double derivative[kMaxPolynomialCoeffs];
  for (int i = 1; i < n; ++i) derivative[i - 1] = i * coeffs[i];
  double breaks[kMaxPolynomialCoeffs + 1];
  breaks[0] = lo;
  const int num_critical =
      PolynomialRootsInInterval(derivative, n - 1, lo, hi, breaks + 1);
  int num_breaks = num_critical + 1;
  breaks[num_breaks++] = hi;

  int num_roots = 0;
  auto add = [&](double root) {
    if (num_roots == 0 || root > roots[num_roots - 1])
      roots[num_roots++] = root;
  };
  for (int i = 0; i + 1 < num_breaks; ++i) {
    const double a = breaks[i], b = breaks[i + 1];
    const double pa = EvaluatePolynomial(coeffs, n, a);
    const double pb = EvaluatePolynomial(coeffs, n, b);
    if (pa == 0) {
      add(a);
    } else if (pb != 0 && (pa < 0) != (pb < 0)) {
      add(BisectSignChange(coeffs, n, a, b));
    }
  }
  if (EvaluatePolynomial(coeffs, n, hi) == 0) add(hi);
  return num_roots;
}

// The smallest x in [lo, hi] with p(x) <= 0, for a polynomial with p(lo) > 0;
// false if p > 0 on all of [lo, hi]. The minimum of p over a piece between
// consecutive critical points lies at one of its ends, so the pieces are
// searched in order and the first one that reaches p <= 0 is bisected.
inline bool FirstNonPositive(const double* coeffs, int num_coeffs, double lo,
                             double hi, double* x) {
  int n = std::min(num_coeffs, kMaxPolynomialCoeffs);
  while (n > 0 && coeffs[n - 1] == 0) --n;
  if (!(EvaluatePolynomial(coeffs, n, lo) > 0)) {
    *x = lo;
    return true;
  }
  double derivative[kMaxPolynomialCoeffs];
  for (int i = 1; i < n; ++i) derivative[i - 1] = i * coeffs[i];
  double breaks[kMaxPolynomialCoeffs + 1];
  breaks[0] = lo;
  const int num_critical =
      n > 1 ? PolynomialRootsInInterval(derivative, n - 1, lo, hi, breaks + 1)
            : 0;
  int num_breaks = num_critical + 1;
  breaks[num_breaks++] = hi;
  for (int i = 1; i < num_breaks; ++i) {
    if (!(EvaluatePolynomial(coeffs, n, breaks[i]) > 0)) {
      // p > 0 at breaks[i - 1] and monotone up to breaks[i].
      double a = breaks[i - 1], b = breaks[i];
      for (int k = 0; k < 2000; ++k) {
        const double mid = a + 0.5 * (b - a);
        if (!(mid > a && mid < b)) break;
        if (EvaluatePolynomial(coeffs, n, mid) > 0) {
          a = mid;
        } else {
          b = mid;
        }
      }
      *x = b;
      return true;
    }
  }
  return false;
}

// Solves g(x) = target for a function increasing on [lo, hi], given as
// evaluate(x, &g, &dg_dx). Newton steps inside a bracket that shrinks every
// iteration; a step that leaves the bracket, or a non-finite or non-positive
// slope, is replaced by bisection. At most 200 iterations. False if the target
// is outside [g(lo), g(hi)] or a value is not finite.
template <typename Evaluate>
bool SolveIncreasing(const Evaluate& evaluate, double lo, double hi,
                     double target, double* x) {
  double g_lo, g_hi, slope;
  evaluate(lo, &g_lo, &slope);
  evaluate(hi, &g_hi, &slope);
  if (!std::isfinite(target) || !std::isfinite(g_lo) || !std::isfinite(g_hi) ||
      !(target >= g_lo && target <= g_hi)) {
    return false;
  }
  if (target == g_lo) {
    *x = lo;
    return true;
  }
  if (target == g_hi) {
    *x = hi;
    return true;
  }
  double current = lo + (hi - lo) * (target - g_lo) / (g_hi - g_lo);
  for (int i = 0; i < 200; ++i) {
    if (!(current > lo && current < hi)) current = lo + 0.5 * (hi - lo);
    double g, dg;
    evaluate(current, &g, &dg);
    if (!std::isfinite(g)) return false;
    const double residual = g - target;
    if (residual == 0) break;
    if (residual < 0) {
      lo = current;
    } else {
      hi = current;
    }
    const double next = current - residual / dg;
    const double tolerance = 4e-16 * std::max(1.0, std::abs(current));
    if (std::isfinite(next) && dg > 0 && next > lo && next < hi) {
      const bool converged = std::abs(next - current) <= tolerance;
      current = next;
      if (converged) break;
    } else {
      current = lo + 0.5 * (hi - lo);
      if (hi - lo <= tolerance) break;
    }
  }
  *x = current;
  return true;
}

}  // namespace internal
}  // namespace sphera
