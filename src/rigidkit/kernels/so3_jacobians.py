"""Kernels of SO(3) calculus: left Jacobian, its inverse, and the Lie bracket.

Conventions (rotation vectors ``w = theta * axis``, radians): the left Jacobian
``J_l(w)`` satisfies ``exp(w + d) ~ exp(J_l(w) d) exp(w)`` to first order in ``d``;
the right Jacobian is ``J_r(w) = J_l(-w)``, with ``exp(w + d) ~ exp(w) exp(J_r(w) d)``.
With ``W = hat(w)`` and ``theta = |w|``::

    J_l    = I + (1 - cos t)/t^2 W + (t - sin t)/t^3 W^2      (versinc2, sin_defect3)
    J_l^-1 = I - W/2 + (1 - (t/2) cot(t/2))/t^2 W^2             (cot_defect2)

Every special case (small angles) lives in the coefficient helpers. The helpers
here are shared with the SE(3) kernels (exp of a twist is ``J_l(w) v``).
"""

from .._engine import helper, kernel
from .coefficients import cot_defect2, norm3, sin_defect3, versinc2
from .vector import cross3, hat_poly_apply


@helper
def eye_hat_hat2(wx, wy, wz, a, b):
    """Entries (row-major) of ``I + a hat(w) + b hat(w)^2``.

    Uses ``hat(w)^2 = w w^T - |w|^2 I``, so the diagonal is ``1 - b (|w|^2 - w_i^2)``.
    """
    xx = wx * wx
    yy = wy * wy
    zz = wz * wz
    bxy = b * wx * wy
    bxz = b * wx * wz
    byz = b * wy * wz
    return (
        1.0 - b * (yy + zz),
        bxy - a * wz,
        bxz + a * wy,
        bxy + a * wz,
        1.0 - b * (xx + zz),
        byz - a * wx,
        bxz - a * wy,
        byz + a * wx,
        1.0 - b * (xx + yy),
    )


@helper
def eye_hat_hat2_apply(wx, wy, wz, a, b, vx, vy, vz):
    """``(I + a hat(w) + b hat(w)^2) v = v + a w x v + b w x (w x v)``."""
    return hat_poly_apply(wx, wy, wz, 1.0, a, b, vx, vy, vz)


@helper
def so3_left_jacobian_entries(wx, wy, wz):
    """Entries of ``J_l(w) = I + versinc2(t) W + sin_defect3(t) W^2``, ``t = |w|``."""
    theta = norm3(wx, wy, wz)
    return eye_hat_hat2(wx, wy, wz, versinc2(theta), sin_defect3(theta))


@helper
def so3_left_jacobian_inverse_entries(wx, wy, wz):
    """Entries of ``J_l(w)^-1 = I - W/2 + cot_defect2(t) W^2`` (singular at t = 2 pi)."""
    theta = norm3(wx, wy, wz)
    return eye_hat_hat2(wx, wy, wz, -0.5, cot_defect2(theta))


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def left_jacobian(wx, wy, wz):
    """Left Jacobian ``J_l(w)`` of SO(3): ``exp(w + d) ~ exp(J_l d) exp(w)``."""
    return so3_left_jacobian_entries(wx, wy, wz)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def left_jacobian_inverse(wx, wy, wz):
    """Inverse of the left Jacobian of SO(3), finite for ``|w| < 2 pi``."""
    return so3_left_jacobian_inverse_entries(wx, wy, wz)


@kernel(inputs=[(3,), (3,)], outputs=[(3,)])
def bracket(ux, uy, uz, vx, vy, vz):
    """Lie bracket of so(3): ``[hat(u), hat(v)] = hat(u x v)``."""
    return cross3(ux, uy, uz, vx, vy, vz)
