"""Rotation derivatives, quaternion kinematics, twists, points, screws, the plane (issue 8).

References: finite differences of scipy.linalg.expm along one-parameter motions
(``R(t) = exp(hat(w) t) R0``), scipy's Rotation, the velocity relations of Murray,
Li & Sastry 1994 (Sec. 2.4), group identities; the lecture-note forms of
docs/errata.md (E3, E5) are shown wrong.
"""

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk

K = rk.kinematics


def hat(w):
    w = np.asarray(w, dtype=float)
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def hat6(V):
    M = np.zeros((4, 4))
    M[:3, :3] = hat(V[3:])
    M[:3, 3] = V[:3]
    return M


def fd(f, t=0.0, h=1e-4):
    """4th-order central first derivative of ``f`` at ``t``."""
    return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h)


def fd2(f, t=0.0, h=1e-3):
    """4th-order central second derivative."""
    return (-f(t + 2 * h) + 16 * f(t + h) - 30 * f(t) + 16 * f(t - h) - f(t - 2 * h)) / (
        12 * h * h
    )


@pytest.fixture
def motion(rng):
    """A rotation with non-constant angular velocity: R(t) = expm(hat(a t + b t^2)) R0."""
    R0 = SciRot.random(random_state=3).as_matrix()
    a = rng.standard_normal(3)
    b = rng.standard_normal(3)

    def R(t):
        return sl.expm(hat(a * t + b * t * t)) @ R0

    return R


# -- rotation matrices -------------------------------------------------------------------


def test_angular_velocity_four_forms(motion):
    """A_R_B' = hat(w_A) A_R_B = A_R_B hat(w_B); B_R_A' = -B_R_A hat(w_A)
    = -hat(w_B) B_R_A, with w_A = A_R_B w_B (Murray, Li & Sastry 1994, Sec. 2.4.1)."""
    A_R_B = motion(0.0)
    R_dot = fd(motion)
    w_A = K.angular_velocity(A_R_B, R_dot, frame="world")
    w_B = K.angular_velocity(A_R_B, R_dot, frame="body")
    np.testing.assert_allclose(A_R_B @ w_B, w_A, atol=1e-15 * 4)
    np.testing.assert_allclose(hat(w_A) @ A_R_B, R_dot, atol=1e-9)
    np.testing.assert_allclose(A_R_B @ hat(w_B), R_dot, atol=1e-9)
    B_R_A_dot = R_dot.T
    np.testing.assert_allclose(-A_R_B.T @ hat(w_A), B_R_A_dot, atol=1e-9)
    np.testing.assert_allclose(-hat(w_B) @ A_R_B.T, B_R_A_dot, atol=1e-9)
    # and the functions themselves, both ways
    for frame, w in (("world", w_A), ("body", w_B)):
        np.testing.assert_allclose(
            K.rotation_derivative(A_R_B, w, frame=frame), R_dot, atol=1e-9
        )


def test_rotation_objects_and_matrices_agree(rng):
    R = rk.Rotation.random((7,), rng=1)
    w = rng.standard_normal((7, 3))
    for frame in ("world", "body"):
        Rd = K.rotation_derivative(R, w, frame=frame)
        np.testing.assert_allclose(
            Rd, K.rotation_derivative(R.as_matrix(), w, frame=frame), atol=0
        )
        np.testing.assert_allclose(K.angular_velocity(R, Rd, frame=frame), w, atol=1e-14)
    wb = K.angular_velocity(R, K.rotation_derivative(R, w, frame="body"), frame="world")
    np.testing.assert_allclose(wb, R.apply(w), atol=1e-15 * 8)


