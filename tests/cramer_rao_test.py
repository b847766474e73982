"""scripts/cramer_rao.py: closed-form bounds, the gauge, a Monte-Carlo check
of the bound against bundle adjustment, and reading a text model.

Closed forms (one camera, points known exactly, so no gauge):

  Angle noise.  The whitened Jacobian of observation i with respect to the
  rotation omega is B^T (-[y]x) / (sigma d), d = |y|, B an orthonormal
  basis of the plane orthogonal to b = y / d; since [b]x v is orthogonal to
  b, its information is [b]x^T [b]x / sigma^2 = (I - b b^T) / sigma^2.
  With respect to the centre it is R^T (I - b b^T) R / (sigma d)^2, and the
  cross term is -[sum_i b_i / d_i]x R / sigma^2.  For shells of points at
  distance d_s whose directions are the vertices of a regular polyhedron
  (icosahedron, cube, octahedron: sum b = 0, sum b b^T = n/3 I), the cross
  term vanishes and
    I_omega = 2N / (3 sigma^2) I,  I_C = (2 / (3 sigma^2)) sum_s n_s / d_s^2 I,
    sigma_rot = sqrt(trace I_omega^-1) = 3 sigma / sqrt(2N),
    sigma_pos = 3 sigma / sqrt(2 sum_s n_s / d_s^2).

  Pixel noise, pinhole (fx = fy = f).  With m = (x/z, y/z) the pixel
  derivative with respect to the rotation (camera frame) is
    d u / d omega = f [[-mx my, 1 + mx^2, -my], [-(1 + my^2), mx my, mx]]
  (columns omega_x, omega_y, omega_z), and with respect to the centre in
  the camera frame -f / z [[1, 0, -mx], [0, 1, -my]].  On a grid symmetric
  under mx -> -mx and my -> -my (depths symmetric too) every off-diagonal
  sum is odd and vanishes, so with the position known
    sigma_rot^2 = sigma^2 / f^2 (1 / sum(mx^2 my^2 + (1 + my^2)^2)
                  + 1 / sum((1 + mx^2)^2 + mx^2 my^2) + 1 / sum(mx^2 + my^2))
  and with the rotation known
    sigma_pos^2 = sigma^2 / f^2 (2 / sum z^-2 + 1 / sum(|m|^2 / z^2)).
"""
import contextlib
import io
import math
import os
import sys
import tempfile
import shutil
import unittest

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "scripts"))
import cramer_rao as crb  # noqa: E402

PINHOLE = ("PINHOLE", 640, 480, [300.0, 300.0, 320.0, 240.0])


def polyhedron(kind):
    """Unit vertex directions of a regular polyhedron."""
    if kind == "octahedron":
        v = np.concatenate([np.eye(3), -np.eye(3)])
    elif kind == "cube":
        v = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1)
                      for c in (-1, 1)], float)
    else:  # icosahedron
        g = (1 + math.sqrt(5)) / 2
        v = []
        for a in (-1, 1):
            for b in (-g, g):
                v += [[0, a, b], [a, b, 0], [b, 0, a]]
        v = np.array(v, float)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def random_rotation(rng):
    return Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()


def look_at(centre, target, rng, jitter=0.05):
    """cam_from_world R whose +z looks from centre at target (+y down-ish)."""
    z = target - centre
    z /= np.linalg.norm(z)
    x = np.cross([0, 1.0, 0], z)
    x /= np.linalg.norm(x)
    R = np.stack([x, np.cross(z, x), z])
    return Rotation.from_rotvec(rng.normal(0, jitter, 3)).as_matrix() @ R


def ring_scene(num_cameras, num_points, seed, cameras=None):
    """Cameras on a circle of radius 2 (heights varied) looking at points in
    the unit ball around the origin; every point seen by every camera
    (within 30 degrees of the axis).  cameras: {id: camera}, assigned
    cyclically; default one PINHOLE."""
    rng = np.random.default_rng(seed)
    cameras = cameras or {1: PINHOLE}
    ids = sorted(cameras)
    angles = np.linspace(0, 2 * np.pi, num_cameras, endpoint=False)
    C = np.stack([2 * np.cos(angles), rng.normal(0, 0.2, num_cameras),
                  2 * np.sin(angles)], axis=1)
    R = [look_at(c, np.zeros(3), rng) for c in C]
    X = rng.normal(size=(num_points, 3))
    X *= (rng.random(num_points) ** (1 / 3) /
          np.linalg.norm(X, axis=1))[:, None]
    obs_image = np.repeat(np.arange(num_cameras), num_points)
    obs_point = np.tile(np.arange(num_points), num_cameras)
    return crb.Scene(cameras, range(1, num_cameras + 1),
                     ["img%d.jpg" % j for j in range(num_cameras)],
                     [ids[j % len(ids)] for j in range(num_cameras)], R, C,
                     range(1, num_points + 1), X, obs_image, obs_point)


