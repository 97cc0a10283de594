"""Kernels between unit quaternions and modified Rodrigues parameters (MRP)."""

from .._engine import kernel
from .quaternion import quat_hemisphere


@kernel(inputs=[(3,)], outputs=[(4,)])
def quat_from_mrp(px, py, pz):
    """``q = ((1 - |p|^2), 2 p) / (1 + |p|^2)``; ``p = axis * tan(theta/4)``."""
    p2 = px * px + py * py + pz * pz
    d = 1.0 + p2
    return ((1.0 - p2) / d, 2.0 * px / d, 2.0 * py / d, 2.0 * pz / d)


@kernel(inputs=[(4,)], outputs=[(3,)])
def mrp_from_quat(w, x, y, z):
    """``p = v / (1 + w)`` with ``w >= 0`` first, so ``|p| <= 1`` (theta <= pi)."""
    w, x, y, z = quat_hemisphere(w, x, y, z)
    d = 1.0 + w
    return (x / d, y / d, z / d)
