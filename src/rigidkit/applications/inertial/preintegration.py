"""IMU preintegration on SE_2(3) (Forster, Carlone, Dellaert & Scaramuzza, T-RO 2017).

Between keyframes ``i`` and ``j`` the gyroscope and accelerometer samples are
summarised by ``Delta R``, ``Delta v``, ``Delta p`` (and ``Delta t``): the motion of
the body seen from its frame at ``i``, without gravity (their eqs. 33), so that
``R_j = R_i dR``, ``v_j = v_i + g t + R_i dv``, ``p_j = p_i + v_i t + g t^2/2 + R_i dp``
(eq. 44; the navigation frame is ``frame="world"``, ``g`` a vector of any direction,
``f = R^T (a - g)`` the specific force). The increments form the Galilean group
SGal(3) (Kelly 2023), which holds SE_2(3) (``rk.ExtendedPose``) and the time.

Error conventions (Forster's): 9-vectors in the order ``(R, v, p)``, the rotation
for a right perturbation ``dR exp(phi)``, velocity and position additive in the
frame at ``i``. The bias Jacobians (9x3) are those of a change of the bias; the
covariance (9x9) is that of the errors from white sensor noise, whose discrete
standard deviation over a step ``h`` is ``sigma / sqrt(h)`` (eq. 45).

GTSAM (``PreintegratedImuMeasurements``, its pip build preintegrating in the
tangent space of ``NavState``) stores ``preintegrated() = (theta, dp, dv)``, rotation,
position, velocity, with ``dR = Exp(theta)``; its ``preintMeasCov()`` is the
covariance of that vector. :func:`to_gtsam` and :func:`from_gtsam` convert: the
order is permuted and the rotation error maps by ``phi = J_r(theta) dtheta``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..._engine.dask_backend import is_dask
from ..._engine.namespace import device_of, is_numpy, namespace_of
from ...functional import so3 as _so3
from ...kernels.kinematics import inertial as _k
from ...kernels.kinematics import inertial_jacobians as _kj
from ...objects.extended_pose import ExtendedPose
from ...objects.rotation import Rotation
from ..kinematics.integration import _steps
from . import _fold
from .strapdown import GRAVITY, running_steps, samples, vector_like

__all__ = ["ImuNoise", "Preintegrated", "preintegrate", "to_gtsam", "from_gtsam"]

_METHODS = ("exact", "forster", "midpoint")
#: Windows x steps per pass on NumPy: the per-step 9x6 sensitivities are summed
#: a chunk at a time, so memory stays bounded for long logs.
_CHUNK = 1 << 16


@dataclass(frozen=True)
class ImuNoise:
    """Continuous-time IMU noise: white noise densities and bias random walks.

    Attributes
    ----------
    gyro_noise_density : float
        rad/s/sqrt(Hz) (the gyroscope's white noise; its discrete standard
        deviation at a rate ``r`` is ``density * sqrt(r)``).
    accel_noise_density : float
        m/s^2/sqrt(Hz).
    gyro_random_walk : float
        rad/s^2/sqrt(Hz): the gyroscope bias drifts as a Wiener process.
    accel_random_walk : float
        m/s^3/sqrt(Hz).
    """

    gyro_noise_density: float = 0.0
    accel_noise_density: float = 0.0
    gyro_random_walk: float = 0.0
    accel_random_walk: float = 0.0


class Preintegrated:
    """A batch of preintegrated IMU windows (see the module doc for conventions).

    Attributes
    ----------
    delta_R : Rotation, shape (...)
    delta_v, delta_p : array, shape (..., 3)
        In the body frame at the window's start (m/s, m).
    delta_t : array, shape (...)
    jacobian_gyro_bias, jacobian_accel_bias : array, shape (..., 9, 3)
        Rows ``(R, v, p)``.
    covariance : array, shape (..., 9, 9), or None without ``noise``
    gyro_bias, accel_bias : array, shape (..., 3)
        The biases the window was integrated with (the linearisation point).
    """

    def __init__(self, delta, jacobian, covariance, gyro_bias, accel_bias):
        self._delta = delta  # (..., 11): SGal(3) (q, dv, dp, dt)
        self._jacobian = jacobian  # (..., 9, 6): columns (gyro bias, accel bias)
        self.covariance = covariance
        self.gyro_bias = gyro_bias
        self.accel_bias = accel_bias

    @property
    def delta_R(self) -> Rotation:
        return Rotation._wrap(self._delta[..., :4])

    @property
    def delta_v(self):
        return self._delta[..., 4:7]

    @property
    def delta_p(self):
        return self._delta[..., 7:10]

    @property
    def delta_t(self):
        return self._delta[..., 10]

    @property
    def jacobian_gyro_bias(self):
        return self._jacobian[..., :3]

    @property
    def jacobian_accel_bias(self):
        return self._jacobian[..., 3:]

    @property
    def shape(self) -> tuple:
        return tuple(self._delta.shape[:-1])

    def __getitem__(self, index):
        """The windows at ``index`` of the batch (NumPy-style indexing)."""
        index = index if isinstance(index, tuple) else (index,)
        cov = None if self.covariance is None else self.covariance[index]
        return Preintegrated(
            self._delta[index],
            self._jacobian[index],
            cov,
            self.gyro_bias[index],
            self.accel_bias[index],
        )

    def predict(self, state_i, *, gravity=GRAVITY):
        """The state at the window's end from ``state_i`` (ExtendedPose) at its start.

        ``(R_i dR, v_i + g t + R_i dv, p_i + v_i t + g t^2/2 + R_i dp)`` (Forster
        et al. 2017, eq. 44), ``g`` (m/s^2) in the navigation frame ``"world"``.
        """
        g = vector_like(gravity, self._delta, "gravity")
        return ExtendedPose._wrap(_k.nav_predict_flat(state_i._data, self._delta, g))

    def corrected(self, gyro_bias=None, accel_bias=None):
        """The first-order bias update (Forster et al. 2017, eq. 44): for ``d b = b -
        b_lin``, ``dR Exp(J^R_g db_g)``, ``dv + J^v_g db_g + J^v_a db_a``, ``dp + ...``.

        The Jacobians and covariance are kept; the result's biases are the new ones.
        """
        dbg, dba, bg, ba = self._bias_change(gyro_bias, accel_bias)
        xp = namespace_of(self._delta)
        db = xp.concat([dbg, dba], axis=-1)[..., None]
        d = xp.matmul(self._jacobian, db)[..., 0]  # (..., 9)
        R = self.delta_R.compose(Rotation.from_rotvec(d[..., :3]))
        delta = xp.concat(
            [
                R.as_quat(),
                self.delta_v + d[..., 3:6],
                self.delta_p + d[..., 6:9],
                self._delta[..., 10:],
            ],
            axis=-1,
        )
        return Preintegrated(delta, self._jacobian, self.covariance, bg, ba)

    def _bias_change(self, gyro_bias, accel_bias):
        bg = (
            self.gyro_bias if gyro_bias is None else vector_like(gyro_bias, self._delta, "")
        )
        ba = (
            self.accel_bias
            if accel_bias is None
            else vector_like(accel_bias, self._delta, "")
        )
        return bg - self.gyro_bias, ba - self.accel_bias, bg, ba

    def residual(
        self, state_i, state_j, *, gravity=GRAVITY, gyro_bias=None, accel_bias=None
    ):
        """Forster's residual (eq. 45) and its Jacobians.

        ``r_R = Log(dR^T R_i^T R_j)``, ``r_v = R_i^T (v_j - v_i - g t) - dv``,
        ``r_p = R_i^T (p_j - p_i - v_i t - g t^2/2) - dp``, with the increments
        corrected to the biases given (first order, :meth:`corrected`).

        Returns
        -------
        r : array, shape (..., 9)
            ``(r_R, r_v, r_p)``.
        J_i, J_j : array, shape (..., 9, 9)
            In right perturbations of the states, ``X exp(xi)`` with ExtendedPose
            tangents ``xi = (rho_v, rho_p, w)``.
        J_gyro_bias, J_accel_bias : array, shape (..., 9, 3)
        """
        pim = self.corrected(gyro_bias, accel_bias)
        dbg = pim.gyro_bias - self.gyro_bias
        xp = namespace_of(self._delta)
        g = vector_like(gravity, self._delta, "gravity")
        t = self.delta_t[..., None]
        Ri = state_i.rotation.as_matrix()
        Rj = state_j.rotation.as_matrix()
        RiT = _swap(Ri)
        u = state_j.velocity - state_i.velocity - g * t
        w = state_j.position - state_i.position - state_i.velocity * t - 0.5 * g * t * t
        u_i = _mv(RiT, u)
        w_i = _mv(RiT, w)
        E = pim.delta_R.inv().compose(state_i.rotation.inv()).compose(state_j.rotation)
        r_R = E.as_rotvec()
        r = xp.concat([r_R, u_i - pim.delta_v, w_i - pim.delta_p], axis=-1)
        Jri = _so3.right_jacobian_inverse(r_R)
        RiTRj = xp.matmul(RiT, Rj)
        zero = 0.0 * Jri
        eye = zero + _cast(np.eye(3), Jri)
        # Columns (rho_v, rho_p, w) of each state's tangent.
        J_i = _blocks(
            [
                [zero, zero, -xp.matmul(Jri, _swap(RiTRj))],
                [-eye, zero, _so3.hat(u_i)],
                [-t[..., None] * eye, -eye, _so3.hat(w_i)],
            ],
            xp,
        )
        J_j = _blocks([[zero, zero, Jri], [RiTRj, zero, zero], [zero, RiTRj, zero]], xp)
        JRg = self._jacobian[..., :3, :3]
        Jr_db = _so3.right_jacobian(_mv(JRg, dbg))
        JbR = -xp.matmul(xp.matmul(Jri, _swap(E.as_matrix())), xp.matmul(Jr_db, JRg))
        J_bg = _cat([JbR, -self._jacobian[..., 3:, :3]], -2, xp)
        J_ba = _cat([zero, -self._jacobian[..., 3:, 3:]], -2, xp)
        return r, J_i, J_j, J_bg, J_ba


def _swap(M):
    """The transposes of a stack of matrices (``.mT``: NumPy, torch and JAX alike;
    Dask's arrays have ``swapaxes`` only)."""
    return M.swapaxes(-1, -2) if is_dask(M) else M.mT


def _mv(M, v):
    return namespace_of(M, v).matmul(M, v[..., None])[..., 0]


def _blocks(rows, xp):
    return _cat([_cat(r, -1, xp) for r in rows], -2, xp)


def _cat(parts, axis, xp):
    """``parts`` (..., a, b) joined along ``axis`` (-1 or -2), their batch shapes
    broadcast first (windows against states, as the other terms broadcast)."""
    batch = np.broadcast_shapes(*(tuple(x.shape[:-2]) for x in parts))
    parts = [
        x if tuple(x.shape[:-2]) == batch else xp.broadcast_to(x, batch + x.shape[-2:])
        for x in parts
    ]
    return xp.concat(parts, axis=axis)


def _cast(a, like):
    """``a`` (NumPy) in the namespace, dtype and device of ``like``."""
    xp = namespace_of(like)
    if is_numpy(xp):
        return np.asarray(a, dtype=like.dtype)
    return xp.asarray(a, dtype=like.dtype, device=device_of(like))


def _vec3(b):
    """A number as the bias ``(b, b, b)``; arrays as they are."""
    return np.full(3, float(b)) if isinstance(b, (int, float)) else b


def _step_fns(method, w, f, h, xp):
    """Steps (..., N, 11) and their Jacobians (..., N, 9, 6) in ``(w, f)``."""
    if method == "exact":
        return _k.imu_step_exact(w, f, h), _kj.imu_step_jacobian_exact(w, f, h)
    if method == "forster":
        return _k.imu_step_forster(w, f, h), _kj.imu_step_jacobian_forster(w, f, h)
    # VINS-Mono's midpoint: the next sample ends the step; the last step holds its own.
    w1 = xp.concat([w[..., 1:, :], w[..., -1:, :]], axis=-2)
    f1 = xp.concat([f[..., 1:, :], f[..., -1:, :]], axis=-2)
    return (
        _k.imu_step_midpoint(w, f, w1, f1, h),
        _kj.imu_step_jacobian_midpoint(w, f, w1, f1, h),
    )


def preintegrate(
    gyro, accel, dt, *, gyro_bias=0.0, accel_bias=0.0, noise=None, method="exact"
):
    """Preintegrated measurements of IMU windows, with bias Jacobians and covariance.

    Parameters
    ----------
    gyro, accel : array_like, shape (..., N, 3)
        Body angular rates (rad/s) and specific forces ``f = R^T (a - g)``
        (m/s^2), sample ``k`` held over step ``k``; leading axes are windows (e.g.
        keyframe intervals of equal length; pad shorter ones with ``dt = 0``).
    dt : float or array_like, shape (N,) or (..., N)
        Step durations (s); a zero-duration step changes nothing.
    gyro_bias, accel_bias : array_like, shape (3,) or (..., 3)
        Subtracted from the samples; the linearisation point of the Jacobians.
    noise : ImuNoise, optional
        Gives the covariance (white noise only: the random walks enter the bias
        between keyframes, ``rw^2 t``, not this covariance).
    method : {"exact", "forster", "midpoint"}
        ``"exact"``: the closed form of a sample held over its step (the
        exponential of SGal(3)), exact for piecewise-constant input;
        ``"forster"``: Forster's recursion (eqs. 26-33, what GTSAM's manifold
        preintegration and most VIO code implement), ``dv += dR f h``,
        ``dp += dv h + dR f h^2/2``; ``"midpoint"``: VINS-Mono's (mean rate of a
        step's two samples, mean of their rotated specific forces; the last step
        holds its sample).

    Returns
    -------
    Preintegrated, shape (...)

    Examples
    --------
    A body at rest (z up) for 0.5 s predicts the same state:

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> accel = np.tile([0.0, 0.0, 9.81], (128, 1))
    >>> pim = rk.inertial.preintegrate(np.zeros((128, 3)), accel, 1 / 256)
    >>> X = pim.predict(rk.ExtendedPose(velocity=[1.0, 0.0, 0.0]))
    >>> np.round(X.position, 12) + 0.0, float(pim.delta_t)
    (array([0.5, 0. , 0. ]), 0.5)
    """
    fn = "preintegrate"
    if method not in _METHODS:
        raise ValueError(f"{fn}: method must be one of {_METHODS}, got {method!r}")
    w, f = samples(gyro, accel, fn)
    h = _steps(dt, w, fn)
    bg = vector_like(_vec3(gyro_bias), w, "gyro_bias")
    ba = vector_like(_vec3(accel_bias), w, "accel_bias")
    xp = namespace_of(w, f)
    batch = tuple(
        np.broadcast_shapes(
            tuple(w.shape[:-2]),
            tuple(f.shape[:-2]),
            tuple(bg.shape[:-1]),
            tuple(ba.shape[:-1]),
            tuple(h.shape[:-1]),
        )
    )
    n = w.shape[-2]
    windows = math.prod(batch)  # not np.prod: torch.compile would trace it as an array
    if all(type(x) is np.ndarray for x in (w, f, h, bg, ba)):
        fold = _fold.ready(method, windows * n)
        if fold is not None:
            parts = _fold.folded(fold, method, w, f, h, bg, ba, noise, batch, w.dtype)
            delta, J, cov = parts
            bg = np.broadcast_to(bg, batch + (3,))
            ba = np.broadcast_to(ba, batch + (3,))
            return Preintegrated(delta, J, cov, bg, ba)
    if is_numpy(xp) and windows > 1 and windows * n > _CHUNK:
        return _chunked(w, f, h, bg, ba, noise, method, batch)
    return _preintegrate(w, f, h, bg, ba, noise, method, xp)


def _preintegrate(w, f, h, bg, ba, noise, method, xp):
    wc = w - bg[..., None, :]
    fc = f - ba[..., None, :]
    inc, S = _step_fns(method, wc, fc, h, xp)
    D = running_steps(inc)
    end = D[..., -1:, :]
    first, after = D[..., :-1, :], D[..., 1:, :]
    # The discrete variances sigma^2 / h of each step (eq. 45); a step of zero
    # duration (padding) has M = 0 and adds nothing.
    hh = h if len(h.shape) else h + 0.0 * wc[..., 0]
    safe = xp.where(hh > 0, hh, 1.0)
    inv = xp.where(hh > 0, 1.0 / safe, 0.0)
    sg, sa = (
        (0.0, 0.0)
        if noise is None
        else (noise.gyro_noise_density, noise.accel_noise_density)
    )
    M, C = _kj.preintegration_sensitivity(
        first, after, end, S, sg * sg * inv, sa * sa * inv
    )
    cov = None if noise is None else _symmetric(xp.sum(C, axis=-2), xp)
    J = -xp.sum(M, axis=-3)
    batch = tuple(J.shape[:-2])
    if is_dask(J):  # the biases too are Dask arrays, as every other field
        import dask.array as da

        xp, bg, ba = da, da.asarray(bg), da.asarray(ba)
    bg = xp.broadcast_to(bg, batch + (3,))
    ba = xp.broadcast_to(ba, batch + (3,))
    return Preintegrated(end[..., 0, :], J, cov, bg, ba)


#: Row and column of each of the 45 upper-triangle entries, and the 81 entries of the
#: full 9x9 matrix as indices into them.
_UPPER = np.triu_indices(9)
_FULL = np.zeros((9, 9), dtype=np.int64)
_FULL[_UPPER] = np.arange(45)
_FULL.T[_UPPER] = np.arange(45)


def _symmetric(upper, xp):
    """The symmetric (..., 9, 9) matrices of their upper triangles (..., 45)."""
    idx = _FULL.reshape(-1)
    if not is_numpy(xp):
        idx = xp.asarray(idx, device=device_of(upper))
    full = upper[..., idx]  # (integer-array indexing: NumPy, torch and JAX alike)
    return xp.reshape(full, tuple(upper.shape[:-1]) + (9, 9))


def _chunked(w, f, h, bg, ba, noise, method, batch):
    """:func:`_preintegrate` on NumPy a few windows at a time (bounded memory)."""
    n = w.shape[-2]
    w = np.broadcast_to(w, batch + (n, 3)).reshape(-1, n, 3)
    f = np.broadcast_to(f, batch + (n, 3)).reshape(-1, n, 3)
    hb = h if h.ndim == 0 else np.broadcast_to(h, batch + (n,)).reshape(-1, n)
    bg = np.broadcast_to(bg, batch + (3,)).reshape(-1, 3)
    ba = np.broadcast_to(ba, batch + (3,)).reshape(-1, 3)
    step = max(1, _CHUNK // n)
    parts = []
    for a in range(0, w.shape[0], step):
        s = slice(a, a + step)
        parts.append(
            _preintegrate(
                w[s], f[s], hb if hb.ndim == 0 else hb[s], bg[s], ba[s], noise, method, np
            )
        )

    def cat(get, trail):
        if get(parts[0]) is None:
            return None
        return np.concatenate([get(p) for p in parts]).reshape(batch + trail)

    return Preintegrated(
        cat(lambda p: p._delta, (11,)),
        cat(lambda p: p._jacobian, (9, 6)),
        cat(lambda p: p.covariance, (9, 9)),
        cat(lambda p: p.gyro_bias, (3,)),
        cat(lambda p: p.accel_bias, (3,)),
    )


# GTSAM's tangent (theta, dp, dv) from ours (R, v, p): the permutation of the rows.
_TO_GTSAM = np.array([0, 1, 2, 6, 7, 8, 3, 4, 5])


def to_gtsam(pim):
    """``(zeta, covariance)`` in GTSAM's layout: ``preintegrated()``, ``preintMeasCov()``.

    ``zeta = (theta, dp, dv)`` with ``dR = Exp(theta)``; GTSAM's rotation error is in
    ``theta`` (``Exp(theta + d) = Exp(theta) Exp(J_r(theta) d)``), ours is the right
    perturbation ``phi = J_r(theta) d``, so its covariance is ``J_r^-1 S J_r^-T``.
    NumPy arrays, shapes (..., 9) and (..., 9, 9) (None without a covariance).

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> w, f = np.tile([0.0, 0.0, 1.0], (10, 1)), np.tile([1.0, 0.0, 9.81], (10, 1))
    >>> pim = rk.inertial.preintegrate(w, f, 0.01, noise=rk.inertial.ImuNoise(1e-3, 1e-2))
    >>> zeta, cov = rk.inertial.to_gtsam(pim)
    >>> np.round(zeta[:3], 12) + 0.0                   # theta: 0.1 rad about z
    array([0. , 0. , 0.1])
    >>> same_p = np.allclose(cov[3:6, 3:6], pim.covariance[6:, 6:])  # p: rows 7-9 here
    >>> bool(np.allclose(zeta[6:], pim.delta_v)), bool(same_p)
    (True, True)
    """
    theta = np.asarray(pim.delta_R.as_rotvec())
    zeta = np.concatenate([theta, np.asarray(pim.delta_p), np.asarray(pim.delta_v)], -1)
    if pim.covariance is None:
        return zeta, None
    T = _gtsam_map(theta, inverse=True)
    return zeta, T @ np.asarray(pim.covariance) @ np.swapaxes(T, -1, -2)


def from_gtsam(zeta, covariance=None):
    """``(delta_R, delta_v, delta_p, covariance)`` in our layout from GTSAM's
    ``preintegrated()`` and ``preintMeasCov()`` (see :func:`to_gtsam`).

    >>> import numpy as np
    >>> R, dv, dp, _ = from_gtsam([0.0, 0.0, 0.1, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    >>> np.round(R.as_rotvec(), 12) + 0.0, dv, dp
    (array([0. , 0. , 0.1]), array([4., 5., 6.]), array([1., 2., 3.]))
    """
    zeta = np.asarray(zeta, dtype=np.float64)
    R = Rotation.from_rotvec(zeta[..., :3])
    cov = None
    if covariance is not None:
        T = _gtsam_map(zeta[..., :3], inverse=False)
        cov = T @ np.asarray(covariance) @ np.swapaxes(T, -1, -2)
    return R, zeta[..., 6:9], zeta[..., 3:6], cov


def _gtsam_map(theta, *, inverse):
    """Ours <- GTSAM's (``inverse=False``) or GTSAM's <- ours, 9x9 (rows permuted)."""
    Jr = np.asarray(_so3.right_jacobian(theta))
    P = np.eye(9)[_TO_GTSAM]  # GTSAM's vector = P ours
    D = np.zeros(theta.shape[:-1] + (9, 9))
    D[..., 3:, 3:] = np.eye(6)
    if inverse:
        D[..., :3, :3] = np.linalg.inv(Jr)
        return P @ D
    D[..., :3, :3] = Jr
    return D @ P.T