class ClosedFormTest(unittest.TestCase):
    def test_angle_noise_polyhedra(self):
        rng = np.random.default_rng(1)
        R, C = random_rotation(rng), rng.normal(size=3)
        shells = [("icosahedron", 2.0), ("cube", 3.5), ("octahedron", 1.2)]
        X = np.concatenate([C + d * polyhedron(k) @ random_rotation(rng).T
                            for k, d in shells])
        n = [12, 8, 6]
        sigma = 1e-3
        cov = crb.known_points_covariance(R, C, X, PINHOLE, sigma, "angle")
        sigma_rot = math.sqrt(np.trace(cov[:3, :3]))
        sigma_pos = math.sqrt(np.trace(cov[3:, 3:]))
        expected_rot = 3 * sigma / math.sqrt(2 * sum(n))
        expected_pos = 3 * sigma / math.sqrt(
            2 * sum(k / d ** 2 for k, (_, d) in zip(n, shells)))
        self.assertAlmostEqual(sigma_rot / expected_rot, 1, delta=1e-6)
        self.assertAlmostEqual(sigma_pos / expected_pos, 1, delta=1e-6)
        # The information itself is isotropic and block diagonal.
        info = crb.known_points_information(R, C, X, PINHOLE, sigma, "angle")
        np.testing.assert_allclose(info[:3, :3],
                                   2 * sum(n) / (3 * sigma ** 2) * np.eye(3),
                                   rtol=1e-9, atol=1e-9 * info[0, 0])
        self.assertLess(np.abs(info[:3, 3:]).max(), 1e-9 * info[0, 0])

    def pinhole_grid(self, rng):
        R, C = random_rotation(rng), rng.normal(size=3)
        g = np.array([-0.6, -0.3, -0.1, 0.1, 0.3, 0.6])
        mx, my = [a.ravel() for a in np.meshgrid(g, g)]
        z = 2 + np.abs(mx) + 3 * np.abs(my)   # symmetric depths
        X = C + np.stack([mx * z, my * z, z], axis=1) @ R
        return R, C, mx, my, z, X

    def test_pinhole_rotation_only(self):
        rng = np.random.default_rng(2)
        R, C, mx, my, _, X = self.pinhole_grid(rng)
        f, sigma = PINHOLE[3][0], 0.7
        cov = crb.known_points_covariance(R, C, X, PINHOLE, sigma, "pixel",
                                          free="rotation")
        expected = sigma / f * math.sqrt(
            1 / np.sum(mx ** 2 * my ** 2 + (1 + my ** 2) ** 2) +
            1 / np.sum((1 + mx ** 2) ** 2 + mx ** 2 * my ** 2) +
            1 / np.sum(mx ** 2 + my ** 2))
        self.assertAlmostEqual(math.sqrt(np.trace(cov)) / expected, 1,
                               delta=1e-6)
        # Rotation about the optical axis alone: 1 / I_zz.
        info = crb.known_points_information(R, C, X, PINHOLE, sigma, "pixel")
        self.assertAlmostEqual(
            info[2, 2] * sigma ** 2 / (f ** 2 * np.sum(mx ** 2 + my ** 2)), 1,
            delta=1e-9)

    def test_pinhole_position_only(self):
        rng = np.random.default_rng(3)
        R, C, mx, my, z, X = self.pinhole_grid(rng)
        f, sigma = PINHOLE[3][0], 0.3
        cov = crb.known_points_covariance(R, C, X, PINHOLE, sigma, "pixel",
                                          free="position")
        expected = sigma / f * math.sqrt(
            2 / np.sum(z ** -2.0) + 1 / np.sum((mx ** 2 + my ** 2) / z ** 2))
        self.assertAlmostEqual(math.sqrt(np.trace(cov)) / expected, 1,
                               delta=1e-6)


class ProjectionTest(unittest.TestCase):
    """The central differences of the fisheye models against the analytic
    pinhole Jacobian where they coincide, and the analytic equirect
    Jacobian against central differences: all < 1e-6 relative (the bound
    needs < 0.1 %)."""

    def rays(self, n=50, half_angle=0.8):
        rng = np.random.default_rng(4)
        v = rng.normal(size=(n, 2)) * 0.4
        y = np.concatenate([v, np.ones((n, 1))], axis=1)
        return y * rng.uniform(0.5, 5, (n, 1))

    def test_fisheye_models_reduce_to_pinhole(self):
        y = self.rays()
        ref = crb.projection_jacobian(PINHOLE, y)
        k = [300.0, 300.0, 320.0, 240.0]
        for camera in [("EUCM", 640, 480, k + [0.0, 1.0]),
                       ("UNIFIED_OMNI", 640, 480, k + [0.0, 0, 0, 0, 0]),
                       ("DOUBLE_SPHERE", 640, 480, k + [0.0, 0.0]),
                       ("OPENCV", 640, 480, k + [0, 0, 0, 0])]:
            np.testing.assert_allclose(crb.project(camera, y),
                                       crb.project(PINHOLE, y), rtol=1e-12)
            J = crb.projection_jacobian(camera, y)
            err = np.abs(J - ref).max() / np.abs(ref).max()
            self.assertLess(err, 1e-6, camera[0])

    def test_fisheye_finite_differences_converged(self):
        # A 10x smaller step changes the Jacobian by < 1e-6 relative.
        y = self.rays() * np.array([3, 3, 1.0])   # up to ~75 degrees
        for camera in [("EUCM", 1024, 1024, [400, 410, 512, 500, 0.6, 1.1]),
                       ("UNIFIED_OMNI", 1024, 1024,
                        [450, 450, 512, 512, 1.0, -0.1, 0.02, 1e-3, -1e-3]),
                       ("DOUBLE_SPHERE", 1024, 1024,
                        [350, 350, 512, 512, -0.2, 0.6]),
                       ("OPENCV_FISHEYE", 1024, 1024,
                        [300, 300, 512, 512, -0.012, 0.0016, -0.0002, 0]),
                       ("OCAM", 1024, 1024,
                        [512, 500, 1.0005, 2e-4, -3e-4, -300, 1.25e-3,
                         -9.7e-7, 2.5e-9])]:
            J = crb.projection_jacobian(camera, y)
            saved = crb.FD_STEP
            try:
                crb.FD_STEP = saved / 10
                J2 = crb.projection_jacobian(camera, y)
            finally:
                crb.FD_STEP = saved
            self.assertLess(np.abs(J - J2).max() / np.abs(J).max(), 1e-6)

    def test_equirect_jacobian(self):
        camera = ("EQUIRECTANGULAR", 2048, 1024, [2048.0, 1024.0])
        rng = np.random.default_rng(5)
        y = rng.normal(size=(200, 3))
        y = y[np.abs(np.arctan2(y[:, 0], y[:, 2])) < 3.0]  # off the seam
        J = crb.projection_jacobian(camera, y)
        h = 1e-6
        for a in range(3):
            e = np.zeros(3)
            e[a] = h
            fd = (crb.project(camera, y + e) -
                  crb.project(camera, y - e)) / (2 * h)
            np.testing.assert_allclose(J[:, :, a], fd, rtol=1e-6,
                                       atol=1e-6 * np.abs(J).max())
        # Projection conventions (equirectangular.h): +z is the centre,
        # +x to the right, -y (up) to the top.
        np.testing.assert_allclose(
            crb.project(camera, np.array([[0, 0, 1.0], [1.0, 0, 0],
                                          [0, -1.0, 1e-12]])),
            [[1024, 512], [1536, 512], [1024, 0]], atol=1e-6)


