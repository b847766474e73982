#!/usr/bin/env python3
"""Cramér-Rao bound on the poses (and points) of a ground-truth scene.

Given the ground-truth model (cam_from_world poses, 3D points, and which
image observes which point) and a keypoint noise model, this computes the
Fisher information of all poses and points and from it the smallest
covariance any unbiased estimator (bundle adjustment at its optimum is one
to first order) can reach, in the gauge of the evaluator's alignment.

Measurements and noise
  Ray of point X in camera j:  y = R_j (X - C_j)   (R_j cam_from_world,
  C_j the camera centre).
  pixel: the measurement is the projection u = pi(y) of the camera model,
         noise isotropic Gaussian in pixels, sigma_px.
  angle: the measurement is the unit ray b = y / |y|, noise isotropic
         Gaussian in the tangent plane of the sphere, sigma (radians).
  Both give per observation a whitened 2 x 3 Jacobian M of the measurement
  with respect to y:
    pixel: M = d pi / d y / sigma_px         (analytic for PINHOLE,
           SIMPLE_PINHOLE and EQUIRECTANGULAR; central differences with the
           step h = 1e-5 |y| for the others: the truncation error is
           O(h^2 / |y|^2) = 1e-10 relative, the rounding error about
           1e-16 |pi| / h, both far below 0.1 %),
    angle: M = B^T / (sigma |y|), the columns of B an orthonormal basis of
           the plane orthogonal to b (d b / d y = (I - b b^T) / |y|).

Parameters
  Image j: omega_j (3) and C_j (3), with R_j <- exp([omega_j]x) R_j, so
  |omega_j| is the rotation error angle ||log(R_gt R_est^T)|| that the
  evaluator measures, and C_j the centre in world units.  Point i: X_i (3).
  Intrinsics are fixed (known calibration), except in the rig bound with
  --intrinsics (below).
    d y / d omega = -[y]x,   d y / d C = -R,   d y / d X = R.
  Observation k (image j, point i) has whitened Jacobians
    A_k = M [-[y]x, -R] (2 x 6)  and  P_k = M R (2 x 3).

Fisher information and Schur complement
  F = J^T J (whitened) has the bundle-adjustment structure
    U_j = sum_k A_k^T A_k,  V_i = sum_k P_k^T P_k,  W_ji = A_k^T P_k,
  and the information on the images with the points as nuisance
  parameters is the reduced camera matrix
    S = U - W V^-1 W^T            (6N x 6N, as in BA's Schur complement).
  Points seen by fewer than two images carry no information on the images
  and are dropped.

Gauge
  A similarity of the world, X <- X + theta x (X - c) + tau + lambda (X - c)
  (c the mean ground-truth centre, only for conditioning), changes no
  measurement: the 7 generators G (columns, one per theta, tau, lambda
  component) act on the parameters as
    omega_j: -R_j theta,   C_j: theta x d_j + tau + lambda d_j,
    X_i: theta x (X_i - c) + tau + lambda (X_i - c),   d_j = C_j - c,
  and F G = 0, S G_cam = 0 (checked by the tests).  The errors that the
  evaluator reports are those after aligning the estimate to the ground
  truth by a similarity g(delta) computed from the estimate.  To first
  order the alignment is linear, g = K delta with K G = I (a pure gauge
  move is recovered exactly), and the reported error is
    delta' = (I - G K) delta = Pi delta.
  Pi annihilates G and is the identity on null(K), so the aligned errors
  are the estimate in the gauge K delta = 0, and the bound is the
  constrained CRB (Stoica and Ng 1998)
    Cov = Q (Q^T S Q)^-1 Q^T = Pi S^+ Pi^T,   Q an orthonormal basis of
  null(K).  (Proof of the second form: S Pi = S and S^+ S = I - P_G give
  Pi S^+ Pi^T S = Pi, so both sides are the symmetric X with range in
  null(K) and X S Q = Q.)  Two alignments are implemented:
  centers:   (model_evaluator --alignment centers, its default) the
             least-squares similarity on the camera centres (Umeyama
             1991, sphera_common.pose_errors).  Linearised it is the
             orthogonal projection of the centre errors off the span of
             the centre generators G_C:  K = (G_C^T G_C)^-1 G_C^T E_C, E_C
             picking the centres out of the camera parameters, i.e. the
             minimum-norm gauge on the centres.
  orientations: `colmap model_evaluator --alignment orientations`
             (colmap_ext/controllers/
             model_evaluation.cc, estimators/similarity_alignment.h): the
             rotation from the camera orientations, the geodesic median of
             R_gt_j^T R_est_j = exp([R_j^T omega_j]x), then scale and
             translation by least squares on the centres with that rotation.
             Linearised with the mean in place of the median:
               theta = -mean_j R_j^T omega_j,  tau = mean_j dC_j,
               lambda = sum_j d_j . dC_j / sum_j |d_j|^2.
             (The L1 median is noisier than the mean, by 1/0.85 in variance
             for Gaussian errors in 3D, on the common rotation only; this
             bound is for the L2 version of the alignment.)
  Point covariances follow by back-substitution in the same gauge (the
  alignment moves points and images by the same similarity, a function of
  the image errors only, so the aligned estimate is the one constrained by
  K delta = 0 on the images):
    Cov(X_i) = V_i^-1 + Y_i^T Cov Y_i,   Y_i = W_i V_i^-1 (6N x 3),
  the point blocks of Pi_full F^+ Pi_full^T (checked by the tests).

Reported bounds
  Per image: sigma_rot = sqrt(trace Cov_omega) (degrees), the RMS rotation
  error angle, and sigma_pos = sqrt(trace Cov_C) (model units), the RMS
  centre error; aggregates: RMS over images, the mean of the per-image
  values, and the expected mean error E|e| of the Gaussian with that
  covariance (what the evaluator's mean error estimates; for an isotropic
  3D Gaussian E|e| = sqrt(8 / (3 pi)) sigma = 0.921 sigma).

Rigs (--rig)
  A rig's bundle adjustment estimates frames (R_f rig_from_world, C_f) and
  each lens's pose in the rig (R_s sensor_from_rig, c_s its centre in the
  rig), the reference lens fixed at the rig frame; image j, lens s of frame
  f, is R_j = R_s R_f, C_j = C_f + R_f^T c_s.  To first order the image
  errors are a linear map T of the rig's (rig_jacobian), so the rig's
  reduced information is T^T S T (the points eliminated as before) and its
  alignment K T; the world similarity moves the frames as cameras and
  stretches the rig (dc_s = lambda c_s).  The bound of a lens's pose is
  then what rig_errors measures: the angle of R_s and the distance of c_s,
  scaled by the alignment.  With --intrinsics each lens's focal length and
  distortion are parameters too (one block per lens, the principal point
  held as COLMAP holds it by default); their derivatives are central
  differences of the projection.

Known points (closed-form checks): known_points_information gives the 6x6
information of one camera's (omega, C) when the points are known exactly.
"""
import argparse
import csv
import math
import os
import sys
import time