def test_angular_acceleration_and_second_derivative(motion):
    R0 = motion(0.0)
    R_dot, R_ddot = fd(motion), fd2(motion)
    for frame in ("world", "body"):
        w = K.angular_velocity(R0, R_dot, frame=frame)
        alpha = K.angular_acceleration(R0, R_dot, R_ddot, frame=frame)

        def w_t(t, frame=frame):
            return K.angular_velocity(motion(t), fd(motion, t), frame=frame)

        np.testing.assert_allclose(alpha, fd(w_t, h=1e-3), atol=1e-6)
        # matrix form: R'' = (hat(alpha) + hat(w)^2) R
        np.testing.assert_allclose(
            K.rotation_second_derivative(R0, w, alpha, frame=frame), R_ddot, atol=1e-6
        )
    A = hat(K.angular_acceleration(R0, R_dot, R_ddot, frame="world"))
    W = hat(K.angular_velocity(R0, R_dot, frame="world"))
    np.testing.assert_allclose((A + W @ W) @ R0, R_ddot, atol=1e-6)
    # (hat(w) + hat(w)^2) R (docs/errata.md E3) is not the second derivative
    assert np.abs((W + W @ W) @ R0 - R_ddot).max() > 0.1


def test_rotation_input_is_validated():
    with pytest.raises(rk.NotARotationError):
        K.angular_velocity(2.0 * np.eye(3), np.zeros((3, 3)), frame="world")
    with pytest.raises(TypeError, match="required keyword-only argument: 'frame'"):
        K.angular_velocity(np.eye(3), np.zeros((3, 3)))
    with pytest.raises(rk.ShapeError):
        K.rotation_derivative(np.eye(3), [1.0, 2.0], frame="world")


# -- quaternions -------------------------------------------------------------------------


def test_quaternion_derivative_against_finite_differences(rng):
    q0 = rk.Rotation.random(rng=2).as_quat()
    w = rng.standard_normal(3)
    for frame in ("world", "body"):

        def q(t, frame=frame):
            dq = rk.Rotation.from_rotvec(w * t).as_quat()
            return rk.quaternion.multiply(*((q0, dq) if frame == "body" else (dq, q0)))

        qd = K.quaternion_derivative(q0, w, frame=frame)
        np.testing.assert_allclose(qd, fd(q), atol=1e-10)
        np.testing.assert_allclose(
            K.quaternion_second_derivative(q0, w, np.zeros(3), frame=frame),
            fd2(q),
            atol=1e-7,
        )
        for scale in (1.0, 3.0, 1e-5):
            np.testing.assert_allclose(
                K.angular_velocity_from_quaternion_derivative(
                    scale * q0, scale * qd, frame=frame
                ),
                w,
                atol=1e-14,
            )
    # q' = q (0, w) / 2: q0' = -q.w/2, q_vec' = (q0 I + hat(q)) w / 2 (body)
    qd = K.quaternion_derivative(q0, w, frame="body")
    np.testing.assert_allclose(qd[0], -0.5 * q0[1:] @ w, atol=1e-16)
    np.testing.assert_allclose(
        qd[1:], 0.5 * (q0[0] * np.eye(3) + hat(q0[1:])) @ w, atol=1e-16
    )


def test_quaternion_second_derivative_with_angular_acceleration(rng):
    q0 = rk.Rotation.random(rng=5).as_quat()
    a, b = rng.standard_normal(3), rng.standard_normal(3)

    def q(t):  # body rotation vector a t + b t^2: w_B(0) = a, alpha_B(0) = 2 b
        return rk.quaternion.multiply(
            q0, rk.Rotation.from_rotvec(a * t + b * t * t).as_quat()
        )

    np.testing.assert_allclose(
        K.quaternion_second_derivative(q0, a, 2 * b, frame="body"), fd2(q), atol=1e-7
    )
    with pytest.raises(rk.ZeroNormError):
        K.angular_velocity_from_quaternion_derivative(np.zeros(4), np.ones(4), frame="body")


