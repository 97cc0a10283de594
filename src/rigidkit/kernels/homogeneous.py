"""Kernels of affine and projective transforms of 3D space (row-major matrices).

An affine transform ``p -> A p + t`` is stored as the 3x4 block ``[A | t]`` (12
components); a projective one as its 4x4 matrix ``H``, acting on ``[p; 1]``
followed by the homogeneous divide. Inverses use the adjugate of the matrix scaled
by its largest entry, so nothing over- or underflows before the final division;
their error is about ``cond(A) eps`` like any backward-stable inverse.

Singularity is measured scale-free by the Hadamard ratio ``|det A| / prod_i
|row_i|``, in [0, 1]: 1 for orthogonal rows, 0 for a singular matrix, and in
between about ``1 / cond`` of ``A`` with its rows normalised (scaling a row changes
neither invertibility nor the accuracy of the adjugate inverse, so
``diag(1, 1, 1e-13)`` counts as perfectly invertible). It is computed as the
determinant of the matrix with normalised rows, so it never over- or underflows.
"""

from .._engine import helper, kernel
from .vector import det3, mat33_mul, normalize4


@helper
def alt3(x, y, z, p, q, r):
    """``x p - y q + z r``: one cofactor of a 4x4 matrix from three 2x2 minors."""
    return x * p - y * q + z * r


@helper
def minors2(x0, x1, x2, x3, y0, y1, y2, y3):
    """The six 2x2 minors of the rows ``x``, ``y``, columns (01, 02, 03, 12, 13, 23)."""
    return (
        x0 * y1 - y0 * x1, x0 * y2 - y0 * x2, x0 * y3 - y0 * x3,
        x1 * y2 - y1 * x2, x1 * y3 - y1 * x3, x2 * y3 - y2 * x3,
    )  # fmt: skip


@helper
def minors4(a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33):
    """The twelve 2x2 minors of rows (0, 1) and of rows (2, 3), and the determinant.

    Laplace expansion along the first two rows: ``det = s0 c5 - s1 c4 + s2 c3 + s3
    c2 - s4 c1 + s5 c0``.
    """
    s0, s1, s2, s3, s4, s5 = minors2(a00, a01, a02, a03, a10, a11, a12, a13)
    c0, c1, c2, c3, c4, c5 = minors2(a20, a21, a22, a23, a30, a31, a32, a33)
    det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0
    return (s0, s1, s2, s3, s4, s5, c0, c1, c2, c3, c4, c5, det)


# -- affine: [A | t], 3x4 ---------------------------------------------------------


@kernel(inputs=[(3, 4), (3,)], outputs=[(3,)])
def affine_apply(a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2, px, py, pz):
    """``A p + t``."""
    return (
        a00 * px + a01 * py + a02 * pz + t0,
        a10 * px + a11 * py + a12 * pz + t1,
        a20 * px + a21 * py + a22 * pz + t2,
    )


@kernel(inputs=[(3, 4), (3, 4)], outputs=[(3, 4)])
def affine_compose(
    a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2,
    b00, b01, b02, u0, b10, b11, b12, u1, b20, b21, b22, u2,
):  # fmt: skip
    """``[A | t] [B | u] = [A B | A u + t]`` (the right one applied first)."""
    c00, c01, c02, c10, c11, c12, c20, c21, c22 = mat33_mul(
        a00, a01, a02, a10, a11, a12, a20, a21, a22,
        b00, b01, b02, b10, b11, b12, b20, b21, b22,
    )  # fmt: skip
    x, y, z = affine_apply(
        a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2, u0, u1, u2
    )
    return (c00, c01, c02, x, c10, c11, c12, y, c20, c21, c22, z)


@kernel(inputs=[(3, 4)], outputs=[()])
def affine_hadamard_ratio(a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2):
    """``|det A| / (|a_0| |a_1| |a_2|)`` for the rows ``a_i`` of ``A``, in [0, 1]."""
    r00, r01, r02, _, _ = normalize4(a00, a01, a02, 0.0)
    r10, r11, r12, _, _ = normalize4(a10, a11, a12, 0.0)
    r20, r21, r22, _, _ = normalize4(a20, a21, a22, 0.0)
    return (abs(det3(r00, r01, r02, r10, r11, r12, r20, r21, r22)),)


@helper
def adjugate3(b00, b01, b02, b10, b11, b12, b20, b21, b22):
    """Entries (row-major) of the adjugate ``adj(B)``, with ``B adj(B) = det(B) I``."""
    return (
        b11 * b22 - b12 * b21, b02 * b21 - b01 * b22, b01 * b12 - b02 * b11,
        b12 * b20 - b10 * b22, b00 * b22 - b02 * b20, b02 * b10 - b00 * b12,
        b10 * b21 - b11 * b20, b01 * b20 - b00 * b21, b00 * b11 - b01 * b10,
    )  # fmt: skip


