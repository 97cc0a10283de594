"""Kernels between unit quaternions and 3x3 rotation matrices (row-major)."""

from .._engine import helper, kernel
from .vector import det3


@helper
def matrix_entries_from_quat(w, x, y, z):
    """The 9 entries (row-major) of the rotation matrix of a unit quaternion.

    The diagonal is written in the homogeneous form ``w^2 + x^2 - y^2 - z^2``, not
    ``1 - 2 (y^2 + z^2)``: for a quaternion off unit norm by ``d`` (a float-rounded
    one is, by ~2e-16) every entry is then off by ``d |R_ij|`` instead of ``2 d``,
    and the terms summed are at most 1 instead of 2. Measured against mpmath on
    the normalised input: <= 5e-16 instead of 1e-15.

    Off the diagonal, ``2 (x y - w z)`` is computed as ``(2x) y - (2w) z``: the
    same number (doubling is exact, short of overflow and subnormals), with 3
    additions instead of 6 (LLVM writes ``2 a`` as ``a + a``), and additions are
    what a batch loop waits on once its stores are vector stores (the loop of
    SE(3) ``as_matrix``: -5% at N = 1e3-1e4).
    """
    ww = w * w
    xx = x * x
    yy = y * y
    zz = z * z
    w2 = w + w
    x2 = x + x
    y2 = y + y
    xy2 = x2 * y
    xz2 = x2 * z
    yz2 = y2 * z
    wx2 = w2 * x
    wy2 = w2 * y
    wz2 = w2 * z
    return (
        (ww + xx) - (yy + zz),
        xy2 - wz2,
        xz2 + wy2,
        xy2 + wz2,
        (ww + yy) - (xx + zz),
        yz2 - wx2,
        xz2 - wy2,
        yz2 + wx2,
        (ww + zz) - (xx + yy),
    )


@kernel(inputs=[(4,)], outputs=[(3, 3)])
def matrix_from_quat(w, x, y, z):
    """Rotation matrix of a unit quaternion (active, acting on column vectors).

    ``R = (w^2 - |v|^2) I + 2 v v^T + 2 w hat(v)``, see :func:`matrix_entries_from_quat`.
    """
    return matrix_entries_from_quat(w, x, y, z)


@kernel(inputs=[(3, 3)], outputs=[(4,), ()])
def quat_from_matrix(r00, r01, r02, r10, r11, r12, r20, r21, r22):
    """Unit quaternion of the rotation nearest a matrix, and the distance from SO(3).

    First one Newton step towards the orthogonal polar factor (the nearest rotation
    in Frobenius norm): with ``C = M^T M - I``, ``N = M (I - C/2)``. The polar factor
    is ``M (I + C)^(-1/2) = M (I - C/2 + 3 C^2/8 - ...)``, so ``N`` is it up to
    ``3/8 |C|^2``: below 1e-20 for a matrix 1e-10 off, 1.5e-12 for one written to
    6 decimals (``|C| <= 2e-6``), 4e-11 at the default tolerance 1e-5, and a
    rounding-level change for a rotation. Without this step a
    perturbation ``e`` moves the result by ``e`` instead of ``e^2``.

    Then Shepperd's method on ``N``: of the four expressions ``4w^2, 4x^2, 4y^2,
    4z^2`` (``1 + tr``, ``1 + 2 n00 - tr``, ...) take the largest (compared through
    the diagonal: ``t0 >= t1`` iff ``n11 + n22 >= 0``, and so on), so the division
    is by a number >= 1/2 and every component is accurate to an ulp, near the
    identity and near pi alike. The 4-vector is then normalised.

    The second output is ``max(max|M^T M - I|, |det M - 1|)``: 0 for a rotation,
    about 2 for a reflection; callers compare it to their tolerance.
    """
    # C = M^T M - I (symmetric).
    c00 = r00 * r00 + r10 * r10 + r20 * r20 - 1.0
    c11 = r01 * r01 + r11 * r11 + r21 * r21 - 1.0
    c22 = r02 * r02 + r12 * r12 + r22 * r22 - 1.0
    c01 = r00 * r01 + r10 * r11 + r20 * r21
    c02 = r00 * r02 + r10 * r12 + r20 * r22
    c12 = r01 * r02 + r11 * r12 + r21 * r22
    # N = M - M C / 2.
    n00 = r00 - 0.5 * (r00 * c00 + r01 * c01 + r02 * c02)
    n01 = r01 - 0.5 * (r00 * c01 + r01 * c11 + r02 * c12)
    n02 = r02 - 0.5 * (r00 * c02 + r01 * c12 + r02 * c22)
    n10 = r10 - 0.5 * (r10 * c00 + r11 * c01 + r12 * c02)
    n11 = r11 - 0.5 * (r10 * c01 + r11 * c11 + r12 * c12)
    n12 = r12 - 0.5 * (r10 * c02 + r11 * c12 + r12 * c22)
    n20 = r20 - 0.5 * (r20 * c00 + r21 * c01 + r22 * c02)
    n21 = r21 - 0.5 * (r20 * c01 + r21 * c11 + r22 * c12)
    n22 = r22 - 0.5 * (r20 * c02 + r21 * c12 + r22 * c22)
    # Each test is read only where the ones before it failed.
    use0 = (n11 + n22 >= 0.0) & (n00 + n22 >= 0.0) & (n00 + n11 >= 0.0)
    use1 = (n00 >= n11) & (n00 >= n22)
    use2 = n11 >= n22
    t0 = 1.0 + n00 + n11 + n22
    t1 = 1.0 + n00 - n11 - n22
    t2 = 1.0 - n00 + n11 - n22
    t3 = 1.0 - n00 - n11 + n22
    w = where(use0, t0, where(use1, n21 - n12, where(use2, n02 - n20, n10 - n01)))
    x = where(use0, n21 - n12, where(use1, t1, where(use2, n01 + n10, n02 + n20)))
    y = where(use0, n02 - n20, where(use1, n01 + n10, where(use2, t2, n12 + n21)))
    z = where(use0, n10 - n01, where(use1, n02 + n20, where(use2, n12 + n21, t3)))
    n = sqrt(w * w + x * x + y * y + z * z)
    n = where(n > 0.0, n, 1.0)
    det = det3(r00, r01, r02, r10, r11, r12, r20, r21, r22)
    # A NaN entry makes det NaN (every entry is a factor of some product in it), and
    # 0 * det keeps that NaN in err, which ``maximum`` alone may drop (numba's and
    # Python's maximum return the other operand): so the caller's err <= tol test
    # fails and reports the NaN (NonFiniteError) instead of returning NaN.
    err = (
        maximum(
            maximum(maximum(abs(c00), abs(c11)), maximum(abs(c22), abs(c01))),
            maximum(maximum(abs(c02), abs(c12)), abs(det - 1.0)),
        )
        + 0.0 * det
    )
    return (w / n, x / n, y / n, z / n, err)
