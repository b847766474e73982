// Ceres settings shared by the small refinements (one pose, one relative
// pose, one point): a dense solver, tolerances near double round-off since
// these problems are tiny and exactness matters for the tests, one thread.
#pragma once

#include <ceres/ceres.h>

namespace sphera {

inline ceres::Solver::Options SmallProblemSolverOptions(
    int max_num_iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_num_iterations;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  return options;
}

}  // namespace sphera