import numpy as np
import scipy.linalg
import scipy.sparse

from sphera_common import (cam_from_world, read_text_model, read_text_rigs,
                           read_text_rows, similarity_of_centres)

FD_STEP = 1e-5  # central-difference step, relative to |y|
GAUGES = ("centers", "orientations")


# ---------------------------------------------------------------------------
# Scene

class Scene:
    """Ground truth: cameras {id: (model, width, height, params)}; per image
    (arrays over images) ids, names, camera ids, R (N,3,3) cam_from_world,
    C (N,3) centres; points (M,3) with ids; observations as index arrays
    obs_image, obs_point (K,) into those arrays and, read from a model, the
    observed pixels (K,2) (None otherwise)."""

    def __init__(self, cameras, image_ids, names, camera_ids, R, C,
                 point_ids, points, obs_image, obs_point, observed=None):
        self.cameras = cameras
        self.image_ids = list(image_ids)
        self.names = list(names)
        self.camera_ids = np.asarray(camera_ids, dtype=int)
        self.R = np.asarray(R, dtype=float).reshape(-1, 3, 3)
        self.C = np.asarray(C, dtype=float).reshape(-1, 3)
        self.point_ids = list(point_ids)
        self.points = np.asarray(points, dtype=float).reshape(-1, 3)
        self.obs_image = np.asarray(obs_image, dtype=int)
        self.obs_point = np.asarray(obs_point, dtype=int)
        self.observed = observed

    @property
    def num_images(self):
        return len(self.image_ids)

    @property
    def num_points(self):
        return len(self.points)


def scene_from_model(model_dir):
    """Scene of a COLMAP text model (observations: POINTS2D with a point)."""
    cameras, images, points = read_text_model(model_dir)
    image_ids = sorted(images)
    point_ids = sorted(points)
    point_index = {pid: i for i, pid in enumerate(point_ids)}
    names, camera_ids, rotations, centres = [], [], [], []
    obs_image, obs_point, observed = [], [], []
    for j, image_id in enumerate(image_ids):
        fields, observations = images[image_id]
        R, t = cam_from_world(fields)
        names.append(fields[9] if len(fields) > 9 else str(image_id))
        camera_ids.append(int(fields[8]))
        rotations.append(R)
        centres.append(-R.T @ t)
        for x, y, pid in observations:
            if pid in point_index:
                obs_image.append(j)
                obs_point.append(point_index[pid])
                observed.append((x, y))
    xyz = [points[pid][0] for pid in point_ids]
    return Scene(cameras, image_ids, names, camera_ids, rotations, centres,
                 point_ids, xyz, obs_image, obs_point,
                 np.array(observed, dtype=float).reshape(-1, 2))


def transform_scene(scene, Q, t, s):
    """The scene after the world similarity X <- s Q X + t."""
    R = scene.R @ Q.T
    C = s * scene.C @ Q.T + t
    X = s * scene.points @ Q.T + t
    return Scene(scene.cameras, scene.image_ids, scene.names,
                 scene.camera_ids, R, C, scene.point_ids, X,
                 scene.obs_image, scene.obs_point)


# ---------------------------------------------------------------------------
# Camera models: pi(y) for rays y (K,3), and d pi / d y (K,2,3)

def _radtan(k, mx, my):
    k1, k2, p1, p2 = k
    r2 = mx * mx + my * my
    radial = k1 * r2 + k2 * r2 * r2
    u = mx + mx * radial + 2 * p1 * mx * my + p2 * (r2 + 2 * mx * mx)
    v = my + my * radial + 2 * p2 * mx * my + p1 * (r2 + 2 * my * my)
    return u, v


def _perspective_params(model, p):
    """(fx, fy, cx, cy, [k1, k2, p1, p2]) of the perspective models."""
    if model == "SIMPLE_PINHOLE":
        return p[0], p[0], p[1], p[2], (0, 0, 0, 0)
    if model == "PINHOLE":
        return p[0], p[1], p[2], p[3], (0, 0, 0, 0)
    if model == "SIMPLE_RADIAL":
        return p[0], p[0], p[1], p[2], (p[3], 0, 0, 0)
    if model == "RADIAL":
        return p[0], p[0], p[1], p[2], (p[3], p[4], 0, 0)
    if model == "OPENCV":
        return p[0], p[1], p[2], p[3], tuple(p[4:8])
    return None


def _kannala_brandt(model, p, x, yy, z):
    """OPENCV_FISHEYE and THIN_PRISM_FISHEYE over their whole field
    (camera_models/kannala_brandt.h): theta = atan2(|(x, y)|, z), the ray on
    the theta plane (a, b) = theta (x, y) / |(x, y)|, then the radial (and
    for THIN_PRISM_FISHEYE the tangential and thin-prism) terms."""
    rho = np.hypot(x, yy)
    theta = np.arctan2(rho, z)
    on_axis = rho == 0
    scale = np.where(on_axis, 0.0, theta / np.where(on_axis, 1.0, rho))
    a, b = scale * x, scale * yy
    t2 = theta * theta
    if model == "OPENCV_FISHEYE":
        k = p[4:8]
        radial = t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])))
        ad, bd = a * (1 + radial), b * (1 + radial)
    else:
        k1, k2, p1, p2, k3, k4, sx1, sy1 = p[4:12]
        radial = t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)))
        ad = (a + a * radial + 2 * p1 * a * b + p2 * (t2 + 2 * a * a) +
              sx1 * t2)
        bd = (b + b * radial + 2 * p2 * a * b + p1 * (t2 + 2 * b * b) +
              sy1 * t2)
    return np.stack([p[0] * ad + p[2], p[1] * bd + p[3]], axis=1)


def _ocam(p, x, yy, z):
    """OCAM (camera_models/ocam.h): the sensor radius rho in [0, rho_max)
    whose ray atan2(rho, -f(rho)) has the ray's angle from +z (monotone
    there; found by bisection to full precision), then OCamCalib's affine
    map."""
    a0, a2, a3, a4 = p[5:9]
    f = lambda r: a0 + r * r * (a2 + r * (a3 + r * a4))  # noqa: E731
    # rho_max: the first positive root of m(rho) = -f + rho f'.
    roots = np.roots([3 * a4, 2 * a3, a2, 0, -a0]) if (a2, a3, a4) != (
        0, 0, 0) else np.array([])
    real = [r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0]
    rho_xy = np.hypot(x, yy)
    theta_ray = np.arctan2(rho_xy, z)
    if real:
        hi = np.full(len(x), min(real))
    else:
        hi = np.full(len(x), max(1.0, -a0))
        for _ in range(2000):
            short = np.arctan2(hi, -f(hi)) < theta_ray
            if not short.any():
                break
            hi[short] *= 2
    lo = np.zeros(len(x))
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        below = np.arctan2(mid, -f(mid)) < theta_ray
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    rho = 0.5 * (lo + hi)
    on_axis = rho_xy == 0
    q = np.where(on_axis, 0.0, rho / np.where(on_axis, 1.0, rho_xy))
    s_col, s_row = q * x, q * yy
    c, d, e = p[2], p[3], p[4]
    return np.stack([e * s_row + s_col + p[0],
                     c * s_row + d * s_col + p[1]], axis=1)