def rank_by_gap(eigenvalues, expected_null):
    """The expected_null smallest |eigenvalues| are tiny and well separated
    from the rest."""
    w = np.sort(np.abs(eigenvalues))
    return w[expected_null - 1] / w[-1], w[expected_null] / w[-1]


class GaugeTest(unittest.TestCase):
    CAMERAS = {1: PINHOLE,
               2: ("EQUIRECTANGULAR", 2048, 1024, [2048.0, 1024.0]),
               3: ("UNIFIED_OMNI", 1024, 1024,
                   [450, 450, 512, 512, 1.0, 0, 0, 0, 0]),
               4: ("DOUBLE_SPHERE", 1024, 1024,
                   [350, 350, 512, 512, -0.2, 0.6]),
               5: ("EUCM", 1024, 1024, [400, 410, 512, 500, 0.6, 1.1])}

    def setUp(self):
        self.scene = ring_scene(5, 200, seed=6, cameras=self.CAMERAS)

    def test_similarity_in_null_space(self):
        N, M = 5, 200
        for noise, sigma in (("pixel", 0.5), ("angle", 1e-3)):
            F = crb.full_information(self.scene, sigma, noise)
            G = crb.gauge_generators(self.scene, with_points=True)
            for col in G.T:
                rel = (np.linalg.norm(F @ col) /
                       (np.linalg.norm(F, 2) * np.linalg.norm(col)))
                self.assertLess(rel, 1e-8)
            small, large = rank_by_gap(np.linalg.eigvalsh(F), 7)
            self.assertLess(small, 1e-12)     # rank 6N + 3M - 7
            self.assertGreater(large, 1e-9)
            S, _, _ = crb.reduced_camera_information(self.scene, sigma, noise)
            small, large = rank_by_gap(np.linalg.eigvalsh(S), 7)
            self.assertLess(small, 1e-12)     # rank 6N - 7
            self.assertGreater(large, 1e-6)
            self.assertEqual(F.shape[0], 6 * N + 3 * M)

    def test_reduced_equals_dense_schur(self):
        F = crb.full_information(self.scene, 0.5, "pixel")
        S, _, _ = crb.reduced_camera_information(self.scene, 0.5, "pixel")
        n = 6 * self.scene.num_images
        dense = F[:n, :n] - F[:n, n:] @ np.linalg.solve(F[n:, n:], F[n:, :n])
        np.testing.assert_allclose(S, dense, atol=1e-9 * np.abs(dense).max())

    def test_covariance_is_projected_pseudo_inverse(self):
        # Q (Q^T S Q)^-1 Q^T = Pi S^+ Pi^T, Pi = I - G K.
        S, _, _ = crb.reduced_camera_information(self.scene, 0.5, "pixel")
        G = crb.gauge_generators(self.scene)
        for gauge in crb.GAUGES:
            K = crb.alignment_map(self.scene, gauge)
            np.testing.assert_allclose(K @ G, np.eye(7), atol=1e-12)
            Pi = np.eye(len(S)) - G @ K
            cov = crb.gauge_covariance(S, K)
            ref = Pi @ np.linalg.pinv(S, rcond=1e-13, hermitian=True) @ Pi.T
            np.testing.assert_allclose(cov, ref,
                                       atol=1e-6 * np.abs(ref).max())

    def test_point_covariances_are_projected_pseudo_inverse(self):
        scene = ring_scene(5, 60, seed=12, cameras=self.CAMERAS)
        F = crb.full_information(scene, 0.5, "pixel")
        S, Y, Vinv = crb.reduced_camera_information(scene, 0.5, "pixel")
        G = crb.gauge_generators(scene, with_points=True)
        n = 6 * scene.num_images
        for gauge in crb.GAUGES:
            K = np.zeros((7, len(F)))
            K[:, :n] = crb.alignment_map(scene, gauge)
            Pi = np.eye(len(F)) - G @ K
            ref = Pi @ np.linalg.pinv(F, rcond=1e-14, hermitian=True) @ Pi.T
            cov = crb.gauge_covariance(S, K[:, :n])
            np.testing.assert_allclose(cov, ref[:n, :n],
                                       atol=1e-6 * np.abs(cov).max())
            points = crb.point_covariances(cov, Y, Vinv)
            for i in range(scene.num_points):
                block = ref[n + 3 * i:n + 3 * i + 3, n + 3 * i:n + 3 * i + 3]
                np.testing.assert_allclose(points[i], block, rtol=1e-5,
                                           atol=1e-6 * np.abs(block).max())

    def test_invariant_under_similarity(self):
        rng = np.random.default_rng(7)
        Q, t, s = random_rotation(rng), rng.normal(size=3) * 10, 2.5
        moved = crb.transform_scene(self.scene, Q, t, s)
        for noise, sigma in (("pixel", 0.5), ("angle", 1e-3)):
            for gauge in crb.GAUGES:
                a = crb.scene_bound(self.scene, sigma, noise, gauge)
                b = crb.scene_bound(moved, sigma, noise, gauge)
                for ra, rb in zip(a["images"], b["images"]):
                    self.assertAlmostEqual(rb["rot_deg"] / ra["rot_deg"], 1,
                                           delta=1e-6)
                    self.assertAlmostEqual(rb["pos"] / ra["pos"], s,
                                           delta=1e-6 * s)
                self.assertAlmostEqual(b["point_rms"] / a["point_rms"], s,
                                       delta=1e-6 * s)

    def test_undefined_alignment_rejected(self):
        # Collinear centres: no rotation from the centres (the evaluator
        # takes it from the orientations); coincident centres: no scale.
        scene = ring_scene(3, 50, seed=8)
        rng = np.random.default_rng(8)
        scene.C[:] = [[-1, 0, -3.0], [0, 0, -3], [1, 0, -3]]
        scene.R[:] = [look_at(c, np.zeros(3), rng) for c in scene.C]
        with self.assertRaises(ValueError):
            crb.scene_bound(scene, 0.5, gauge="centers")
        crb.scene_bound(scene, 0.5, gauge="orientations")
        scene.C[:] = [0, 0, -2.0]
        with self.assertRaises(ValueError):
            crb.scene_bound(scene, 0.5, gauge="orientations")

    def test_unconstrained_image_rejected(self):
        scene = ring_scene(4, 50, seed=8)
        keep = (scene.obs_image != 3) | (scene.obs_point < 2)
        scene.obs_image = scene.obs_image[keep]
        scene.obs_point = scene.obs_point[keep]
        with self.assertRaises(ValueError):
            crb.scene_bound(scene, 0.5)