@kernel(inputs=[(3, 4)], outputs=[(3, 4), ()])
def affine_inverse(a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2):
    """``[A^-1 | -A^-1 t]`` from the adjugate of ``A / m``, ``m = max |a_ij|``, and the
    Hadamard ratio of ``A`` (second output) for the caller's singularity check.

    A singular ``A`` gives a meaningless finite result (the division is guarded);
    callers check the Hadamard ratio (:func:`affine_hadamard_ratio`) first.
    """
    m = maximum(
        maximum(maximum(abs(a00), abs(a01)), maximum(abs(a02), abs(a10))),
        maximum(maximum(abs(a11), abs(a12)), maximum(abs(a20), abs(a21))),
    )
    m = maximum(m, abs(a22))
    k = 1.0 / where(m > 0.0, m, 1.0)
    # B = A / m has its entries in [-1, 1]: no product below over- or underflows.
    b00, b01, b02 = a00 * k, a01 * k, a02 * k
    b10, b11, b12 = a10 * k, a11 * k, a12 * k
    b20, b21, b22 = a20 * k, a21 * k, a22 * k
    j00, j01, j02, j10, j11, j12, j20, j21, j22 = adjugate3(
        b00, b01, b02, b10, b11, b12, b20, b21, b22
    )
    # det B along its first row, from the cofactors the adjugate holds already.
    det = b00 * j00 + b01 * j10 + b02 * j20
    d = k / where(abs(det) > 0.0, det, 1.0)  # A^-1 = adj(B) / (m det B)
    i00, i01, i02 = j00 * d, j01 * d, j02 * d
    i10, i11, i12 = j10 * d, j11 * d, j12 * d
    i20, i21, i22 = j20 * d, j21 * d, j22 * d
    (ratio,) = affine_hadamard_ratio(
        a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2
    )
    return (
        i00, i01, i02, -(i00 * t0 + i01 * t1 + i02 * t2),
        i10, i11, i12, -(i10 * t0 + i11 * t1 + i12 * t2),
        i20, i21, i22, -(i20 * t0 + i21 * t1 + i22 * t2),
        ratio,
    )  # fmt: skip


# -- projective: H, 4x4 --------------------------------------------------------------


@kernel(inputs=[(4, 4), (4, 4)], outputs=[(4, 4)])
def projective_compose(
    a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
    b00, b01, b02, b03, b10, b11, b12, b13, b20, b21, b22, b23, b30, b31, b32, b33,
):  # fmt: skip
    """Matrix product ``H1 H2`` (``H2`` applied first)."""
    return (
        a00 * b00 + a01 * b10 + a02 * b20 + a03 * b30,
        a00 * b01 + a01 * b11 + a02 * b21 + a03 * b31,
        a00 * b02 + a01 * b12 + a02 * b22 + a03 * b32,
        a00 * b03 + a01 * b13 + a02 * b23 + a03 * b33,
        a10 * b00 + a11 * b10 + a12 * b20 + a13 * b30,
        a10 * b01 + a11 * b11 + a12 * b21 + a13 * b31,
        a10 * b02 + a11 * b12 + a12 * b22 + a13 * b32,
        a10 * b03 + a11 * b13 + a12 * b23 + a13 * b33,
        a20 * b00 + a21 * b10 + a22 * b20 + a23 * b30,
        a20 * b01 + a21 * b11 + a22 * b21 + a23 * b31,
        a20 * b02 + a21 * b12 + a22 * b22 + a23 * b32,
        a20 * b03 + a21 * b13 + a22 * b23 + a23 * b33,
        a30 * b00 + a31 * b10 + a32 * b20 + a33 * b30,
        a30 * b01 + a31 * b11 + a32 * b21 + a33 * b31,
        a30 * b02 + a31 * b12 + a32 * b22 + a33 * b32,
        a30 * b03 + a31 * b13 + a32 * b23 + a33 * b33,
    )


@kernel(inputs=[(4, 4), (3,)], outputs=[(4,)])
def projective_apply_homogeneous(
    a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
    px, py, pz,
):  # fmt: skip
    """``H [p; 1]``, the image before the homogeneous divide."""
    return (
        a00 * px + a01 * py + a02 * pz + a03,
        a10 * px + a11 * py + a12 * pz + a13,
        a20 * px + a21 * py + a22 * pz + a23,
        a30 * px + a31 * py + a32 * pz + a33,
    )


