"""Gradients of every differentiable public op (torch, JAX) against finite differences.

The table ``OPS`` lists each op as a function of one flat parameter vector per batch
element (a rotation vector, a quaternion, a twist, Euler angles, ...). Every op is
evaluated on one batch whose rows are the points that break formulas: random points,
a rotation (or vector part) of exactly 0, of 1e-8, of ``pi - 1e-5`` and of exactly
``pi`` (plus, for the Euler ops, a third angle of exactly 0 and a gimbal lock; for
the quaternion algebra, real quaternions). For each backend (torch autograd, JAX)
and dtype (float64, float32):

* first derivatives (the Jacobian, one pass per output or per input) against central
  differences of the float64 NumPy evaluation, ``h = 1e-6`` (1e-7 within 1e-5 of a
  singularity): truncation ``h^2 |f'''| / 6`` plus rounding ``eps |f| / h``, below
  1e-9 of the scale of the Jacobian; the tolerance is 1e-6 of it (float64) or 2e-3
  (float32, whose own rounding is ~1e-7 / h of the derivative);
* second derivatives of ``c . f`` (``c`` random; forward-over-reverse in JAX,
  double backward in torch) against second differences of values, ``h = 1e-4``:
  truncation ``h^2 |f''''| / 12`` plus rounding ``4 eps |f| / h^2``, ~1e-8; the
  tolerance is 1e-5 of the scale (float64) or 5e-2 (float32).

Where an op is not differentiable (the angle and axis at the identity, the logarithm
at exactly pi, Euler angles at gimbal lock) only finiteness is asserted: no NaN, no
infinity. Where a singularity lies closer than the second-difference step (1e-5 from
pi), the second derivatives are checked for finiteness only. NaN is always a failure.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk
from rigidkit._engine.namespace import namespace_of

KINDS = ("random", "random", "zero", "tiny", "near_pi", "pi")
H1 = {"near_pi": 1e-7}  # first-difference step by kind (default 1e-6)
H2 = 1e-4


# -- points -----------------------------------------------------------------------------


def rotvecs(rng, kinds=KINDS):
    """One rotation vector per kind: random angle in (0.3, 2.8), 0, 1e-8, pi - 1e-5, pi."""
    axes = rng.standard_normal((len(kinds), 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    angle = {"zero": 0.0, "tiny": 1e-8, "near_pi": math.pi - 1e-5, "pi": math.pi}
    t = np.array([angle.get(k, rng.uniform(0.3, 2.8)) for k in kinds])
    return axes * t[:, None]


def quats(rng, kinds=KINDS):
    """Unit quaternions (w, x, y, z) of :func:`rotvecs`, from scipy, ``w >= 0``."""
    q = SciRotation.from_rotvec(rotvecs(rng, kinds)).as_quat(scalar_first=True)
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def with_random(x, rng, n):
    """Append ``n`` standard normal parameters (vectors, translations) to each row."""
    return np.concatenate([x, rng.standard_normal((x.shape[0], n))], axis=-1)


def twists(rng, kinds=KINDS):
    return np.concatenate([rng.standard_normal((len(kinds), 3)), rotvecs(rng, kinds)], -1)


def euler_points(seq):
    """Points for ``as_euler(seq)``: the standard kinds, a third angle of exactly 0
    away from the lock, and an exact gimbal lock (not differentiable)."""

    def build(rng):
        q = quats(rng)
        proper = seq[0].lower() == seq[2].lower()
        mid = 1.0 if proper else 0.4
        lock = 0.0 if proper else math.pi / 2
        extra = [[0.3, mid, 0.0], [-2.0, mid + 0.3, 0.0], [0.7, lock, 0.0]]
        q3 = SciRotation.from_euler(seq, extra).as_quat(scalar_first=True)
        return np.concatenate([q, q3]), (*KINDS, "third0", "third0", "lock")

    return build


def real_quaternions(rng):
    """General quaternions: random, positive reals (the reported case), tiny vector
    parts, near and on the negative real axis (the branch cut of log)."""
    q = rng.standard_normal((6, 4))
    q[2] = [2.0, 0.0, 0.0, 0.0]
    q[3] = [0.5, 1e-8, -2e-8, 1e-8]
    q[4] = [-1.5, 1e-3, 0.0, 0.0]  # (finite differences need |v| >> their step)
    q[5] = [-1.5, 0.0, 0.0, 0.0]
    return q, ("random", "random", "zero", "tiny", "near_pi", "pi")


def hamilton(a, b):
    """Hamilton products ``a b`` of quaternions ``(w, x, y, z)`` (..., 4), by hand."""
    aw, av, bw, bv = a[..., :1], a[..., 1:], b[..., :1], b[..., 1:]
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([w, aw * bv + bw * av + np.cross(av, bv)], axis=-1)


def dual_quats(rng):
    """``(q, (0, t) q / 2)`` of rotations of each kind and random ``t``, scaled by
    0.7..1.4 (non-unit input, which ``from_dual_quat`` normalises)."""
    q = quats(rng)
    t = np.concatenate([np.zeros((len(q), 1)), rng.standard_normal((len(q), 3))], -1)
    return np.concatenate([q, 0.5 * hamilton(t, q)], -1) * rng.uniform(0.7, 1.4, (6, 1))


def pose_pairs(rng):
    """Poses ``(q1, t1, q2, t2)`` whose relative rotation ``q1* q2`` is of each kind."""
    q1, rel = quats(rng, ("random",) * len(KINDS)), quats(rng)
    t1, t2 = rng.standard_normal((2, len(KINDS), 3))
    return np.concatenate([q1, t1, hamilton(q1, rel), t2], -1)


def distance_to(x):
    """``T1.distance_to(T2)`` of ``x = (q1, t1, q2, t2)``, weights 0.7 and 1.3."""
    T1 = T(R.from_quat(x[..., :4]), x[..., 4:7])
    T2 = T(R.from_quat(x[..., 7:11]), x[..., 11:])
    return T1.distance_to(T2, rotation_weight=0.7, translation_weight=1.3)


def planar_twists(rng):
    """``(vx, vy, omega)`` with ``|omega|`` of each kind."""
    omega = np.linalg.norm(rotvecs(rng), axis=-1)[:, None]
    return np.concatenate([rng.standard_normal((len(KINDS), 2)), omega], -1)


def pure_quaternions(rng):
    """Vector parts of norm random, 0, 1e-8, pi - 1e-5, pi, with a random scalar."""
    return np.concatenate([rng.standard_normal((6, 1)), rotvecs(rng)], -1), KINDS


def rotation_pairs(rng):
    """Quaternions ``(q1, q2)`` whose relative rotation ``q1* q2`` is of each kind."""
    q1, rel = quats(rng, ("random",) * len(KINDS)), quats(rng)
    return np.concatenate([q1, hamilton(q1, rel)], -1)


def rot6d_points(rng):
    """The first two matrix columns of rotations of each kind, made general: scaled
    columns, the second not orthogonal to the first (Gram-Schmidt has work to do)."""
    M = SciRotation.from_rotvec(rotvecs(rng)).as_matrix()
    a1 = M[..., 0] * rng.uniform(0.5, 2.0, (len(M), 1))
    a2 = M[..., 1] * rng.uniform(0.5, 2.0, (len(M), 1)) + 0.4 * a1
    return np.concatenate([a1, a2], -1)


def davenport_axes():
    """General Davenport axes: ``n1, n2`` and ``n2, n3`` orthogonal, ``n1 . n3 =
    cos(1.1)`` (neither Euler's proper 0 nor Tait-Bryan's pi/2)."""
    n2 = np.array([0.36, -0.48, 0.8])
    n1 = np.cross(n2, [1.0, 0.0, 0.0])
    n1 /= np.linalg.norm(n1)
    n3 = math.cos(1.1) * n1 + math.sin(1.1) * np.cross(n2, n1)
    return np.array([n1, n2, n3])


DAVENPORT_AXES = davenport_axes()


def davenport_points(order):
    """Points for ``as_davenport``: the standard kinds, a third angle of exactly 0,
    and an exact lock: the middle turn maps the first axis onto the last
    (extrinsic, ``+1.1``) or the last onto the first (intrinsic, ``-1.1``). The
    middle angles lie inside the returned range, ``[1.1 - pi, 1.1]`` or ``[-1.1,
    pi - 1.1]``, away from its ends (else the others land on their +-pi cut)."""

    def build(rng):
        lock, mid = (1.1, -1.5) if order == "e" else (-1.1, 1.5)
        extra = [[0.3, 0.4, 0.0], [-2.0, mid, 0.0], [0.7, lock, 0.0]]
        q3 = SciRotation.from_davenport(DAVENPORT_AXES, order, extra)
        q3 = q3.as_quat(scalar_first=True)
        return np.concatenate([quats(rng), q3]), (*KINDS, "third0", "third0", "lock")

    return build


def swing_twist(x):
    """``(swing, twist)`` quaternions of ``x = (q, axis)``, one row of 8."""
    swing, twist = R.from_quat(x[..., :4]).swing_twist(x[..., 4:])
    xp = namespace_of(x)
    return xp.concat([swing.as_quat(), twist.as_quat()], axis=-1)


# -- the table ---------------------------------------------------------------------------


@dataclass
class Op:
    name: str
    fn: object  # fn(x) -> array (P, ...), x of shape (P, n) in any namespace
    points: object  # points(rng) -> x0 (P, n) or (x0, kinds)
    nondiff: set = field(default_factory=set)  # kinds: finite only
    first_only: set = field(default_factory=set)  # kinds: second derivative finite only

    def __repr__(self):
        return self.name


def from_rotvec_points(rng):
    return rotvecs(rng)


def quat_points(rng):
    return quats(rng)


R = rk.Rotation
T = rk.Transform
NEAR = {"near_pi"}
PI = {"pi"}
CONE = {"zero", "tiny", "pi"}  # 1e-8 from the apex of a cone: finite differences cross it

OPS = [
    # SO(3): construction and conversions
    Op("Rotation.from_rotvec", lambda x: R.from_rotvec(x).as_quat(), from_rotvec_points),
    Op("Rotation.exp.as_matrix", lambda x: R.exp(x).as_matrix(), from_rotvec_points),
    Op("so3.exp", lambda x: rk.so3.exp(x), from_rotvec_points),
    Op("Rotation.from_quat", lambda x: R.from_quat(x).as_quat(), quat_points),
    Op("Rotation.as_matrix", lambda x: R.from_quat(x).as_matrix(), quat_points),
    Op("Rotation.as_rotvec", lambda x: R.from_quat(x).as_rotvec(), quat_points, PI, NEAR),
    Op("Rotation.log", lambda x: R.from_quat(x).log(), quat_points, PI, NEAR),
    # (log of the matrix of a rotation vector: matrix entries moved by the step 1e-4 of
    # the second differences would leave SO(3) beyond from_matrix's tolerance)
    Op("so3.log", lambda x: rk.so3.log(rk.so3.exp(x)), from_rotvec_points, PI, NEAR),
    Op("Rotation.as_mrp", lambda x: R.from_quat(x).as_mrp(), quat_points, PI, NEAR),
    Op(
        "Rotation.from_mrp",
        lambda x: R.from_mrp(x).as_quat(),
        lambda rng: SciRotation.from_rotvec(rotvecs(rng)).as_mrp(),
    ),
    Op(
        "Rotation.from_axis_angle",
        lambda x: R.from_axis_angle(x[..., :3], x[..., 3]).as_quat(),
        lambda rng: np.concatenate(
            [rng.standard_normal((6, 3)), np.linalg.norm(rotvecs(rng), axis=-1)[:, None]],
            -1,
        ),
    ),
    # The angle is |w|-like at pi and |v|-like at 0 (a cone): not differentiable there.
    Op("Rotation.angle", lambda x: R.from_quat(x).angle, quat_points, CONE, NEAR),
    Op("Rotation.magnitude", lambda x: R.from_quat(x).magnitude(), quat_points, CONE, NEAR),
    Op("Rotation.axis", lambda x: R.from_quat(x).axis, quat_points, CONE, NEAR),
    Op(
        "Rotation.apply",
        lambda x: R.from_quat(x[..., :4]).apply(x[..., 4:]),
        lambda rng: with_random(quats(rng), rng, 3),
    ),
    Op(
        "Rotation @ Rotation",
        lambda x: (R.from_quat(x[..., :4]) @ R.from_quat(x[..., 4:])).as_quat(),
        lambda rng: np.concatenate([quats(rng), quats(rng)], -1),
    ),
    Op("Rotation.inv", lambda x: R.from_quat(x).inv().as_quat(), quat_points),
    Op(
        "Rotation ** t",
        lambda x: (R.from_quat(x[..., :4]) ** x[..., 4]).as_quat(),
        lambda rng: with_random(quats(rng), rng, 1),
        PI,
        NEAR,
    ),
    Op(
        "Rotation.from_euler(ZYX)",
        lambda x: R.from_euler("ZYX", x).as_quat(),
        lambda rng: np.concatenate([rotvecs(rng), [[0.3, 0.2, 0.0]]]),
    ),
    Op(
        "Rotation.from_euler(zxz)",
        lambda x: R.from_euler("zxz", x).as_quat(),
        lambda rng: rotvecs(rng),
    ),
    # Euler angles: the third angle merely 0 is differentiable, the lock is not.
    *[
        Op(
            f"Rotation.as_euler({seq})",
            lambda x, seq=seq: R.from_quat(x).as_euler(seq),
            euler_points(seq),
            {"lock", "zero", "tiny"} if seq[0].lower() == seq[2].lower() else {"lock"},
        )
        for seq in ("ZYX", "xyz", "ZXZ", "yxy")
    ],
    # SO(3) Jacobians
    *[
        Op(f"so3.{name}", lambda x, name=name: getattr(rk.so3, name)(x), from_rotvec_points)
        for name in (
            "left_jacobian",
            "right_jacobian",
            "left_jacobian_inverse",
            "right_jacobian_inverse",
        )
    ],
    # SE(3)
    Op("Transform.exp", lambda x: T.exp(x).as_matrix(), twists),
    Op("se3.left_jacobian", lambda x: rk.se3.left_jacobian(x), twists),
    Op(
        "Transform.log",
        lambda x: T.exp(x).log(),  # log of a pose built from its twist
        twists,
        PI,
        NEAR,
    ),
    Op(
        "Transform.apply",
        lambda x: T(R.from_quat(x[..., :4]), x[..., 4:7]).apply(x[..., 7:]),
        lambda rng: with_random(quats(rng), rng, 6),
    ),
    Op(
        "Transform @ Transform",
        lambda x: (T(R.from_quat(x[..., :4]), x[..., 4:7]) @ T.exp(x[..., 7:])).as_matrix(),
        lambda rng: np.concatenate([with_random(quats(rng), rng, 3), twists(rng)], -1),
    ),
    Op(
        "Transform.inv",
        lambda x: T(R.from_quat(x[..., :4]), x[..., 4:]).inv().as_matrix(),
        lambda rng: with_random(quats(rng), rng, 3),
    ),
    # Sim(3)
    Op(
        "Similarity.exp",
        lambda x: rk.Similarity.exp(x).as_matrix(),
        lambda rng: with_random(twists(rng), rng, 1) * np.array([1, 1, 1, 1, 1, 1, 0.3]),
    ),
    # the plane
    Op(
        "Rotation2D.exp",
        lambda x: rk.Rotation2D.exp(x).as_matrix(),
        lambda rng: np.linalg.norm(rotvecs(rng), axis=-1)[:, None],
    ),
    Op(
        "Transform2D.exp",
        lambda x: rk.Transform2D.exp(x).as_matrix(),
        planar_twists,
    ),
    Op(
        "Transform2D.log",
        lambda x: rk.Transform2D.exp(x).log(),
        planar_twists,
        PI,
        NEAR,
    ),
    # the quaternion algebra
    Op("Quaternion.log", lambda x: rk.Quaternion(x).log()._q, real_quaternions, PI, NEAR),
    Op("Quaternion.exp", lambda x: rk.Quaternion(x).exp()._q, pure_quaternions),
    Op("Quaternion.inv", lambda x: rk.Quaternion(x).inv()._q, real_quaternions),
    Op("Quaternion.norm", lambda x: rk.Quaternion(x).norm(), real_quaternions),
    Op(
        "Quaternion * Quaternion",
        lambda x: (rk.Quaternion(x[..., :4]) * rk.Quaternion(x[..., 4:]))._q,
        lambda rng: rng.standard_normal((4, 8)),
    ),
    # SE(3): other software's formats, the inverse action, a distance
    Op(
        "Transform.apply(inverse=True)",
        lambda x: T(R.from_quat(x[..., :4]), x[..., 4:7]).apply(x[..., 7:], inverse=True),
        lambda rng: with_random(quats(rng), rng, 6),
    ),
    Op("Transform.from_dual_quat", lambda x: T.from_dual_quat(x).as_matrix(), dual_quats),
    # (pq and dual quaternions are polynomial in q and t after the normalisation)
    Op(
        "Transform.from_pq(xyzw).as_dual_quat",
        lambda x: T.from_pq(x, scalar_first=False).as_dual_quat(),
        lambda rng: np.concatenate(
            [rng.standard_normal((6, 3)), np.roll(quats(rng), -1, axis=-1)], -1
        ),
    ),
    # theta^2 is smooth at a relative rotation of 0 (the distance too, t1 != t2);
    # theta is |w|-like at pi.
    Op("Transform.distance_to", distance_to, pose_pairs, PI, NEAR),
    # -- added after the rest (earlier entries keep their seeds, 1000 + index) --
    # 6D: Gram-Schmidt of non-orthogonal, scaled columns (the matrix is smooth at
    # every rotation; the quaternion would flip sign at pi).
    Op("Rotation.from_6d", lambda x: R.from_6d(x).as_matrix(), rot6d_points),
    Op("Rotation.as_6d", lambda x: R.from_quat(x).as_6d(), quat_points),
    # The twist (w, (v . n) n) / norm, flipped to w >= 0, jumps from angle pi to -pi
    # where w = 0 (a rotation by pi, v . n != 0): both quaternions change sign there,
    # and 1e-5 from it the second differences cross it.
    Op(
        "Rotation.swing_twist",
        swing_twist,
        lambda rng: with_random(quats(rng), rng, 3),
        PI,
        NEAR,
    ),
    # theta of the relative rotation: a cone at 0 (|v|) and at pi (|w|), as Rotation.angle.
    Op(
        "rk.geodesic_distance",
        lambda x: rk.geodesic_distance(R.from_quat(x[..., :4]), R.from_quat(x[..., 4:])),
        rotation_pairs,
        CONE,
        NEAR,
    ),
    # 2 sqrt(2) sin(theta / 2) = |R1 - R2|_F: a cone at 0 only; smooth at pi (its
    # maximum), where it is |v| / |q| of the relative rotation.
    Op(
        "rk.chordal_distance",
        lambda x: rk.chordal_distance(R.from_quat(x[..., :4]), R.from_quat(x[..., 4:])),
        rotation_pairs,
        {"zero", "tiny"},
    ),
    *[
        Op(
            f"Rotation.from_davenport({order})",
            lambda x, order=order: R.from_davenport(DAVENPORT_AXES, order, x).as_quat(),
            lambda rng: rotvecs(rng),
        )
        for order in ("e", "i")
    ],
    # As for as_euler: only the lock is not differentiable (general axes: the
    # identity is no lock).
    *[
        Op(
            f"Rotation.as_davenport({order})",
            lambda x, order=order: R.from_quat(x).as_davenport(DAVENPORT_AXES, order),
            davenport_points(order),
            {"lock"},
        )
        for order in ("e", "i")
    ],
]


ROWS = 9  # every op on batches of one size: JAX compiles each primitive once per shape


def points_of(op, rng):
    pts = op.points(rng)
    if isinstance(pts, tuple):
        x0, kinds = pts
    else:
        x0 = np.asarray(pts, dtype=np.float64)
        kinds = KINDS if len(x0) == len(KINDS) else ("random",) * len(x0)
        if op.name == "Rotation.from_euler(ZYX)":
            kinds = (*KINDS, "third0")
    pad = ROWS - len(x0)  # more random points: repeats of the first, random, rows
    x0 = np.concatenate([x0, np.resize(x0[:1], (pad, x0.shape[1]))])
    return x0, (*kinds, *(("random",) * pad))


# -- references: differences of the float64 NumPy path ------------------------------------


def evaluate(op, x):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rk.GimbalLockWarning)
        return op.fn(x)


def flat(y, P):
    return np.asarray(y, dtype=np.float64).reshape(P, -1)


def fd_jacobian(op, x0, kinds):
    P, n = x0.shape
    h = np.array([H1.get(k, 1e-6) for k in kinds])[:, None]
    cols = []
    for i in range(n):
        e = np.zeros_like(x0)
        e[:, i] = 1.0
        up = flat(evaluate(op, x0 + h * e), P)
        down = flat(evaluate(op, x0 - h * e), P)
        cols.append((up - down) / (2 * h))
    return np.stack(cols, axis=-1)  # (P, m, n)


def fd_hessian(op, x0, c):
    P, n = x0.shape

    def g(x):
        return flat(evaluate(op, x), P) @ c

    H = np.zeros((P, n, n))
    g0 = g(x0)
    E = np.eye(n)
    for i in range(n):
        H[:, i, i] = (g(x0 + H2 * E[i]) - 2 * g0 + g(x0 - H2 * E[i])) / H2**2
        for j in range(i):
            d = (
                g(x0 + H2 * (E[i] + E[j]))
                - g(x0 + H2 * (E[i] - E[j]))
                - g(x0 - H2 * (E[i] - E[j]))
                + g(x0 - H2 * (E[i] + E[j]))
            ) / (4 * H2**2)
            H[:, i, j] = H[:, j, i] = d
    return H


# -- autodiff ----------------------------------------------------------------------------


def torch_derivatives(torch, op, x0, c, dtype):
    x = torch.tensor(x0, dtype=dtype, requires_grad=True)
    P, n = x0.shape
    y = evaluate(op, x).reshape(P, -1)
    rows = []
    for k in range(y.shape[1]):
        (gk,) = torch.autograd.grad(y[:, k].sum(), x, retain_graph=True, allow_unused=True)
        rows.append(torch.zeros_like(x) if gk is None else gk)
    J = torch.stack(rows, dim=1).detach().double().numpy()
    x = torch.tensor(x0, dtype=dtype, requires_grad=True)
    g = (evaluate(op, x).reshape(P, -1) * torch.tensor(c, dtype=dtype)).sum()
    (G,) = torch.autograd.grad(g, x, create_graph=True)
    rows = []
    for i in range(n):
        hi = None
        if G.requires_grad:
            (hi,) = torch.autograd.grad(
                G[:, i].sum(), x, retain_graph=True, allow_unused=True
            )
        rows.append(torch.zeros_like(x) if hi is None else hi)
    H = torch.stack(rows, dim=1).detach().double().numpy()
    return J, H


def jax_derivatives(jax, op, x0, c, dtype):
    """The Jacobian from min(m, n) passes; the Hessian from one forward-over-reverse
    product per input. (Eager: each pass runs rigidkit once on the whole batch.)"""
    jnp = jax.numpy
    P, n = x0.shape
    x = jnp.asarray(x0, dtype=dtype)

    def f(x):
        return jnp.reshape(evaluate(op, x), (P, -1))

    def tiled(e):
        return jnp.asarray(np.tile(e, (P, 1)), dtype=dtype)

    y, vjp = jax.vjp(f, x)
    m = y.shape[1]
    if m <= n:  # a pullback per output row
        J = np.stack([np.asarray(vjp(tiled(e))[0]) for e in np.eye(m)], axis=1)
    else:  # a pushforward per input column (Jacobian matrices: 6 inputs, 36 outputs)
        J = np.stack([np.asarray(jax.jvp(f, (x,), (tiled(e),))[1]) for e in np.eye(n)], -1)
    cj = jnp.asarray(c, dtype=dtype)
    grad = jax.grad(lambda x: jnp.sum(f(x) * cj))
    H = np.stack([np.asarray(jax.jvp(grad, (x,), (tiled(e),))[1]) for e in np.eye(n)], 1)
    return J.astype(np.float64), H.astype(np.float64)


# -- the test ----------------------------------------------------------------------------

TOL = {  # (first, second) derivatives, relative to the scale of each
    "float64": (1e-6, 1e-5),
    "float32": (2e-3, 5e-2),
}


def check(op, kinds, J, H, J_ref, H_ref, dtype_name):
    tol1, tol2 = TOL[dtype_name]
    for p, kind in enumerate(kinds):
        where = f"{op.name} at {kind} (row {p})"
        assert np.all(np.isfinite(J[p])), f"{where}: non-finite Jacobian {J[p]}"
        assert np.all(np.isfinite(H[p])), f"{where}: non-finite Hessian {H[p]}"
        if kind in op.nondiff:
            continue
        scale = max(1.0, np.abs(J_ref[p]).max())
        err = np.abs(J[p] - J_ref[p]).max()
        assert err <= tol1 * scale, f"{where}: Jacobian off by {err:.3g}, scale {scale:.3g}"
        if kind in op.first_only:
            continue
        scale = max(1.0, np.abs(H_ref[p]).max())
        err = np.abs(H[p] - H_ref[p]).max()
        assert err <= tol2 * scale, f"{where}: Hessian off by {err:.3g}, scale {scale:.3g}"


@pytest.fixture(scope="module")
def references():
    """Points, weights ``c`` and finite-difference derivatives of every op (float64)."""
    out = {}
    for k, op in enumerate(OPS):
        rng = np.random.default_rng(1000 + k)
        x0, kinds = points_of(op, rng)
        m = flat(evaluate(op, x0), len(x0)).shape[1]
        c = rng.standard_normal(m)
        out[op.name] = (x0, kinds, c, fd_jacobian(op, x0, kinds), fd_hessian(op, x0, c))
    return out


@pytest.mark.parametrize("dtype_name", ["float64", "float32"])
@pytest.mark.parametrize("op", OPS, ids=repr)
def test_torch_gradients(op, dtype_name, torch, references):
    x0, kinds, c, J_ref, H_ref = references[op.name]
    J, H = torch_derivatives(torch, op, x0, c, getattr(torch, dtype_name))
    check(op, kinds, J, H, J_ref, H_ref, dtype_name)


@pytest.mark.parametrize("dtype_name", ["float64", "float32"])
@pytest.mark.parametrize("op", OPS, ids=repr)
def test_jax_gradients(op, dtype_name, jax, references):
    x0, kinds, c, J_ref, H_ref = references[op.name]
    J, H = jax_derivatives(jax, op, x0, c, getattr(jax.numpy, dtype_name))
    check(op, kinds, J, H, J_ref, H_ref, dtype_name)


def test_references_see_the_reported_errors(references):
    """The finite differences themselves find what the issue reports (so the checks
    above could fail): the Euler Jacobian at a third angle of 0 is the identity map
    of the angles, and d(vector part of log)/dv = I / w at a positive real q."""
    x0, kinds, _, J_ref, _ = references["Rotation.as_euler(ZYX)"]
    p = kinds.index("third0")
    q = x0[p]
    # d(angles)/dq times dq/d(angles) (from scipy's quaternion of the angles) = I.
    a = SciRotation.from_quat(q, scalar_first=True).as_euler("ZYX")
    h = 1e-6
    dq = np.stack(
        [
            (
                SciRotation.from_euler("ZYX", a + h * e).as_quat(scalar_first=True)
                - SciRotation.from_euler("ZYX", a - h * e).as_quat(scalar_first=True)
            )
            / (2 * h)
            for e in np.eye(3)
        ],
        axis=-1,
    )
    np.testing.assert_allclose(J_ref[p] @ dq, np.eye(3), atol=1e-6)
    x0, kinds, _, J_ref, _ = references["Quaternion.log"]
    p = kinds.index("zero")
    np.testing.assert_allclose(J_ref[p][1:, 1:], np.eye(3) / x0[p, 0], atol=1e-8)


def test_jax_forward_mode_with_concrete_operands(jax, rng):
    """Eager ``jax.jacfwd`` (what ``jax.hessian`` runs last) where concrete JAX arrays
    meet traced ones: a fixed rotation or pose applied to a traced vector, a traced
    rotation applied to a fixed vector or composed with a fixed one (once an
    ``AttributeError``, 'SingleDeviceSharding' object has no attribute 'spec':
    ``device=`` of a tracer). References: the matrix from scipy (d(R v)/dv = R) and
    central differences of the NumPy path."""
    jnp = jax.numpy
    q, q2 = quats(rng, ("random", "random"))
    v, t = rng.standard_normal((2, 3))
    M = SciRotation.from_quat(q, scalar_first=True).as_matrix()
    R_fixed = R.from_quat(jnp.asarray(q))  # concrete, on the default device

    J = jax.jacfwd(lambda v: R_fixed.apply(v))(jnp.asarray(v))
    np.testing.assert_allclose(np.asarray(J), M, atol=1e-12)
    T_fixed = T(R_fixed, jnp.asarray(t))
    J = jax.jacfwd(lambda p: T_fixed.apply(p))(jnp.asarray(v))
    np.testing.assert_allclose(np.asarray(J), M, atol=1e-12)

    def rotated(q):
        return R.from_quat(q).apply(jnp.asarray(v))  # traced rotation, concrete vector

    op = Op("from_quat(q).apply(v)", lambda x: R.from_quat(x).apply(v), None)
    J_fd = fd_jacobian(op, q2[None], ("random",))[0]
    J = jax.jacfwd(rotated)(jnp.asarray(q2))
    np.testing.assert_allclose(np.asarray(J), J_fd, atol=1e-8)

    op = Op("R_fixed @ R(q)", lambda x: (R.from_quat(q) @ R.from_quat(x)).as_quat(), None)
    J_fd = fd_jacobian(op, q2[None], ("random",))[0]
    J = jax.jacfwd(lambda x: (R_fixed @ R.from_quat(x)).as_quat())(jnp.asarray(q2))
    np.testing.assert_allclose(np.asarray(J), J_fd, atol=1e-8)


def test_cos_of_norm_across_its_threshold():
    """The series that gives ``exp`` its Hessian at 0 (``cos`` as a polynomial of
    ``|r|^2`` below ``|r| = 0.03``) against mpmath on both sides of its threshold,
    within 1 ulp-ish, on Python floats, vectorised NumPy and the numba loop (through
    ``quat_from_rotvec``, whose ``w`` is ``cos(|r|/2)``)."""
    mp = pytest.importorskip("mpmath")
    from rigidkit._engine.primitives import xp_bindings
    from rigidkit.kernels import so3

    t = 0.03 * (1 + np.array([-1e-3, -1e-8, 0.0, 1e-8, 1e-3]))
    n = np.concatenate([np.logspace(-12, 0.5, 120), t, [np.nextafter(0.03, 0), 0.0]])
    with mp.workdps(40):
        ref = np.array([float(mp.cos(mp.mpf(float(x)))) for x in n])
    h = so3.cos_of_norm
    got = {
        "python": np.array([h(float(x * x), float(x)) for x in n]),
        "numpy-xp": h.bound(xp_bindings(np, np.dtype(np.float64), None))(n * n, n),
    }
    axes = np.random.default_rng(5).standard_normal((len(n), 3))
    r = 2 * n[:, None] * axes / np.linalg.norm(axes, axis=-1, keepdims=True)
    got = {label: (g, ref, 0.0) for label, g in got.items()}
    with mp.workdps(40):  # the exact norm of the rounded vectors
        ref_r = [
            float(mp.cos(mp.sqrt(sum(mp.mpf(float(c)) ** 2 for c in v)) / 2)) for v in r
        ]
    # numba rounds |r| itself (1 ulp), which moves cos(|r|/2) by n tan(n) ulp.
    got["numba"] = (so3.quat_from_rotvec(r, backend="numba")[:, 0], ref_r, 1.0)
    for label, (g, want, rounded_norm) in got.items():
        err = np.abs(g - want) / np.asarray(want)
        bound = 2.3e-16 * (1.0 + rounded_norm * n * np.tan(n))
        i = int(np.argmax(err / bound))
        assert err[i] <= bound[i], f"{label}: rel. error {err[i]:.3g} at n = {n[i]!r}"


def test_distance_hessian_at_equal_rotations(torch):
    """Where the two rotations are bit-equal (``t1 != t2``) the distance is smooth
    (``theta^2`` is), but ``theta = 2 atan2(norm3(v), w)`` has the subgradient 0 at
    ``v = 0``, so autodiff drops the rotation block of the Hessian (all zeros). The
    reference: second differences of the NumPy path."""
    x0 = np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0]])
    op = Op("distance_to(equal rotations)", distance_to, None)
    c = np.ones(1)
    _, H = torch_derivatives(torch, op, x0, c, torch.float64)
    np.testing.assert_allclose(H[0], fd_hessian(op, x0, c)[0], atol=1e-5)