# ---------------------------------------------------------------------------
# Monte Carlo: bundle adjustment of noisy pinhole observations


def pinhole_residuals(camera, R, C, X, obs_image, obs_point, observed):
    """Residuals (K,2) and the Jacobians (K,2,6), (K,2,3) in the parameters
    (omega, C) and X; written independently of cramer_rao.py."""
    f, cx, cy = camera[3][0], camera[3][2], camera[3][3]
    Rk = R[obs_image]
    y = np.einsum("kab,kb->ka", Rk, X[obs_point] - C[obs_image])
    x, yy, z = y.T
    r = np.stack([f * x / z + cx, f * yy / z + cy], 1) - observed
    Jy = np.zeros((len(y), 2, 3))
    Jy[:, 0, 0] = f / z
    Jy[:, 1, 1] = f / z
    Jy[:, 0, 2] = -f * x / z ** 2
    Jy[:, 1, 2] = -f * yy / z ** 2
    # omega: exp([w]x) y = y + w x y, d/dw = -[y]x.
    yx = np.zeros((len(y), 3, 3))
    yx[:, 0, 1], yx[:, 0, 2], yx[:, 1, 2] = -z, yy, -x
    yx = yx - np.transpose(yx, (0, 2, 1))
    Jc = np.concatenate([-Jy @ yx, -Jy @ Rk], axis=2)
    return r, Jc, Jy @ Rk


def bundle_adjust(scene, observed, iterations=4):
    """Gauss-Newton from the ground truth, minimum-norm steps."""
    camera = scene.cameras[1]
    R, C, X = scene.R.copy(), scene.C.copy(), scene.points.copy()
    N, M = scene.num_images, scene.num_points
    rows = np.arange(2 * len(observed)).reshape(-1, 2)
    for _ in range(iterations):
        r, Jc, Jp = pinhole_residuals(camera, R, C, X, scene.obs_image,
                                      scene.obs_point, observed)
        J = np.zeros((2 * len(r), 6 * N + 3 * M))
        cam_cols = 6 * scene.obs_image[:, None] + np.arange(6)
        pt_cols = 6 * N + 3 * scene.obs_point[:, None] + np.arange(3)
        J[rows[:, :, None], cam_cols[:, None, :]] = Jc
        J[rows[:, :, None], pt_cols[:, None, :]] = Jp
        H = J.T @ J
        step = -np.linalg.solve(H + 1e-9 * np.trace(H) / len(H) *
                                np.eye(len(H)), J.T @ r.ravel())
        cam = step[:6 * N].reshape(N, 6)
        R = Rotation.from_rotvec(cam[:, :3]).as_matrix() @ R
        C = C + cam[:, 3:]
        X = X + step[6 * N:].reshape(M, 3)
    return R, C, X