def test_quaternion_torch_gradient(torch, rng):
    q = torch.tensor(rk.Rotation.random(rng=1).as_quat(), requires_grad=True)
    w = torch.tensor(rng.standard_normal(3), requires_grad=True)
    qd = K.quaternion_derivative(q, w, frame="world")
    assert isinstance(qd, torch.Tensor)
    qd[1].backward()
    # q' is linear in w: d q'_x / d w_j = q'_x for w = e_j
    expected = np.array(
        [
            K.quaternion_derivative(q.detach().numpy(), e, frame="world")[1]
            for e in np.eye(3)
        ]
    )
    np.testing.assert_allclose(w.grad.numpy(), expected, atol=1e-15)


# -- twists ------------------------------------------------------------------------------


@pytest.fixture
def pose_motion(rng):
    """T(t) = expm(hat(V t + U t^2)) T0, a motion with non-constant twist."""
    T0 = rk.Transform.random(rng=4).as_matrix()
    V = rng.standard_normal(6)
    U = rng.standard_normal(6)
    return (lambda t: sl.expm(hat6(V * t + U * t * t)) @ T0), V


def test_twists_from_derivatives(pose_motion):
    T, V = pose_motion
    T0, T_dot = T(0.0), fd(T)
    Vw = K.twist_from_derivative(T0, T_dot, frame="world")
    Vb = K.twist_from_derivative(T0, T_dot, frame="body")
    np.testing.assert_allclose(Vw, V, atol=1e-9)  # the motion's world twist at t = 0
    np.testing.assert_allclose(hat6(Vw), T_dot @ np.linalg.inv(T0), atol=1e-9)
    np.testing.assert_allclose(hat6(Vb), np.linalg.inv(T0) @ T_dot, atol=1e-9)
    # 000 E.1: v = p' - w x p
    p, p_dot = T0[:3, 3], T_dot[:3, 3]
    np.testing.assert_allclose(Vw[:3], p_dot - np.cross(Vw[3:], p), atol=1e-9)
    Tobj = rk.Transform.from_matrix(T0)
    np.testing.assert_allclose(K.twist_to_world(Tobj, Vb), Vw, atol=1e-13)
    np.testing.assert_allclose(K.twist_to_body(T0, Vw), Vb, atol=1e-13)
    np.testing.assert_allclose(Tobj.adjoint() @ Vb, Vw, atol=1e-13)
    for frame, Vf in (("world", Vw), ("body", Vb)):
        np.testing.assert_allclose(
            K.transform_derivative(Tobj, Vf, frame=frame), T_dot, atol=1e-9
        )


def test_spatial_acceleration_corrected(pose_motion):
    """000 E.2 corrected: q'' = (hat(V') + hat(V)^2) [q; 1] for a body point."""
    T, _ = pose_motion
    T0 = T(0.0)
    Vw = K.twist_from_derivative(T0, fd(T), frame="world")

    def Vw_t(t):
        return K.twist_from_derivative(T(t), fd(T, t), frame="world")

    Vw_dot = fd(Vw_t, h=1e-3)
    M = K.spatial_acceleration_matrix(Vw, Vw_dot, frame="world")
    q_body = np.array([0.3, -0.2, 0.5, 1.0])

    def point(t):
        return T(t) @ q_body

    q_world = T0 @ q_body
    np.testing.assert_allclose(M @ q_world, fd2(point), atol=1e-6)
    T_ddot = K.transform_second_derivative(T0, Vw, Vw_dot, frame="world")
    np.testing.assert_allclose(T_ddot, fd2(T), atol=1e-6)
    Vb = K.twist_to_body(T0, Vw)

    def Vb_t(t):
        return K.twist_from_derivative(T(t), fd(T, t), frame="body")

    T_ddot_b = K.transform_second_derivative(T0, Vb, fd(Vb_t, h=1e-3), frame="body")
    np.testing.assert_allclose(T_ddot_b, fd2(T), atol=1e-6)
    # hat(V) + hat(V)^2 on [q; 0] (docs/errata.md E5) is not the acceleration
    wrong = (hat6(Vw) + hat6(Vw) @ hat6(Vw)) @ np.append(q_world[:3], 0.0)
    assert np.abs(wrong - fd2(point)).max() > 1e-2


