"""Kernels of the angular velocity and acceleration of a rotation-vector curve.

For ``R(t) = R0 exp(hat(r(t)))`` the body angular velocity (``R^T dR/dt =
hat(omega)``) is ``omega = J_r(r) r'`` with the right Jacobian
``J_r(r) = I - a hat(r) + b hat(r)^2``, ``a = (1 - cos t)/t^2`` (versinc2),
``b = (t - sin t)/t^3`` (sin_defect3), ``t = |r|``. Its derivative is

    omega' = J_r(r) r'' + (dJ_r/dt) r'
           = J_r(r) r'' + (r.r') (k1 r x r' + k2 r x (r x r')) + b r' x (r x r')

with ``k1 = -(da/dt)/t = (2 (1 - cos t) - t sin t)/t^4`` and
``k2 = (db/dt)/t = (3 sin t - 2t - t cos t)/t^5`` (the angle's rate is
``(r.r')/t``). These are the formulas of scipy's ``RotationSpline``; the
coefficients here come from the shared helpers, without thresholds of their own.
"""

from .._engine import helper, kernel
from .coefficients import cot_defect2, norm3, sin_cos_defect5, sin_defect3, sinc, versinc2
from .so3_jacobians import cross3, eye_hat_hat2_apply


@helper
def versinc2_rate(x):
    """``(2 (1 - cos x) - x sin x) / x**4`` (1/12 at 0), minus ``d versinc2/dx`` over x.

    With ``y = x/2`` the numerator is ``4 sin(y) (sin y - y cos y)``, and
    ``sin y - y cos y = y^3 (versinc2(y) - sin_defect3(y))`` (see ``cot_defect2``),
    so the coefficient is ``cot_defect2(x) sinc(y)^2``: products of accurate
    factors, no cancellation, the series in those helpers.
    """
    s = sinc(0.5 * x)
    return cot_defect2(x) * s * s


@kernel(inputs=[(3,), (3,)], outputs=[(3,)])
def body_rate_from_rotvec_rate(rx, ry, rz, dx, dy, dz):
    """Body angular velocity ``J_r(r) r'`` of ``R0 exp(hat(r(t)))``, radians per time."""
    theta = norm3(rx, ry, rz)
    return eye_hat_hat2_apply(rx, ry, rz, -versinc2(theta), sin_defect3(theta), dx, dy, dz)


@kernel(inputs=[(3,), (3,), (3,)], outputs=[(3,)])
def body_acceleration_from_rotvec_rates(rx, ry, rz, dx, dy, dz, ax, ay, az):
    """Body angular acceleration ``J_r(r) r'' + (dJ_r/dt) r'`` (see the module doc)."""
    theta = norm3(rx, ry, rz)
    b = sin_defect3(theta)
    jx, jy, jz = eye_hat_hat2_apply(rx, ry, rz, -versinc2(theta), b, ax, ay, az)
    p = rx * dx + ry * dy + rz * dz
    cx, cy, cz = cross3(rx, ry, rz, dx, dy, dz)
    ccx, ccy, ccz = cross3(rx, ry, rz, cx, cy, cz)
    dcx, dcy, dcz = cross3(dx, dy, dz, cx, cy, cz)
    k1 = p * versinc2_rate(theta)
    k2 = -2.0 * p * sin_cos_defect5(theta)
    return (
        jx + k1 * cx + k2 * ccx + b * dcx,
        jy + k1 * cy + k2 * ccy + b * dcy,
        jz + k1 * cz + k2 * ccz + b * dcz,
    )