def aligned_errors(scene, R, C, gauge):
    """(rotation angles, centre errors) per image after aligning (R, C) to
    the ground truth: centres = Umeyama on the centres; evaluator = world
    rotation as the chordal mean of R_gt^T R_est, then scale and
    translation on the centres."""
    gt_c = scene.C - scene.C.mean(0)
    est_c = C - C.mean(0)
    if gauge == "centers":
        u, sv, vt = np.linalg.svd(gt_c.T @ est_c)
        D = np.diag([1, 1, np.sign(np.linalg.det(u @ vt))])
        Q = u @ D @ vt
    else:
        mean = sum(g.T @ e for g, e in zip(scene.R, R))
        u, _, vt = np.linalg.svd(mean)
        Q = u @ np.diag([1, 1, np.linalg.det(u @ vt)]) @ vt
    rotated = est_c @ Q.T
    s = (rotated * gt_c).sum() / (rotated ** 2).sum()
    pos = np.linalg.norm(s * rotated - gt_c, axis=1)
    rot = [np.linalg.norm(Rotation.from_matrix(g @ Q @ e.T).as_rotvec())
           for g, e in zip(scene.R, R)]
    return np.array(rot), pos


class MonteCarloTest(unittest.TestCase):
    """RMS errors of bundle adjustment over T = 100 noisy trials against the
    bound.  The sample mean square of the errors over T trials and 4 images
    (3 components each) has at least 3T effective degrees of freedom, so a
    relative standard deviation of at most sqrt(2 / 300) = 8 %, i.e. 4 % on
    the RMS; the second-order bias at sigma / f = 1.7e-3 is negligible.  A
    15 % tolerance is > 3 standard deviations (the seed is fixed)."""

    def test_bundle_adjustment_reaches_bound(self):
        scene = ring_scene(4, 100, seed=9)
        sigma = 0.5
        exact = crb.projections(scene)
        rng = np.random.default_rng(10)
        errors = {g: ([], []) for g in crb.GAUGES}
        for _ in range(100):
            R, C, _ = bundle_adjust(scene, exact + rng.normal(0, sigma,
                                                              exact.shape))
            for gauge in crb.GAUGES:
                rot, pos = aligned_errors(scene, R, C, gauge)
                errors[gauge][0].extend(rot)
                errors[gauge][1].extend(pos)
        for gauge in crb.GAUGES:
            bound = crb.scene_bound(scene, sigma, "pixel", gauge)
            rot_rms = math.degrees(np.sqrt(np.mean(np.square(
                errors[gauge][0]))))
            pos_rms = np.sqrt(np.mean(np.square(errors[gauge][1])))
            self.assertAlmostEqual(rot_rms / bound["rot_rms_deg"], 1,
                                   delta=0.15, msg=gauge)
            self.assertAlmostEqual(pos_rms / bound["pos_rms"], 1,
                                   delta=0.15, msg=gauge)


# ---------------------------------------------------------------------------
# Text model


def write_text_model(scene, path, pixels=None):
    """COLMAP text model of the scene, POINTS2D the exact projections or
    PIXELS (K, 2), one per observation."""
    if pixels is None:
        pixels = crb.projections(scene)
    os.makedirs(path, exist_ok=True)
    with open(os.path.join(path, "cameras.txt"), "w") as f:
        for cid, (model, w, h, params) in scene.cameras.items():
            f.write("%d %s %d %d %s\n" % (cid, model, w, h,
                                          " ".join(map(repr, params))))
    tracks = {i: [] for i in range(scene.num_points)}
    with open(os.path.join(path, "images.txt"), "w") as f:
        f.write("# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n")
        for j in range(scene.num_images):
            x, y, z, w = Rotation.from_matrix(scene.R[j]).as_quat()
            t = -scene.R[j] @ scene.C[j]
            f.write("%d %s %d %s\n" % (
                scene.image_ids[j], " ".join(map(repr, [w, x, y, z, *t])),
                scene.camera_ids[j], scene.names[j]))
            sel = np.flatnonzero(scene.obs_image == j)
            entries = []
            for idx, (k, uv) in enumerate(zip(sel, pixels[sel])):
                i = scene.obs_point[k]
                tracks[i].append((scene.image_ids[j], idx))
                entries.append("%r %r %d" % (uv[0], uv[1],
                                             scene.point_ids[i]))
            f.write(" ".join(entries) + "\n")
    with open(os.path.join(path, "points3D.txt"), "w") as f:
        for i in range(scene.num_points):
            track = " ".join("%d %d" % e for e in tracks[i])
            f.write("%d %s 128 128 128 0 %s\n" % (
                scene.point_ids[i], " ".join(map(repr, scene.points[i])),
                track))


class TextModelTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="cramer_rao_test_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def test_same_bound_as_in_memory(self):
        scene = ring_scene(4, 30, seed=11, cameras=GaugeTest.CAMERAS)
        # A point seen once and an image id gap must not matter.
        keep = (scene.obs_point != 5) | (scene.obs_image == 0)
        scene.obs_image = scene.obs_image[keep]
        scene.obs_point = scene.obs_point[keep]
        scene.image_ids = [1, 2, 5, 7]
        path = os.path.join(self.tmp, "sparse_gt")
        write_text_model(scene, path)
        for noise, sigma, sigma_arg in (("pixel", 0.5, 0.5),
                                        ("angle", math.radians(0.01), 0.01)):
            a = crb.scene_bound(scene, sigma, noise)
            b = crb.bound_for_model(path, sigma_arg, noise)
            self.assertEqual(b["num_observations"], len(scene.obs_image))
            for key in ("rot_rms_deg", "pos_rms", "rot_mean_deg",
                        "pos_mean", "point_rms"):
                self.assertAlmostEqual(b[key] / a[key], 1, delta=1e-9, msg=key)
            self.assertEqual([r["name"] for r in b["images"]], scene.names)
        # The command line prints the table and writes the CSV.
        csv_path = os.path.join(self.tmp, "bound.csv")
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            self.assertEqual(crb.main(["--gt_model", path, "--sigma_px",
                                       "0.5", "--csv", csv_path]), 0)
        self.assertIn("RMS over images", out.getvalue())
        with open(csv_path) as f:
            lines = f.read().splitlines()
        self.assertEqual(len(lines), 1 + 4 + 3)


