"""Kernels between unit quaternions and 3x3 rotation matrices (row-major)."""

from .._engine import kernel


@kernel(inputs=[(4,)], outputs=[(3, 3)])
def matrix_from_quat(w, x, y, z):
    """Rotation matrix of a unit quaternion (active, acting on column vectors)."""
    xx = x * x
    yy = y * y
    zz = z * z
    xy = x * y
    xz = x * z
    yz = y * z
    wx = w * x
    wy = w * y
    wz = w * z
    return (
        1.0 - 2.0 * (yy + zz),
        2.0 * (xy - wz),
        2.0 * (xz + wy),
        2.0 * (xy + wz),
        1.0 - 2.0 * (xx + zz),
        2.0 * (yz - wx),
        2.0 * (xz - wy),
        2.0 * (yz + wx),
        1.0 - 2.0 * (xx + yy),
    )


@kernel(inputs=[(3, 3)], outputs=[(4,), ()])
def quat_from_matrix(r00, r01, r02, r10, r11, r12, r20, r21, r22):
    """Unit quaternion of a rotation matrix, and the matrix's distance from SO(3).

    Shepperd's method: of the four expressions 4w^2, 4x^2, 4y^2, 4z^2 (from the
    trace and diagonal) take the largest, so the division is by a number >= 1/2 and
    every component is accurate to an ulp, near the identity and near pi alike. The
    4-vector is then normalised, which for a nearly orthogonal matrix gives the
    rotation to first order.

    The second output is ``max(max|R^T R - I|, |det R - 1|)``: 0 for a rotation,
    about 2 for a reflection; callers compare it to their tolerance.
    """
    t0 = 1.0 + r00 + r11 + r22
    t1 = 1.0 + r00 - r11 - r22
    t2 = 1.0 - r00 + r11 - r22
    t3 = 1.0 - r00 - r11 + r22
    # Each test is read only where the ones before it failed.
    use0 = (t0 >= t1) & (t0 >= t2) & (t0 >= t3)
    use1 = (t1 >= t2) & (t1 >= t3)
    use2 = t2 >= t3
    w = where(use0, t0, where(use1, r21 - r12, where(use2, r02 - r20, r10 - r01)))
    x = where(use0, r21 - r12, where(use1, t1, where(use2, r01 + r10, r02 + r20)))
    y = where(use0, r02 - r20, where(use1, r01 + r10, where(use2, t2, r12 + r21)))
    z = where(use0, r10 - r01, where(use1, r02 + r20, where(use2, r12 + r21, t3)))
    n = sqrt(w * w + x * x + y * y + z * z)
    n = where(n > 0.0, n, 1.0)
    c00 = r00 * r00 + r10 * r10 + r20 * r20 - 1.0
    c11 = r01 * r01 + r11 * r11 + r21 * r21 - 1.0
    c22 = r02 * r02 + r12 * r12 + r22 * r22 - 1.0
    c01 = r00 * r01 + r10 * r11 + r20 * r21
    c02 = r00 * r02 + r10 * r12 + r20 * r22
    c12 = r01 * r02 + r11 * r12 + r21 * r22
    det = (
        r00 * (r11 * r22 - r12 * r21)
        - r01 * (r10 * r22 - r12 * r20)
        + r02 * (r10 * r21 - r11 * r20)
    )
    err = maximum(
        maximum(maximum(abs(c00), abs(c11)), maximum(abs(c22), abs(c01))),
        maximum(maximum(abs(c02), abs(c12)), abs(det - 1.0)),
    )
    return (w / n, x / n, y / n, z / n, err)