def project(camera, y):
    """Pixels (K,2) of the rays y (K,3) in the camera (model, w, h, params),
    following camera_models/*.h."""
    model, _, _, p = camera
    x, yy, z = y[:, 0], y[:, 1], y[:, 2]
    if model in ("OPENCV_FISHEYE", "THIN_PRISM_FISHEYE"):
        return _kannala_brandt(model, p, x, yy, z)
    if model == "OCAM":
        return _ocam(p, x, yy, z)
    persp = _perspective_params(model, p)
    if persp is not None:
        fx, fy, cx, cy, k = persp
        u, v = _radtan(k, x / z, yy / z)
        return np.stack([fx * u + cx, fy * v + cy], axis=1)
    if model == "EQUIRECTANGULAR":
        theta = np.arctan2(x, z)
        phi = np.arctan2(-yy, np.hypot(x, z))
        return np.stack([(theta / (2 * np.pi) + 0.5) * p[0],
                         (0.5 - phi / np.pi) * p[1]], axis=1)
    if model == "EUCM":
        alpha, beta = p[4], p[5]
        d = np.sqrt(beta * (x * x + yy * yy) + z * z)
        den = alpha * d + (1 - alpha) * z
        return np.stack([p[0] * x / den + p[2], p[1] * yy / den + p[3]], 1)
    if model == "UNIFIED_OMNI":
        s = y / np.linalg.norm(y, axis=1, keepdims=True)
        den = s[:, 2] + p[4]
        u, v = _radtan(p[5:9], s[:, 0] / den, s[:, 1] / den)
        return np.stack([p[0] * u + p[2], p[1] * v + p[3]], axis=1)
    if model == "DOUBLE_SPHERE":
        xi, alpha = p[4], p[5]
        rho2 = x * x + yy * yy
        zs = xi * np.sqrt(rho2 + z * z) + z
        den = alpha * np.sqrt(rho2 + zs * zs) + (1 - alpha) * zs
        return np.stack([p[0] * x / den + p[2], p[1] * yy / den + p[3]], 1)
    raise ValueError("camera model %s is not supported" % model)


def _pinhole_jacobian(fx, fy, y):
    x, yy, z = y[:, 0], y[:, 1], y[:, 2]
    J = np.zeros((len(y), 2, 3))
    J[:, 0, 0] = fx / z
    J[:, 0, 2] = -fx * x / (z * z)
    J[:, 1, 1] = fy / z
    J[:, 1, 2] = -fy * yy / (z * z)
    return J


def _equirect_jacobian(W, H, y):
    """theta = atan2(x, z), phi = atan2(-y, rho), rho = |(x, z)|:
    d theta = (z dx - x dz) / rho^2,
    d phi = (-rho dy + y (x dx + z dz) / rho) / r^2."""
    x, yy, z = y[:, 0], y[:, 1], y[:, 2]
    rho2 = x * x + z * z
    rho = np.sqrt(rho2)
    r2 = rho2 + yy * yy
    J = np.zeros((len(y), 2, 3))
    ku, kv = W / (2 * np.pi), -H / np.pi
    J[:, 0, 0] = ku * z / rho2
    J[:, 0, 2] = -ku * x / rho2
    J[:, 1, 0] = kv * yy * x / (rho * r2)
    J[:, 1, 1] = -kv * rho / r2
    J[:, 1, 2] = kv * yy * z / (rho * r2)
    return J


def projection_jacobian(camera, y):
    """d pi / d y (K,2,3): analytic for the pinholes and the equirect,
    central differences (step FD_STEP |y|) for the others."""
    model, _, _, p = camera
    if model in ("PINHOLE", "SIMPLE_PINHOLE"):
        fx, fy = _perspective_params(model, p)[:2]
        return _pinhole_jacobian(fx, fy, y)
    if model == "EQUIRECTANGULAR":
        return _equirect_jacobian(p[0], p[1], y)
    h = FD_STEP * np.linalg.norm(y, axis=1)
    J = np.empty((len(y), 2, 3))
    for a in range(3):
        step = np.zeros_like(y)
        step[:, a] = h
        J[:, :, a] = (project(camera, y + step) -
                      project(camera, y - step)) / (2 * h)[:, None]
    return J