class ReconstructionBoundTest(unittest.TestCase):
    """The bound of a reconstruction's own tracks: a bundle adjustment of
    noisy observations (sigma = 0.4 px) in a world moved by a similarity,
    written as text models; the noise is recovered from its residuals and
    the bound is the ground truth's."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="cramer_rao_test_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def test_noise_and_bound_of_a_reconstruction(self):
        scene = ring_scene(4, 100, seed=21)
        sigma = 0.4
        observed = crb.projections(scene) + np.random.default_rng(22).normal(
            0, sigma, (len(scene.obs_image), 2))
        R, C, X = bundle_adjust(scene, observed)
        estimate = crb.transform_scene(
            crb.Scene(scene.cameras, scene.image_ids, scene.names,
                      scene.camera_ids, R, C, scene.point_ids, X,
                      scene.obs_image, scene.obs_point),
            random_rotation(np.random.default_rng(23)),
            np.array([3.0, -1.0, 2.0]), 2.5)
        gt_path = os.path.join(self.tmp, "gt")
        est_path = os.path.join(self.tmp, "est")
        write_text_model(scene, gt_path)
        write_text_model(estimate, est_path, observed)
        rebuilt, sigma_estimated = crb.reconstruction_scene(gt_path,
                                                            est_path)
        # 800 residuals, 317 parameters: sigma^2 has a relative spread of
        # sqrt(2 / 483) = 6 %, sigma 3 %; 10 % is over 3 spreads.
        self.assertAlmostEqual(sigma_estimated / sigma, 1, delta=0.1)
        # The points come back into the ground-truth frame within the noise.
        self.assertLess(np.abs(rebuilt.points - scene.points).max(), 0.02)
        self.assertTrue(np.allclose(rebuilt.C, scene.C))
        expected = crb.scene_bound(scene, sigma, "pixel", points=False)
        bound = crb.bound_for_reconstruction(gt_path, est_path,
                                             sigma_px=sigma)
        self.assertEqual(bound["sigma_px_estimated"], sigma_estimated)
        for key in ("rot_expected_mean_deg", "pos_expected_mean"):
            self.assertAlmostEqual(bound[key] / expected[key], 1, delta=0.02,
                                   msg=key)
        # Images outside the ground truth are refused when fewer than 3
        # remain.
        with open(os.path.join(gt_path, "images.txt")) as f:
            lines = f.read().splitlines()
        with open(os.path.join(gt_path, "images.txt"), "w") as f:
            f.write("\n".join(lines[:5]) + "\n")
        with self.assertRaises(ValueError):
            crb.reconstruction_scene(gt_path, est_path)


# ---------------------------------------------------------------------------
# Rigs

KB_LENS = [150.0, 150.0, 400.0, 400.0, -0.012, 0.0016, -0.0002, 0.0]


def dual_fisheye_rig_scene(num_frames=6, num_points=400, seed=5):
    """(scene, rig): two 200-degree Kannala-Brandt lenses back to back, 3 cm
    apart (lens 1 turned 180 degrees about y, its centre at z = -3 cm in
    the rig), on frames along a path in a shell of points 1.5 to 4 m
    away; a lens sees the points within 100 degrees of its axis."""
    rng = np.random.default_rng(seed)
    R_s = [np.eye(3), Rotation.from_euler("y", 180, degrees=True).as_matrix()]
    c_s = [np.zeros(3), np.array([0.0, 0.0, -0.03])]
    R_f = [Rotation.from_euler("yxz", [rng.uniform(0, 360), rng.normal(0, 5),
                                       rng.normal(0, 5)],
                               degrees=True).as_matrix()
           for _ in range(num_frames)]
    C_f = np.stack([np.linspace(-0.6, 0.6, num_frames),
                    rng.normal(0, 0.05, num_frames),
                    rng.normal(0, 0.3, num_frames)], axis=1)
    X = rng.normal(size=(num_points, 3))
    X *= (rng.uniform(1.5, 4, num_points) / np.linalg.norm(X, axis=1))[:, None]
    R, C, camera_ids, names, frame, sensor = [], [], [], [], [], []
    obs_image, obs_point = [], []
    for f in range(num_frames):
        for s in range(2):
            j = len(R)
            R.append(R_s[s] @ R_f[f])
            C.append(C_f[f] + R_f[f].T @ c_s[s])
            camera_ids.append(s + 1)
            names.append("lens%d/frame%03d.jpg" % (s, f))
            frame.append(f)
            sensor.append(s)
            y = (X - C[j]) @ R[j].T
            angle = np.degrees(np.arctan2(np.hypot(y[:, 0], y[:, 1]), y[:, 2]))
            seen = np.flatnonzero(angle < 100)
            obs_image += [j] * len(seen)
            obs_point += list(seen)
    cameras = {1: ("OPENCV_FISHEYE", 800, 800, KB_LENS),
               2: ("OPENCV_FISHEYE", 800, 800, KB_LENS)}
    scene = crb.Scene(cameras, range(1, len(R) + 1), names, camera_ids, R, C,
                      range(1, num_points + 1), X, obs_image, obs_point)
    rig = crb.Rig(frame, sensor, R_f, C_f, [1, 2], R_s, c_s, [True, False])
    return scene, rig


def write_rig_files(rig, scene, path):
    """rigs.txt and frames.txt (COLMAP 4 text) of the rig, beside the
    images.txt of write_text_model."""
    def pose(R, t):
        x, y, z, w = Rotation.from_matrix(R).as_quat()
        return " ".join(map(repr, [w, x, y, z, *t]))
    free = rig.free_sensors()
    with open(os.path.join(path, "rigs.txt"), "w") as f:
        f.write("1 %d CAMERA %d %s\n" % (
            len(rig.reference), rig.camera_ids[0], " ".join(
                "CAMERA %d 1 %s" % (rig.camera_ids[s], pose(
                    rig.R_s[s], -rig.R_s[s] @ rig.c_s[s])) for s in free)))
    with open(os.path.join(path, "frames.txt"), "w") as f:
        for frame in range(rig.num_frames):
            images = np.flatnonzero(rig.image_frame == frame)
            f.write("%d 1 %s %d %s\n" % (
                frame + 1, pose(rig.R_f[frame], -rig.R_f[frame] @
                                rig.C_f[frame]), len(images), " ".join(
                    "CAMERA %d %d" % (scene.camera_ids[j], scene.image_ids[j])
                    for j in images)))


def rig_gauge_generators(rig):
    """G (6F + 6S', 7): the world similarity (theta, tau, lambda about the
    mean image centre c, as crb.gauge_generators) on the rig's parameters:
    frames as cameras (omega_f = -R_f theta, dC_f = theta x d_f + tau +
    lambda d_f, d_f = C_f - c), free sensors omega_s = 0, dc_s = lambda c_s
    (the scale stretches the rig)."""
    F = rig.num_frames
    C_images = rig.C_f[rig.image_frame] + np.einsum(
        "jba,jb->ja", rig.R_f[rig.image_frame], rig.c_s[rig.image_sensor])
    c = C_images.mean(axis=0)
    frames = np.zeros((F, 6, 7))
    frames[:, 0:3, 0:3] = -rig.R_f
    d = rig.C_f - c
    frames[:, 3:6, 0:3] = -crb.skew(d)
    frames[:, 3:6, 3:6] = np.eye(3)
    frames[:, 3:6, 6] = d
    free = rig.free_sensors()
    sensors = np.zeros((len(free), 6, 7))
    sensors[:, 3:6, 6] = rig.c_s[free]
    return np.concatenate([frames.reshape(6 * F, 7),
                           sensors.reshape(6 * len(free), 7)])


class RigBoundTest(unittest.TestCase):
    def test_rig_jacobian_is_the_first_order_change(self):
        scene, rig = dual_fisheye_rig_scene()
        T = crb.rig_jacobian(rig)
        rng = np.random.default_rng(2)
        delta = rng.normal(size=T.shape[1]) * 1e-6
        F = rig.num_frames
        moved_R_f = [Rotation.from_rotvec(delta[6 * f:6 * f + 3]).as_matrix()
                     @ rig.R_f[f] for f in range(F)]
        moved_C_f = [rig.C_f[f] + delta[6 * f + 3:6 * f + 6]
                     for f in range(F)]
        sensor = delta[6 * F:6 * F + 6]
        moved_R_s = [rig.R_s[0], Rotation.from_rotvec(sensor[:3]).as_matrix()
                     @ rig.R_s[1]]
        moved_c_s = [rig.c_s[0], rig.c_s[1] + sensor[3:]]
        expected = T @ delta
        for j in range(scene.num_images):
            f, s = rig.image_frame[j], rig.image_sensor[j]
            R = moved_R_s[s] @ moved_R_f[f]
            C = moved_C_f[f] + moved_R_f[f].T @ moved_c_s[s]
            omega = Rotation.from_matrix(R @ scene.R[j].T).as_rotvec()
            np.testing.assert_allclose(omega, expected[6 * j:6 * j + 3],
                                       atol=1e-11)
            np.testing.assert_allclose(C - scene.C[j],
                                       expected[6 * j + 3:6 * j + 6],
                                       atol=1e-11)

    def test_the_world_similarity_moves_the_rig_as_it_moves_the_images(self):
        scene, rig = dual_fisheye_rig_scene()
        G = rig_gauge_generators(rig)
        np.testing.assert_allclose(crb.rig_jacobian(rig) @ G,
                                   crb.gauge_generators(scene), atol=1e-12)
        S, _, _ = crb.reduced_camera_information(scene, 0.5, "pixel")
        T = crb.rig_jacobian(rig)
        residual = np.abs(T.T @ S @ T @ G).max()
        self.assertLess(residual, 1e-6 * np.abs(T.T @ S @ T).max())

    def test_one_lens_rig_is_the_image_bound(self):
        scene = ring_scene(8, 60, seed=3)
        rig = crb.Rig(range(8), [0] * 8, scene.R, scene.C, [1], [np.eye(3)],
                      [np.zeros(3)], [True])
        images = crb.scene_bound(scene, 0.5, points=False)
        frames = crb.rig_bound(scene, rig, 0.5)
        self.assertAlmostEqual(frames["frame_rot_rms_deg"] /
                               images["rot_rms_deg"], 1, delta=1e-9)
        self.assertAlmostEqual(frames["frame_pos_rms"] / images["pos_rms"], 1,
                               delta=1e-9)
        self.assertEqual(frames["sensors"], [])

    def test_a_rig_bounds_its_frames_at_most_as_its_images(self):
        # The rig is the images' model with lens 1's poses tied to the
        # frames': a restriction, so no frame's bound can grow.
        scene, rig = dual_fisheye_rig_scene()
        images = crb.scene_bound(scene, 0.5, points=False)["covariance"]
        result = crb.rig_bound(scene, rig, 0.5)
        frames = result["covariance"]
        for f in range(rig.num_frames):
            j = int(np.flatnonzero((rig.image_frame == f) &
                                   (rig.image_sensor == 0))[0])
            self.assertLessEqual(np.trace(frames[6 * f:6 * f + 6,
                                                 6 * f:6 * f + 6]),
                                 np.trace(images[6 * j:6 * j + 6,
                                                 6 * j:6 * j + 6]))
        (lens,) = result["sensors"]
        self.assertEqual((lens["camera_id"], lens["name"]), (2, "lens1"))
        self.assertGreater(lens["rot_deg"], 0)
        # Estimating the lenses' focal lengths and distortion too can only
        # loosen the bound.
        calibrated = crb.rig_bound(scene, rig, 0.5, intrinsics=True)
        self.assertGreater(calibrated["sensors"][0]["centre"], lens["centre"])
        self.assertGreater(calibrated["sensors"][0]["rot_deg"],
                           lens["rot_deg"])

    def test_command_line_reads_the_rig_of_a_text_model(self):
        scene, rig = dual_fisheye_rig_scene()
        with tempfile.TemporaryDirectory() as tmp:
            write_text_model(scene, tmp)
            write_rig_files(rig, scene, tmp)
            read = crb.rig_of_scene(crb.scene_from_model(tmp), tmp)
            np.testing.assert_array_equal(read.image_frame, rig.image_frame)
            np.testing.assert_allclose(read.c_s, rig.c_s, atol=1e-12)
            np.testing.assert_allclose(read.C_f, rig.C_f, atol=1e-12)
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                self.assertEqual(crb.main(["--gt_model", tmp, "--sigma_px",
                                           "0.5", "--rig", "--intrinsics"]),
                                 0)
            self.assertIn("lens1", out.getvalue())
            self.assertIn("intrinsics estimated", out.getvalue())


class RenderedLensesTest(unittest.TestCase):
    """project() against the C++ camera models: the renderer writes each
    observation of its ground truth where camera_models/ puts the point, so
    the bound of a scene drawn through a Kannala-Brandt or OCam lens (the
    realistic rigs) rests on the same projection the renderer used."""

    def test_projection_matches_the_renderer(self):
        if not os.environ.get("SPHERA_RENDER"):
            self.skipTest("SPHERA_RENDER (the built sphera_render) is not set")
        import sphera_common as common
        size = 320
        c = size / 2.0
        lenses = {
            # 200 degrees, the realistic rigs' Kannala-Brandt shape.
            "kb": ("OPENCV_FISHEYE", [90.5, 90.5, c, c, -0.012, 0.0016,
                                      -0.0002, 0.0]),
            "prism": ("THIN_PRISM_FISHEYE",
                      [90.0, 91.0, c + 3, c - 2, -0.01, 0.001, 2e-4, -1e-4,
                       -1e-4, 0.0, 3e-4, -2e-4]),
            # A polynomial that folds at rho = 185 px, outside the image
            # circle; slightly non-identity affine map.
            "ocam": ("OCAM", [c + 1.5, c - 2.5, 1.0005, 2e-4, -3e-4, -37.5,
                              0.01, -3.0e-5, 0.0]),
        }
        with tempfile.TemporaryDirectory() as work:
            rig = os.path.join(work, "rig.txt")
            common.write_rig(rig, [
                common.rig_line(name, model, size, size, params,
                                [0.3 * k, 0.0, 0.2], 40 * k, 10 * k)
                for k, (name, (model, params)) in enumerate(lenses.items())])
            scene_dir = os.path.join(work, "scene")
            common.run_render(scene_dir, "--rig", rig, "--seed", 3,
                              "--supersample", 1, "--points", 2000)
            scene = crb.scene_from_model(os.path.join(scene_dir, "sparse_gt"))
        for j, name in enumerate(scene.names):
            rows = scene.obs_image == j
            model = scene.cameras[scene.camera_ids[j]][0]
            with self.subTest(model=model):
                self.assertGreater(rows.sum(), 50, name)
                y = crb.observation_rays(scene)[rows]
                # Rays beyond 90 degrees from the axis are among them.
                angles = np.degrees(np.arctan2(np.hypot(y[:, 0], y[:, 1]),
                                               y[:, 2]))
                self.assertGreater(angles.max(), 95, name)
                error = np.abs(crb.projections(scene)[rows] -
                               scene.observed[rows]).max()
                self.assertLess(error, 1e-6, name)


if __name__ == "__main__":
    unittest.main()