def test_point_velocity_and_acceleration(rng):
    """Against differentiating p(t) = R(t) r(t) + o(t) for a point moving in the body."""
    w, al = rng.standard_normal(3), rng.standard_normal(3)
    r0, vr, ar = rng.standard_normal(3), rng.standard_normal(3), rng.standard_normal(3)
    o_v, o_a = rng.standard_normal(3), rng.standard_normal(3)

    def p(t):
        R = sl.expm(hat(w * t + 0.5 * al * t * t))
        return R @ (r0 + vr * t + 0.5 * ar * t * t) + o_v * t + 0.5 * o_a * t * t

    np.testing.assert_allclose(K.point_velocity(w, r0 + 0 * w, o_v + vr), fd(p), atol=1e-9)
    a = K.point_acceleration(w, al, r0, a_origin=o_a, v_rel=vr, a_rel=ar)
    np.testing.assert_allclose(a, fd2(p), atol=1e-6)
    # the named terms
    tangential = np.cross(al, r0)
    centripetal = np.cross(w, np.cross(w, r0))
    coriolis = 2 * np.cross(w, vr)
    np.testing.assert_allclose(
        a, o_a + tangential + centripetal + coriolis + ar, atol=1e-14
    )
    assert K.point_velocity(np.ones((4, 1, 3)), np.ones((5, 3))).shape == (4, 5, 3)


# -- screws ------------------------------------------------------------------------------


def test_screws_round_trip_and_match_the_exponential(rng):
    V = rng.standard_normal((6, 6))
    q, u, h, m = K.screw_from_twist(V)
    np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, atol=1e-15)
    np.testing.assert_allclose(K.twist_from_screw(q, u, h, m), V, atol=1e-14)
    # q is the axis point nearest the origin: on the axis, orthogonal to u
    np.testing.assert_allclose(np.sum(q * u, axis=-1), 0.0, atol=1e-14)
    # a point on the axis only slides along it: exp(V) q = q + h m u
    T = rk.Transform.exp(V)
    np.testing.assert_allclose(T @ q, q + (h * m)[:, None] * u, atol=1e-12)
    T2 = rk.Transform.from_screw(q, u, h, m)
    assert bool(np.all(T2.approx_equal(T, atol=1e-13)))
    q2, u2, h2, m2 = T2.as_screw()  # angles below pi: the same screw back
    small = m < np.pi
    np.testing.assert_allclose(h2[small], h[small], atol=1e-12)
    np.testing.assert_allclose(u2[small], u[small], atol=1e-12)


def test_pure_translation_screw():
    q, u, h, m = K.screw_from_twist([0.0, 3.0, 4.0, 0.0, 0.0, 0.0])
    assert h == np.inf and m == 5.0
    np.testing.assert_allclose(u, [0.0, 0.6, 0.8])
    T = rk.Transform.from_screw([7.0, 7.0, 7.0], [0.0, 0.0, 2.0], np.inf, 1.5)
    np.testing.assert_allclose(T.translation, [0.0, 0.0, 1.5])
    assert float(T.rotation.angle) == 0.0
    with pytest.raises(rk.ZeroNormError):
        rk.Transform.from_screw([0, 0, 0], [0, 0, 0], 0.1, 1.0)
    q, u, h, m = K.screw_from_twist(np.zeros(6))
    assert m == 0.0 and h == 0.0


# -- the plane ---------------------------------------------------------------------------