@kernel(inputs=[(4, 4), (3,)], outputs=[(3,), ()])
def projective_apply(
    a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
    px, py, pz,
):  # fmt: skip
    """``(x, y, z) / w`` for ``(x, y, z, w) = H [p; 1]``, and ``|w| / max|x, y, z, w|``.

    The second output, in [0, 1], says how close the image is to infinity: 0
    when ``w = 0``. Where ``w = 0`` the first output divides by 1 instead (a
    finite placeholder); callers flag those points from the ratio.
    """
    x, y, z, w = projective_apply_homogeneous(
        a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
        px, py, pz,
    )  # fmt: skip
    m = maximum(maximum(abs(x), abs(y)), maximum(abs(z), abs(w)))
    ratio = abs(w) / where(m > 0.0, m, 1.0)
    safe = where(abs(w) > 0.0, w, 1.0)
    return (x / safe, y / safe, z / safe, ratio)


@kernel(inputs=[(4, 4)], outputs=[()])
def projective_hadamard_ratio(
    a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
):  # fmt: skip
    """``|det H| / prod_i |h_i|`` for the rows ``h_i`` of ``H``, in [0, 1]."""
    r00, r01, r02, r03, _ = normalize4(a00, a01, a02, a03)
    r10, r11, r12, r13, _ = normalize4(a10, a11, a12, a13)
    r20, r21, r22, r23, _ = normalize4(a20, a21, a22, a23)
    r30, r31, r32, r33, _ = normalize4(a30, a31, a32, a33)
    det = minors4(
        r00, r01, r02, r03, r10, r11, r12, r13, r20, r21, r22, r23, r30, r31, r32, r33
    )[12]
    return (abs(det),)


@kernel(inputs=[(4, 4)], outputs=[(4, 4), ()])
def projective_inverse(
    a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
):  # fmt: skip
    """``H^-1``: adjugate over determinant (2x2 minors), of ``H / max|h_ij|``; and the
    Hadamard ratio of ``H`` (second output) for the caller's singularity check.

    A singular ``H`` gives a meaningless finite result (the division is guarded);
    callers check the Hadamard ratio first.
    """
    m = maximum(
        maximum(
            maximum(maximum(abs(a00), abs(a01)), maximum(abs(a02), abs(a03))),
            maximum(maximum(abs(a10), abs(a11)), maximum(abs(a12), abs(a13))),
        ),
        maximum(
            maximum(maximum(abs(a20), abs(a21)), maximum(abs(a22), abs(a23))),
            maximum(maximum(abs(a30), abs(a31)), maximum(abs(a32), abs(a33))),
        ),
    )
    k = 1.0 / where(m > 0.0, m, 1.0)
    # B = H / m has its entries in [-1, 1]: no product below over- or underflows.
    b00, b01, b02, b03 = a00 * k, a01 * k, a02 * k, a03 * k
    b10, b11, b12, b13 = a10 * k, a11 * k, a12 * k, a13 * k
    b20, b21, b22, b23 = a20 * k, a21 * k, a22 * k, a23 * k
    b30, b31, b32, b33 = a30 * k, a31 * k, a32 * k, a33 * k
    s0, s1, s2, s3, s4, s5, c0, c1, c2, c3, c4, c5, det = minors4(
        b00, b01, b02, b03, b10, b11, b12, b13, b20, b21, b22, b23, b30, b31, b32, b33
    )
    d = k / where(abs(det) > 0.0, det, 1.0)  # H^-1 = adj(B) / (m det B)
    (ratio,) = projective_hadamard_ratio(
        a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33
    )
    # Entry (i, j) of adj(B) is a row of B other than j against the minors of the
    # complementary pair of rows (Laplace), with the checkerboard sign.
    return (
        alt3(b11, b12, b13, c5, c4, c3) * d, -alt3(b01, b02, b03, c5, c4, c3) * d,
        alt3(b31, b32, b33, s5, s4, s3) * d, -alt3(b21, b22, b23, s5, s4, s3) * d,
        -alt3(b10, b12, b13, c5, c2, c1) * d, alt3(b00, b02, b03, c5, c2, c1) * d,
        -alt3(b30, b32, b33, s5, s2, s1) * d, alt3(b20, b22, b23, s5, s2, s1) * d,
        alt3(b10, b11, b13, c4, c2, c0) * d, -alt3(b00, b01, b03, c4, c2, c0) * d,
        alt3(b30, b31, b33, s4, s2, s0) * d, -alt3(b20, b21, b23, s4, s2, s0) * d,
        -alt3(b10, b11, b12, c3, c1, c0) * d, alt3(b00, b01, b02, c3, c1, c0) * d,
        -alt3(b30, b31, b32, s3, s1, s0) * d, alt3(b20, b21, b22, s3, s1, s0) * d,
        ratio,
    )  # fmt: skip