def tangent_basis(b):
    """(K,3,2): orthonormal bases of the planes orthogonal to unit b (K,3)."""
    helper = np.zeros_like(b)
    use_x = np.abs(b[:, 0]) < 0.9
    helper[use_x, 0] = 1
    helper[~use_x, 1] = 1
    e1 = np.cross(b, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(b, e1)
    return np.stack([e1, e2], axis=2)


def whitened_measurement_jacobian(camera, y, sigma, noise):
    """M (K,2,3): d measurement / d y divided by the noise sigma."""
    if noise == "pixel":
        return projection_jacobian(camera, y) / sigma
    if noise == "angle":
        norm = np.linalg.norm(y, axis=1)
        B = tangent_basis(y / norm[:, None])
        return np.transpose(B, (0, 2, 1)) / (sigma * norm)[:, None, None]
    raise ValueError("noise must be 'pixel' or 'angle', not %r" % noise)


def skew(v):
    """[v]x for v (K,3) -> (K,3,3)."""
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


# ---------------------------------------------------------------------------
# Fisher information

def observation_rays(scene):
    """The rays y = R_j (X_i - C_j) (K,3) of every observation."""
    return np.einsum("kab,kb->ka", scene.R[scene.obs_image],
                     scene.points[scene.obs_point] - scene.C[scene.obs_image])


def projections(scene):
    """The pixels (K,2) where every observation's point projects."""
    y = observation_rays(scene)
    pixels = np.empty((len(y), 2))
    cams = scene.camera_ids[scene.obs_image]
    for camera_id in np.unique(cams):
        sel = cams == camera_id
        pixels[sel] = project(scene.cameras[camera_id], y[sel])
    return pixels


# The principal point's indices in a model's parameters (default (2, 3)).
PRINCIPAL_POINT = {"SIMPLE_PINHOLE": (1, 2), "SIMPLE_RADIAL": (1, 2),
                   "RADIAL": (1, 2), "OCAM": (0, 1), "EQUIRECTANGULAR": ()}


def refined_intrinsics(model, num_params):
    """Indices of the parameters that COLMAP's bundle adjustment refines by
    default: focal length and distortion, the principal point held
    (--Mapper.ba_refine_principal_point 0)."""
    fixed = PRINCIPAL_POINT.get(model, (2, 3))
    return [p for p in range(num_params) if p not in fixed]


def intrinsics_jacobian(camera, y):
    """d pi / d params (K,2,P) of the rays y (K,3) for the refined
    parameters (refined_intrinsics): central differences, the step 1e-6 of
    each parameter's size (at least 1e-6 for a parameter of 0, e.g. an
    unused distortion term)."""
    model, width, height, params = camera
    params = np.asarray(params, dtype=float)
    refined = refined_intrinsics(model, len(params))
    J = np.empty((len(y), 2, len(refined)))
    for column, p in enumerate(refined):
        h = 1e-6 * max(abs(params[p]), 1.0)
        up, down = params.copy(), params.copy()
        up[p] += h
        down[p] -= h
        J[:, :, column] = (project((model, width, height, up), y) -
                           project((model, width, height, down), y)) / (2 * h)
    return J


def observation_jacobians(scene, sigma, noise, intrinsics=False):
    """Whitened Jacobians of every observation: A (K,2,6) with respect to
    (omega, C) of its image, P (K,2,3) with respect to its point.  With
    intrinsics (pixel noise; every camera of one model), A (K,2,6+P) also
    holds the derivatives by its camera's P refined parameters."""
    R = scene.R[scene.obs_image]
    y = observation_rays(scene)
    M = np.empty((len(y), 2, 3))
    cams = scene.camera_ids[scene.obs_image]
    for camera_id in np.unique(cams):
        sel = cams == camera_id
        M[sel] = whitened_measurement_jacobian(
            scene.cameras[camera_id], y[sel], sigma, noise)
    A = np.concatenate([-M @ skew(y), -M @ R], axis=2)
    P = M @ R
    if intrinsics:
        sizes = {len(refined_intrinsics(camera[0], len(camera[3])))
                 for camera in scene.cameras.values()}
        if noise != "pixel" or len(sizes) != 1:
            raise ValueError("intrinsics are bounded for pixel noise and "
                             "cameras of one model")
        Ji = np.empty((len(y), 2, sizes.pop()))
        for camera_id in np.unique(cams):
            sel = cams == camera_id
            Ji[sel] = intrinsics_jacobian(scene.cameras[camera_id],
                                          y[sel]) / sigma
        A = np.concatenate([A, Ji], axis=2)
    return A, P


def _sum_by(index, values, n):
    """sum of values[k] (K, ...) over k with index[k] = i, for i < n."""
    K = len(index)
    onehot = scipy.sparse.csr_matrix(
        (np.ones(K), (index, np.arange(K))), shape=(n, K))
    return (onehot @ values.reshape(K, -1)).reshape((n,) + values.shape[1:])


def information_blocks(scene, sigma, noise, intrinsics=False):
    """U (N,D,D), V (M,3,3) and W (K,D,3) of the Fisher information, D = 6
    (6 + P with intrinsics, observation_jacobians)."""
    A, P = observation_jacobians(scene, sigma, noise, intrinsics)
    At = np.transpose(A, (0, 2, 1))
    U = _sum_by(scene.obs_image, At @ A, scene.num_images)
    V = _sum_by(scene.obs_point, np.transpose(P, (0, 2, 1)) @ P,
                scene.num_points)
    return U, V, At @ P


def full_information(scene, sigma, noise):
    """Dense F over (omega_j, C_j for all j; X_i for all i); small scenes."""
    U, V, W = information_blocks(scene, sigma, noise)
    n6 = 6 * scene.num_images
    F = np.zeros((n6 + 3 * scene.num_points,) * 2)
    for j in range(scene.num_images):
        F[6 * j:6 * j + 6, 6 * j:6 * j + 6] = U[j]
    for i in range(scene.num_points):
        F[n6 + 3 * i:n6 + 3 * i + 3, n6 + 3 * i:n6 + 3 * i + 3] = V[i]
    for k, (j, i) in enumerate(zip(scene.obs_image, scene.obs_point)):
        rows = slice(6 * j, 6 * j + 6)
        cols = slice(n6 + 3 * i, n6 + 3 * i + 3)
        F[rows, cols] += W[k]
        F[cols, rows] += W[k].T
    return F


def _block_sparse(blocks, rows, cols, shape):
    """Sparse matrix with blocks[k] (b,c) at block row rows[k], col cols[k]."""
    _, b, c = blocks.shape
    r = (rows[:, None, None] * b + np.arange(b)[None, :, None])
    q = (cols[:, None, None] * c + np.arange(c)[None, None, :])
    r, q = np.broadcast_arrays(r, q)
    return scipy.sparse.csr_matrix(
        (blocks.ravel(), (r.ravel(), q.ravel())), shape=shape)


def reduced_camera_information(scene, sigma, noise, chunk=2000,
                               intrinsics=False):
    """(S, Y, Vinv): S = U - W V^-1 W^T (DN x DN: D = 6, 6 + P with
    intrinsics), Y = W V^-1 (sparse, DN x 3M) and the V_i^-1, over the
    points seen by at least two images.
    S is accumulated over chunks of points as dense products, which BLAS
    does faster than a sparse product with a dense result."""
    U, V, W = information_blocks(scene, sigma, noise, intrinsics)
    N, Mp = scene.num_images, scene.num_points
    D = U.shape[1]
    track = np.bincount(scene.obs_point, minlength=Mp)
    keep = track[scene.obs_point] >= 2
    Vinv = np.zeros_like(V)
    good = track >= 2
    Vinv[good] = np.linalg.inv(V[good])
    Wm = _block_sparse(W[keep], scene.obs_image[keep],
                       scene.obs_point[keep], (D * N, 3 * Mp)).tocsc()
    Vm = _block_sparse(Vinv, np.arange(Mp), np.arange(Mp), (3 * Mp, 3 * Mp))
    Y = (Wm @ Vm).tocsc()
    S = scipy.linalg.block_diag(*U)
    for i0 in range(0, Mp, chunk):
        cols = slice(3 * i0, 3 * min(Mp, i0 + chunk))
        S -= Y[:, cols].toarray() @ Wm[:, cols].toarray().T
    return 0.5 * (S + S.T), Y, Vinv


# ---------------------------------------------------------------------------
# Gauge

def gauge_generators(scene, with_points=False):
    """G (6N [+ 3M], 7): columns theta_x..z, tau_x..z, lambda of the world
    similarity about the mean centre c (see the module docstring)."""
    c = scene.C.mean(axis=0)
    N = scene.num_images
    blocks = []
    cam = np.zeros((N, 6, 7))
    cam[:, 0:3, 0:3] = -scene.R                 # omega = -R theta
    d = scene.C - c
    cam[:, 3:6, 0:3] = -skew(d)                 # theta x d = -[d]x theta
    cam[:, 3:6, 3:6] = np.eye(3)
    cam[:, 3:6, 6] = d
    blocks.append(cam.reshape(6 * N, 7))
    if with_points:
        e = scene.points - c
        pts = np.zeros((scene.num_points, 3, 7))
        pts[:, :, 0:3] = -skew(e)
        pts[:, :, 3:6] = np.eye(3)
        pts[:, :, 6] = e
        blocks.append(pts.reshape(3 * scene.num_points, 7))
    return np.concatenate(blocks, axis=0)


def alignment_map(scene, gauge):
    """K (7 x 6N): the linearised alignment g = K delta of the camera errors
    delta, with K G = I."""
    N = scene.num_images
    G = gauge_generators(scene)
    if gauge == "centers":
        centre_rows = (6 * np.arange(N)[:, None] + np.arange(3, 6)).ravel()
        GC = G[centre_rows]
        K = np.zeros((7, 6 * N))
        K[:, centre_rows] = np.linalg.solve(GC.T @ GC, GC.T)
        return K
    if gauge == "orientations":
        d = scene.C - scene.C.mean(axis=0)
        K = np.zeros((7, N, 6))
        K[0:3, :, 0:3] = -np.transpose(scene.R, (2, 0, 1)) / N  # -R^T / N
        K[3:6, :, 3:6] = np.eye(3)[:, None, :] / N
        K[6, :, 3:6] = d / (d * d).sum()
        return K.reshape(7, 6 * N)
    raise ValueError("gauge must be one of %s" % (GAUGES,))


def check_alignable(scene, gauge):
    """Raises ValueError when the alignment is undefined: coincident
    centres (no scale), or for the centres alignment collinear centres (no
    rotation about their line)."""
    d = scene.C - scene.C.mean(axis=0)
    spread = math.sqrt((d * d).sum(axis=1).mean()) if len(d) else 0.0
    if not spread > 1e-9 * (1 + np.abs(scene.C).max(initial=0)):
        raise ValueError("the camera centres coincide: no alignment")
    if gauge == "centers":
        u = d / spread   # rotation generators theta x u_j, unit size
        GC = np.concatenate([-skew(u), np.broadcast_to(
            np.eye(3), u.shape + (3,)), u[:, :, None]], axis=2)
        sv = np.linalg.svd(GC.reshape(-1, 7), compute_uv=False)
        if not sv[-1] > 1e-6 * sv[0]:
            raise ValueError("the centres alignment needs at least 3 "
                             "non-collinear camera centres")


def gauge_covariance(S, K):
    """Cov = Q (Q^T S Q)^-1 Q^T, Q an orthonormal basis of null(K)."""
    _, _, vt = np.linalg.svd(K)
    Q = vt[K.shape[0]:].T
    info = Q.T @ S @ Q
    info = 0.5 * (info + info.T)
    # Jacobi-scaled condition number: independent of the units.
    scale = 1 / np.sqrt(np.clip(np.diag(info), 1e-300, None))
    w = np.linalg.eigvalsh(info * scale[:, None] * scale[None, :])
    if not w[0] > 1e-12 * w[-1]:
        raise ValueError("the information is singular beyond the gauge: "
                         "some image is not constrained by the observations")
    return Q @ scipy.linalg.inv(info) @ Q.T


def point_covariances(Cov, Y, Vinv, chunk=2000):
    """Per-point 3x3 covariances (M,3,3) in the gauge of Cov: the point
    block of the constrained CRB with the constraint K delta = 0 on the
    images only, V_i^-1 + Y_i^T Cov Y_i with Y_i = W_i V_i^-1 (the
    columns of point i of Y).  The aligned point errors are in that gauge
    because the alignment moves points and images by the same similarity
    g = K delta, which leaves K delta' = 0."""
    N6, M = Y.shape[0], len(Vinv)
    out = Vinv.copy()
    Y = Y.tocsc()
    for i0 in range(0, M, chunk):
        i1 = min(M, i0 + chunk)
        Yd = Y[:, 3 * i0:3 * i1].toarray()
        Z = Cov @ Yd
        Yt = np.transpose(Yd.reshape(N6, -1, 3), (1, 2, 0))   # (b, 3, 6N)
        out[i0:i1] += Yt @ np.transpose(Z.reshape(N6, -1, 3), (1, 0, 2))
    return out


# ---------------------------------------------------------------------------
# Bounds

def known_points_information(R, C, points, camera, sigma, noise):
    """6x6 Fisher information of one camera's (omega, C) from points known
    exactly (no gauge: the points fix the world frame)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    n = len(points)
    scene = Scene({1: camera}, [1], ["camera"], [1], [R], [C],
                  range(n), points, np.zeros(n, int), np.arange(n))
    A, _ = observation_jacobians(scene, sigma, noise)
    return np.einsum("kai,kaj->ij", A, A)


def known_points_covariance(R, C, points, camera, sigma, noise,
                            free="pose"):
    """Covariance bound of the free parameters of one camera from known
    points: free = 'pose' (omega, C: 6x6), 'rotation' (omega, with C known)
    or 'position' (C, with R known)."""
    info = known_points_information(R, C, points, camera, sigma, noise)
    sel = {"pose": slice(0, 6), "rotation": slice(0, 3),
           "position": slice(3, 6)}[free]
    return np.linalg.inv(info[sel, sel])


_NORMAL_SAMPLES = np.random.default_rng(0).standard_normal((20000, 3))


def expected_norm(cov):
    """E|e| for e ~ N(0, cov) (3x3), by a fixed set of normal samples
    (relative error about 0.3 %)."""
    w, v = np.linalg.eigh(0.5 * (cov + cov.T))
    L = v * np.sqrt(np.clip(w, 0, None))
    return float(np.linalg.norm(_NORMAL_SAMPLES @ L.T, axis=1).mean())


def scene_bound(scene, sigma, noise="pixel", gauge="centers",
                points=True):
    """Bound of every image (and point) of the scene.  sigma in pixels for
    noise='pixel', in radians for noise='angle'.  Returns a dict:
      images: [{image_id, name, num_observations, rot_deg, pos,
                rot_expected_deg, pos_expected}]   (sqrt of the traces and
              the expected error norms E|e|),
      rot_rms_deg, rot_mean_deg, rot_expected_mean_deg, pos_rms, pos_mean,
      pos_expected_mean, point_rms (RMS over points of sqrt trace; None
      with points=False), covariance (6N x 6N, (omega_j, C_j) blocks), the
      counts, sigma, noise, gauge."""
    if not len(scene.obs_image):
        raise ValueError("the model has no observations of 3D points (render "
                         "the ground truth with sphera_render --points N)")
    counts = np.bincount(scene.obs_image, minlength=scene.num_images)
    if counts.min() < 3:
        raise ValueError("images with fewer than 3 observations have no "
                         "bounded pose: %s" % ", ".join(
                             scene.names[j] for j in np.flatnonzero(
                                 counts < 3)))
    check_alignable(scene, gauge)
    S, Y, Vinv = reduced_camera_information(scene, sigma, noise)
    cov = gauge_covariance(S, alignment_map(scene, gauge))
    N = scene.num_images
    rows = []
    for j in range(N):
        crot = cov[6 * j:6 * j + 3, 6 * j:6 * j + 3]
        cpos = cov[6 * j + 3:6 * j + 6, 6 * j + 3:6 * j + 6]
        rows.append({
            "image_id": scene.image_ids[j], "name": scene.names[j],
            "num_observations": int(counts[j]),
            "rot_deg": math.degrees(math.sqrt(max(np.trace(crot), 0))),
            "pos": math.sqrt(max(np.trace(cpos), 0)),
            "rot_expected_deg": math.degrees(expected_norm(crot)),
            "pos_expected": expected_norm(cpos)})
    result = {"images": rows, "covariance": cov, "num_images": N,
              "num_points": scene.num_points,
              "num_observations": len(scene.obs_image),
              "sigma": sigma, "noise": noise, "gauge": gauge}
    for key in ("rot_deg", "pos", "rot_expected_deg", "pos_expected"):
        values = np.array([r[key] for r in rows])
        base = key.replace("_deg", "")
        suffix = "_deg" if key.endswith("_deg") else ""
        if key.startswith(("rot_expected", "pos_expected")):
            result[base + "_mean" + suffix] = float(values.mean())
        else:
            result[base + "_rms" + suffix] = float(np.sqrt(
                (values ** 2).mean()))
            result[base + "_mean" + suffix] = float(values.mean())
    result["point_rms"] = None
    if points:
        track = np.bincount(scene.obs_point, minlength=scene.num_points)
        pcov = point_covariances(cov, Y, Vinv)[track >= 2]
        result["point_rms"] = float(np.sqrt(
            np.trace(pcov, axis1=1, axis2=2).mean())) if len(pcov) else None
    return result


def bound_for_model(model_dir, sigma, noise="pixel", gauge="centers",
                    points=True):
    """scene_bound of a COLMAP text model; sigma in pixels for
    noise='pixel', in DEGREES for noise='angle'."""
    scene = scene_from_model(model_dir)
    if noise == "angle":
        sigma = math.radians(sigma)
    return scene_bound(scene, sigma, noise, gauge, points)


def reconstruction_scene(gt_dir, model_dir):
    """(scene, sigma_px) for the tracks a reconstruction found: the
    ground-truth poses (and cameras) of the images the text model at
    MODEL_DIR registered, matched by name; its 3D points carried into the
    ground-truth frame by the least-squares similarity of the camera centres;
    its observations.  sigma_px is the keypoint noise estimated from the
    model's own pixel residuals, sum |r|^2 / (2K - (6N + 3M - 7)) (K
    observations, N images, M points: the degrees of freedom that bundle
    adjustment leaves to the residuals)."""
    gt = scene_from_model(gt_dir)
    est = scene_from_model(model_dir)
    gt_index = {name: j for j, name in enumerate(gt.names)}
    common = [j for j, name in enumerate(est.names) if name in gt_index]
    if len(common) < 3:
        raise ValueError("fewer than 3 images of %s are in the ground truth"
                         % model_dir)
    gt_rows = [gt_index[est.names[j]] for j in common]
    keep = np.isin(est.obs_image, common)
    residuals = (projections(est) - est.observed)[keep]
    dof = 2 * len(residuals) - (6 * len(common) + 3 * est.num_points - 7)
    if dof <= 0:
        raise ValueError("%s has too few observations to estimate the noise"
                         % model_dir)
    sigma_px = math.sqrt(float((residuals ** 2).sum()) / dof)
    scale, rotation, translation = similarity_of_centres(est.C[common],
                                                         gt.C[gt_rows])
    row_of_image = np.full(est.num_images, -1)
    row_of_image[common] = np.arange(len(common))
    scene = Scene(gt.cameras, [gt.image_ids[j] for j in gt_rows],
                  [gt.names[j] for j in gt_rows], gt.camera_ids[gt_rows],
                  gt.R[gt_rows], gt.C[gt_rows], est.point_ids,
                  scale * est.points @ rotation.T + translation,
                  row_of_image[est.obs_image[keep]], est.obs_point[keep])
    return scene, sigma_px


def bound_for_reconstruction(gt_dir, model_dir, gauge="centers",
                             sigma_px=None):
    """scene_bound of the reconstruction's own tracks in the ground truth
    (reconstruction_scene), with its estimated pixel noise unless sigma_px
    is given; the result also holds sigma_px_estimated."""
    scene, estimated = reconstruction_scene(gt_dir, model_dir)
    result = scene_bound(scene, sigma_px or estimated, "pixel", gauge,
                         points=False)
    result["sigma_px_estimated"] = estimated
    return result


# ---------------------------------------------------------------------------
# Rigs

class Rig:
    """How the images of a scene are the lenses of a rig: per image (arrays
    over the scene's images) its frame index and sensor index; per frame
    R_f (rig_from_world) and C_f (the rig frame's origin in the world); per
    sensor its camera id, R_s (sensor_from_rig), c_s (its centre in the rig
    frame) and whether it is a rig's reference sensor (the rig frame itself:
    R_s = I, c_s = 0, not a parameter)."""

    def __init__(self, image_frame, image_sensor, R_f, C_f, camera_ids, R_s,
                 c_s, reference):
        self.image_frame = np.asarray(image_frame, dtype=int)
        self.image_sensor = np.asarray(image_sensor, dtype=int)
        self.R_f = np.asarray(R_f, dtype=float).reshape(-1, 3, 3)
        self.C_f = np.asarray(C_f, dtype=float).reshape(-1, 3)
        self.camera_ids = list(camera_ids)
        self.R_s = np.asarray(R_s, dtype=float).reshape(-1, 3, 3)
        self.c_s = np.asarray(c_s, dtype=float).reshape(-1, 3)
        self.reference = np.asarray(reference, dtype=bool)

    @property
    def num_frames(self):
        return len(self.R_f)

    def free_sensors(self):
        """Indices of the sensors whose pose in the rig is a parameter."""
        return np.flatnonzero(~self.reference)


def rig_of_scene(scene, gt_dir):
    """The Rig of the scene's images from the ground truth's rigs.txt and
    frames.txt (COLMAP 4 text): the images of one frame are its lenses; a
    frame's pose follows from any of its images and that lens's pose in the
    rig."""
    rigs = read_text_rigs(gt_dir)
    frame_of_image = {}
    for fields in read_text_rows(os.path.join(gt_dir, "frames.txt")):
        data = fields[10:]
        for k in range(0, len(data), 3):
            if data[k] == "CAMERA":
                frame_of_image[int(data[k + 2])] = int(fields[0])
    reference_ids = set()
    for fields in read_text_rows(os.path.join(gt_dir, "rigs.txt")):
        if int(fields[1]) > 0 and fields[2] == "CAMERA":
            reference_ids.add(int(fields[3]))
    image_frame, image_sensor, frames, sensors = [], [], {}, {}
    R_f, C_f, R_s, c_s, reference = [], [], [], [], []
    for j, image_id in enumerate(scene.image_ids):
        camera_id = int(scene.camera_ids[j])
        frame_id = frame_of_image.get(image_id)
        pose = next((rig[camera_id] for rig in rigs.values()
                     if rig.get(camera_id) is not None), None)
        if frame_id is None or pose is None:
            raise ValueError("image %s is in no frame of a rig with a pose "
                             "of its camera in %s" % (scene.names[j], gt_dir))
        if camera_id not in sensors:
            sensors[camera_id] = len(sensors)
            R_s.append(pose[0])
            c_s.append(-pose[0].T @ pose[1])
            reference.append(camera_id in reference_ids)
        s = sensors[camera_id]
        if frame_id not in frames:
            frames[frame_id] = len(frames)
            rotation = R_s[s].T @ scene.R[j]                 # R_f = R_s^T R_j
            R_f.append(rotation)
            C_f.append(scene.C[j] - rotation.T @ c_s[s])
        image_frame.append(frames[frame_id])
        image_sensor.append(s)
    return Rig(image_frame, image_sensor, R_f, C_f, list(sensors), R_s, c_s,
               reference)


def rig_jacobian(rig):
    """T (6N x 6F + 6S'): the image errors (omega_j, dC_j) of small
    changes of the frames (omega_f, dC_f) and of the free sensors
    (omega_s, dc_s), with R_f <- exp([omega_f]x) R_f, C_f <- C_f + dC_f,
    R_s <- exp([omega_s]x) R_s, c_s <- c_s + dc_s.  Image j (sensor s of
    frame f) has R_j = R_s R_f and C_j = C_f + R_f^T c_s, so to first order
      omega_j = R_s omega_f + omega_s,
      dC_j = dC_f + R_f^T [c_s]x omega_f + R_f^T dc_s."""
    N, F = len(rig.image_frame), rig.num_frames
    free = rig.free_sensors()
    column_of_sensor = np.full(len(rig.reference), -1)
    column_of_sensor[free] = 6 * F + 6 * np.arange(len(free))
    T = np.zeros((6 * N, 6 * F + 6 * len(free)))
    for j in range(N):
        f, s = rig.image_frame[j], rig.image_sensor[j]
        rows, frame = 6 * j, 6 * f
        T[rows:rows + 3, frame:frame + 3] = rig.R_s[s]
        T[rows + 3:rows + 6, frame:frame + 3] = rig.R_f[f].T @ skew(
            rig.c_s[s])
        T[rows + 3:rows + 6, frame + 3:frame + 6] = np.eye(3)
        if column_of_sensor[s] >= 0:
            c = column_of_sensor[s]
            T[rows:rows + 3, c:c + 3] = np.eye(3)
            T[rows + 3:rows + 6, c + 3:c + 6] = rig.R_f[f].T
    return T


def rig_bound(scene, rig, sigma, noise="pixel", gauge="centers",
              intrinsics=False):
    """Bound of the rig's free sensors (rotation and centre in the rig) and
    of its frames when the poses are estimated as a rig (frames and sensor
    poses, as the mapper's rig bundle adjustment does) instead of one pose
    per image: the images' reduced camera information S in the rig's
    parameters, T^T S T (T = rig_jacobian; a linear change of the image
    parameters, so eliminating the points first changes nothing), with the
    evaluator's alignment of the image centres, K T.  Returns {sensors:
    [{camera_id, name, rot_deg, centre}] (sqrt of the traces; centre in
    model units), frame_rot_rms_deg, frame_pos_rms, covariance, counts}.
    With intrinsics each lens's P camera parameters are estimated too
    (self-calibration; pixel noise): they follow the rig's parameters, one
    block per sensor, shared by the sensor's images."""
    check_alignable(scene, gauge)
    S, _, _ = reduced_camera_information(scene, sigma, noise,
                                         intrinsics=intrinsics)
    T = rig_jacobian(rig)
    K = alignment_map(scene, gauge)
    if intrinsics:
        N, R = scene.num_images, T.shape[1]
        D = S.shape[0] // N
        P = D - 6
        T_images, K_images = T, K
        T = np.zeros((D * N, R + P * len(rig.reference)))
        K = np.zeros((7, D * N))
        for j in range(N):
            s = rig.image_sensor[j]
            T[D * j:D * j + 6, :R] = T_images[6 * j:6 * j + 6]
            T[D * j + 6:D * j + D, R + P * s:R + P * s + P] = np.eye(P)
            K[:, D * j:D * j + 6] = K_images[:, 6 * j:6 * j + 6]
    cov = gauge_covariance(T.T @ S @ T, K @ T)
    F = rig.num_frames
    first_image = {s: j for j, s in reversed(list(enumerate(
        rig.image_sensor)))}
    sensors = []
    for k, s in enumerate(rig.free_sensors()):
        block = cov[6 * F + 6 * k:6 * F + 6 * k + 6,
                    6 * F + 6 * k:6 * F + 6 * k + 6]
        sensors.append({
            "camera_id": rig.camera_ids[s],
            "name": scene.names[first_image[s]].split("/")[0],
            "rot_deg": math.degrees(math.sqrt(max(np.trace(block[:3, :3]),
                                                  0))),
            "centre": math.sqrt(max(np.trace(block[3:, 3:]), 0))})
    rot = [np.trace(cov[6 * f:6 * f + 3, 6 * f:6 * f + 3]) for f in range(F)]
    pos = [np.trace(cov[6 * f + 3:6 * f + 6, 6 * f + 3:6 * f + 6])
           for f in range(F)]
    return {"sensors": sensors, "num_frames": F, "covariance": cov,
            "frame_rot_rms_deg": math.degrees(math.sqrt(max(np.mean(rot),
                                                            0))),
            "frame_pos_rms": math.sqrt(max(np.mean(pos), 0)),
            "num_images": scene.num_images, "num_points": scene.num_points,
            "num_observations": len(scene.obs_image), "sigma": sigma,
            "noise": noise, "gauge": gauge, "intrinsics": intrinsics}


def format_rig_report(result):
    lines = ["Rig bound: %d frames (%d images), %d points, %d observations, "
             "%s noise sigma = %.4g, gauge: %s alignment, intrinsics %s" % (
                 result["num_frames"], result["num_images"],
                 result["num_points"], result["num_observations"],
                 result["noise"], result["sigma"], result["gauge"],
                 "estimated" if result["intrinsics"] else "known"),
             "%9s  %-12s  %14s  %14s" % ("camera_id", "lens",
                                         "rotation (deg)", "centre")]
    for r in result["sensors"]:
        lines.append("%9d  %-12s  %14.6g  %14.6g" % (
            r["camera_id"], r["name"][:12], r["rot_deg"], r["centre"]))
    lines.append("frames RMS:             rot %.6g deg, pos %.6g" % (
        result["frame_rot_rms_deg"], result["frame_pos_rms"]))
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# Command line

def format_report(result):
    unit = "px" if result["noise"] == "pixel" else "rad"
    lines = ["Cramer-Rao bound: %d images, %d points, %d observations, "
             "%s noise sigma = %.4g %s, gauge: %s alignment" % (
                 result["num_images"], result["num_points"],
                 result["num_observations"], result["noise"],
                 result["sigma"], unit, result["gauge"]),
             "%8s  %-20s %6s  %12s  %12s" % ("image_id", "name", "obs",
                                             "rot (deg)", "pos")]
    for r in result["images"]:
        lines.append("%8d  %-20s %6d  %12.6g  %12.6g" % (
            r["image_id"], r["name"][:20], r["num_observations"],
            r["rot_deg"], r["pos"]))
    lines.append("RMS over images:        rot %.6g deg, pos %.6g" % (
        result["rot_rms_deg"], result["pos_rms"]))
    lines.append("mean of sqrt(trace):    rot %.6g deg, pos %.6g" % (
        result["rot_mean_deg"], result["pos_mean"]))
    lines.append("expected mean error:    rot %.6g deg, pos %.6g" % (
        result["rot_expected_mean_deg"], result["pos_expected_mean"]))
    if result["point_rms"] is not None:
        lines.append("points RMS:             %.6g" % result["point_rms"])
    return "\n".join(lines)


def write_csv(result, path):
    keys = ["image_id", "name", "num_observations", "rot_deg", "pos",
            "rot_expected_deg", "pos_expected"]
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(keys)
        for r in result["images"]:
            writer.writerow([r[k] for k in keys])
        for label, rot, pos in (
                ("RMS", "rot_rms_deg", "pos_rms"),
                ("mean", "rot_mean_deg", "pos_mean"),
                ("expected_mean", "rot_expected_mean_deg",
                 "pos_expected_mean")):
            writer.writerow(["", label, result["num_observations"],
                             result[rot], result[pos], "", ""])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--gt_model", required=True,
                        help="COLMAP text model with the observations")
    parser.add_argument("--noise", choices=("pixel", "angle"))
    parser.add_argument("--sigma_px", type=float)
    parser.add_argument("--sigma_deg", type=float)
    parser.add_argument("--gauge", choices=GAUGES, default="centers",
                        help="model_evaluator --alignment whose errors are "
                        "bounded (default: centers)")
    parser.add_argument("--no_points", action="store_true",
                        help="skip the point bound")
    parser.add_argument("--model",
                        help="text model of a reconstruction of the scene: "
                        "bound its own tracks in the ground-truth poses, "
                        "pixel noise estimated from its residuals unless "
                        "--sigma_px is given")
    parser.add_argument("--rig", action="store_true",
                        help="bound the scene as a rig (the ground truth's "
                        "rigs.txt and frames.txt): each lens's rotation and "
                        "centre in the rig and the frames, as a rig's bundle "
                        "adjustment estimates them")
    parser.add_argument("--intrinsics", action="store_true",
                        help="with --rig: the lenses' focal lengths and "
                        "distortion are estimated too (self-calibration, the "
                        "principal point held as COLMAP's bundle adjustment "
                        "holds it by default), not known")
    parser.add_argument("--csv", help="write the per-image (with --rig: "
                        "per-lens) table here")
    args = parser.parse_args(argv)
    noise = args.noise or ("angle" if args.sigma_deg is not None
                           else "pixel")
    sigma = args.sigma_px if noise == "pixel" else args.sigma_deg
    if args.model and (noise != "pixel" or not (sigma is None or sigma > 0)):
        parser.error("--model bounds pixel noise: give no --sigma_deg, and "
                     "--sigma_px only to override the estimate")
    if not args.model and (
            sigma is None or (args.sigma_px is not None and
                              args.sigma_deg is not None) or not sigma > 0):
        parser.error("give one positive --sigma_px (pixel noise) or "
                     "--sigma_deg (angle noise)")
    if args.intrinsics and not args.rig:
        parser.error("--intrinsics bounds a rig's self-calibration: give "
                     "--rig too")
    start = time.time()
    try:
        if args.rig:
            if args.model:
                scene, estimated = reconstruction_scene(args.gt_model,
                                                        args.model)
                print("pixel noise estimated from the model's residuals: "
                      "%.4g px" % estimated)
                sigma = sigma or estimated
            else:
                scene = scene_from_model(args.gt_model)
                sigma = math.radians(sigma) if noise == "angle" else sigma
            result = rig_bound(scene, rig_of_scene(scene, args.gt_model),
                               sigma, noise, args.gauge, args.intrinsics)
        elif args.model:
            result = bound_for_reconstruction(args.gt_model, args.model,
                                              args.gauge, sigma)
            print("pixel noise estimated from the model's residuals: "
                  "%.4g px" % result["sigma_px_estimated"])
        else:
            result = bound_for_model(args.gt_model, sigma, noise, args.gauge,
                                     not args.no_points)
    except (OSError, ValueError) as e:
        print("error: %s" % e, file=sys.stderr)
        return 1
    print(format_rig_report(result) if args.rig else format_report(result))
    print("time %.2f s" % (time.time() - start))
    if args.csv and args.rig:
        with open(args.csv, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(["camera_id", "lens", "rot_deg", "centre"])
            for r in result["sensors"]:
                writer.writerow([r["camera_id"], r["name"], r["rot_deg"],
                                 r["centre"]])
    elif args.csv:
        write_csv(result, args.csv)
    return 0


if __name__ == "__main__":
    sys.exit(main())