def test_planar_kinematics():
    """R(t) = exp(w J t), R'(0) = w J; q'' = [[-w^2, -a], [a, -w^2]] q (a = w')."""
    P = K.planar
    J = np.array([[0.0, -1.0], [1.0, 0.0]])
    w, a = 1.7, 0.4

    def R(t):
        th = w * t + 0.5 * a * t * t
        return np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])

    np.testing.assert_allclose(P.rotation_derivative(np.eye(2), [w], frame="world"), w * J)
    R1 = R(0.3)
    for frame in ("world", "body"):
        np.testing.assert_allclose(
            P.angular_velocity(R1, fd(R, 0.3), frame=frame), [w + a * 0.3], atol=1e-9
        )
    q0 = np.array([0.5, -1.2])
    acc = P.point_acceleration([w], [a], q0)
    np.testing.assert_allclose(
        acc, np.array([[-(w**2), -a], [a, -(w**2)]]) @ q0, atol=1e-15
    )
    np.testing.assert_allclose(acc, fd2(lambda t: R(t) @ q0), atol=1e-6)
    np.testing.assert_allclose(P.point_velocity([w], q0), w * J @ q0)


def test_planar_twists(rng):
    P = K.planar
    V = rng.standard_normal(3)
    U = rng.standard_normal(3)
    T0 = rk.Transform2D.exp(rng.standard_normal(3)).as_matrix()

    def hat3(x):
        return np.array([[0, -x[2], x[0]], [x[2], 0, x[1]], [0, 0, 0]])

    def T(t):
        return sl.expm(hat3(V * t + U * t * t)) @ T0

    Vw = P.twist_from_derivative(T0, fd(T), frame="world")
    Vb = P.twist_from_derivative(T0, fd(T), frame="body")
    np.testing.assert_allclose(Vw, V, atol=1e-9)
    np.testing.assert_allclose(hat3(Vb), np.linalg.inv(T0) @ fd(T), atol=1e-9)
    for frame, Vf in (("world", Vw), ("body", Vb)):
        np.testing.assert_allclose(
            P.transform_derivative(T0, Vf, frame=frame), fd(T), atol=1e-9
        )
    with pytest.raises(rk.NotARigidTransformError):
        P.twist_from_derivative(2 * T0, fd(T), frame="world")


# -- the kernels' bindings agree (kernels with static parameters; tests/test_engine.py
# covers the others) ----------------------------------------------------------------------


def _param_kernels():
    from rigidkit.functional.euler import parse_sequence
    from rigidkit.kernels.kinematics import euler_rates as k2
    from rigidkit.kernels.kinematics import integration as k3
    from rigidkit.kernels.kinematics import planar as k4
    from rigidkit.kernels.kinematics import rotation as k1
    from rigidkit.kernels.kinematics import twist as k5

    cases = []
    for mod in (k1, k5, k3, k4):
        for obj in vars(mod).values():
            if getattr(obj, "params", None) in (("body",), ("inverse",)):
                cases += [(obj, (b,)) for b in (0, 1)]
    for obj in vars(k2).values():
        if getattr(obj, "params", ()) and obj.params[0] == "e1":
            for seq in ("ZYX", "xzx", "YXZ", "zyz"):
                for b in (0, 1):
                    cases.append((obj, (*parse_sequence(seq).params, b, 1.0)))
    return cases


def test_parameterised_kernels_agree_on_every_binding(rng):
    for kern, params in _param_kernels():
        n = 1500  # above the numba threshold
        arrays = [rng.standard_normal((n,) + s) for s in kern.inputs]
        xp = kern(*params, *arrays, backend="xp")
        nb = kern(*params, *arrays, backend="numba")
        one = kern(*params, *(a[7] for a in arrays), backend="python")
        xp = xp if isinstance(xp, tuple) else (xp,)
        nb = nb if isinstance(nb, tuple) else (nb,)
        one = one if isinstance(one, tuple) else (one,)
        for a, b, c in zip(xp, nb, one):
            scale = np.maximum(1.0, np.abs(a))
            assert np.abs((a - b) / scale).max() < 1e-13, (kern.name, params)
            assert np.abs((a[7] - c) / scale[7]).max() < 1e-13, (kern.name, params)
