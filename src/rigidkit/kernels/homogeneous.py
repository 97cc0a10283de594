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


@helper
def det3(a00, a01, a02, a10, a11, a12, a20, a21, a22):
    """Determinant of a 3x3 matrix (cofactor expansion along the first row)."""
    return (
        a00 * (a11 * a22 - a12 * a21)
        - a01 * (a10 * a22 - a12 * a20)
        + a02 * (a10 * a21 - a11 * a20)
    )


@helper
def unit_row3(x, y, z):
    """``(x, y, z) / |(x, y, z)|`` scaled by the largest component (zero stays zero)."""
    m = maximum(maximum(abs(x), abs(y)), abs(z))
    safe = where(m > 0.0, m, 1.0)
    xs = x / safe
    ys = y / safe
    zs = z / safe
    n = sqrt(xs * xs + ys * ys + zs * zs)
    n = where(m > 0.0, n, 1.0)
    return (xs / n, ys / n, zs / n)


@helper
def unit_row4(x, y, z, w):
    """``(x, y, z, w) / |(x, y, z, w)|`` scaled by the largest component."""
    m = maximum(maximum(abs(x), abs(y)), maximum(abs(z), abs(w)))
    safe = where(m > 0.0, m, 1.0)
    xs = x / safe
    ys = y / safe
    zs = z / safe
    ws = w / safe
    n = sqrt(xs * xs + ys * ys + zs * zs + ws * ws)
    n = where(m > 0.0, n, 1.0)
    return (xs / n, ys / n, zs / n, ws / n)


@helper
def minors4(a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33):
    """The twelve 2x2 minors of rows (0, 1) and of rows (2, 3), and the determinant.

    Laplace expansion along the first two rows: ``det = s0 c5 - s1 c4 + s2 c3 + s3
    c2 - s4 c1 + s5 c0``.
    """
    s0 = a00 * a11 - a10 * a01
    s1 = a00 * a12 - a10 * a02
    s2 = a00 * a13 - a10 * a03
    s3 = a01 * a12 - a11 * a02
    s4 = a01 * a13 - a11 * a03
    s5 = a02 * a13 - a12 * a03
    c5 = a22 * a33 - a32 * a23
    c4 = a21 * a33 - a31 * a23
    c3 = a21 * a32 - a31 * a22
    c2 = a20 * a33 - a30 * a23
    c1 = a20 * a32 - a30 * a22
    c0 = a20 * a31 - a30 * a21
    det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0
    return (s0, s1, s2, s3, s4, s5, c0, c1, c2, c3, c4, c5, det)


# -- affine: [A | t], 3x4 ---------------------------------------------------------


@kernel(inputs=[(3, 4), (3, 4)], outputs=[(3, 4)])
def affine_compose(
    a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2,
    b00, b01, b02, u0, b10, b11, b12, u1, b20, b21, b22, u2,
):  # fmt: skip
    """``[A | t] [B | u] = [A B | A u + t]`` (the right one applied first)."""
    return (
        a00 * b00 + a01 * b10 + a02 * b20,
        a00 * b01 + a01 * b11 + a02 * b21,
        a00 * b02 + a01 * b12 + a02 * b22,
        a00 * u0 + a01 * u1 + a02 * u2 + t0,
        a10 * b00 + a11 * b10 + a12 * b20,
        a10 * b01 + a11 * b11 + a12 * b21,
        a10 * b02 + a11 * b12 + a12 * b22,
        a10 * u0 + a11 * u1 + a12 * u2 + t1,
        a20 * b00 + a21 * b10 + a22 * b20,
        a20 * b01 + a21 * b11 + a22 * b21,
        a20 * b02 + a21 * b12 + a22 * b22,
        a20 * u0 + a21 * u1 + a22 * u2 + t2,
    )


@kernel(inputs=[(3, 4), (3,)], outputs=[(3,)])
def affine_apply(a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2, px, py, pz):
    """``A p + t``."""
    return (
        a00 * px + a01 * py + a02 * pz + t0,
        a10 * px + a11 * py + a12 * pz + t1,
        a20 * px + a21 * py + a22 * pz + t2,
    )


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
    b00 = a00 * k
    b01 = a01 * k
    b02 = a02 * k
    b10 = a10 * k
    b11 = a11 * k
    b12 = a12 * k
    b20 = a20 * k
    b21 = a21 * k
    b22 = a22 * k
    c00 = b11 * b22 - b12 * b21
    c10 = b12 * b20 - b10 * b22
    c20 = b10 * b21 - b11 * b20
    det = b00 * c00 + b01 * c10 + b02 * c20
    d = k / where(abs(det) > 0.0, det, 1.0)
    i00 = c00 * d
    i01 = (b02 * b21 - b01 * b22) * d
    i02 = (b01 * b12 - b02 * b11) * d
    i10 = c10 * d
    i11 = (b00 * b22 - b02 * b20) * d
    i12 = (b02 * b10 - b00 * b12) * d
    i20 = c20 * d
    i21 = (b01 * b20 - b00 * b21) * d
    i22 = (b00 * b11 - b01 * b10) * d
    r00, r01, r02 = unit_row3(a00, a01, a02)
    r10, r11, r12 = unit_row3(a10, a11, a12)
    r20, r21, r22 = unit_row3(a20, a21, a22)
    ratio = abs(det3(r00, r01, r02, r10, r11, r12, r20, r21, r22))
    return (
        i00, i01, i02, -(i00 * t0 + i01 * t1 + i02 * t2),
        i10, i11, i12, -(i10 * t0 + i11 * t1 + i12 * t2),
        i20, i21, i22, -(i20 * t0 + i21 * t1 + i22 * t2),
        ratio,
    )  # fmt: skip


@kernel(inputs=[(3, 4)], outputs=[()])
def affine_hadamard_ratio(a00, a01, a02, t0, a10, a11, a12, t1, a20, a21, a22, t2):
    """``|det A| / (|a_0| |a_1| |a_2|)`` for the rows ``a_i`` of ``A``, in [0, 1]."""
    r00, r01, r02 = unit_row3(a00, a01, a02)
    r10, r11, r12 = unit_row3(a10, a11, a12)
    r20, r21, r22 = unit_row3(a20, a21, a22)
    return (abs(det3(r00, r01, r02, r10, r11, r12, r20, r21, r22)),)


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
    x = a00 * px + a01 * py + a02 * pz + a03
    y = a10 * px + a11 * py + a12 * pz + a13
    z = a20 * px + a21 * py + a22 * pz + a23
    w = a30 * px + a31 * py + a32 * pz + a33
    m = maximum(maximum(abs(x), abs(y)), maximum(abs(z), abs(w)))
    ratio = abs(w) / where(m > 0.0, m, 1.0)
    safe = where(abs(w) > 0.0, w, 1.0)
    return (x / safe, y / safe, z / safe, ratio)


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
    b00 = a00 * k
    b01 = a01 * k
    b02 = a02 * k
    b03 = a03 * k
    b10 = a10 * k
    b11 = a11 * k
    b12 = a12 * k
    b13 = a13 * k
    b20 = a20 * k
    b21 = a21 * k
    b22 = a22 * k
    b23 = a23 * k
    b30 = a30 * k
    b31 = a31 * k
    b32 = a32 * k
    b33 = a33 * k
    s0, s1, s2, s3, s4, s5, c0, c1, c2, c3, c4, c5, det = minors4(
        b00, b01, b02, b03, b10, b11, b12, b13, b20, b21, b22, b23, b30, b31, b32, b33
    )
    d = k / where(abs(det) > 0.0, det, 1.0)
    r00, r01, r02, r03 = unit_row4(a00, a01, a02, a03)
    r10, r11, r12, r13 = unit_row4(a10, a11, a12, a13)
    r20, r21, r22, r23 = unit_row4(a20, a21, a22, a23)
    r30, r31, r32, r33 = unit_row4(a30, a31, a32, a33)
    ratio = abs(
        minors4(
            r00, r01, r02, r03, r10, r11, r12, r13, r20, r21, r22, r23, r30, r31, r32, r33
        )[12]
    )
    return (
        (b11 * c5 - b12 * c4 + b13 * c3) * d,
        (-b01 * c5 + b02 * c4 - b03 * c3) * d,
        (b31 * s5 - b32 * s4 + b33 * s3) * d,
        (-b21 * s5 + b22 * s4 - b23 * s3) * d,
        (-b10 * c5 + b12 * c2 - b13 * c1) * d,
        (b00 * c5 - b02 * c2 + b03 * c1) * d,
        (-b30 * s5 + b32 * s2 - b33 * s1) * d,
        (b20 * s5 - b22 * s2 + b23 * s1) * d,
        (b10 * c4 - b11 * c2 + b13 * c0) * d,
        (-b00 * c4 + b01 * c2 - b03 * c0) * d,
        (b30 * s4 - b31 * s2 + b33 * s0) * d,
        (-b20 * s4 + b21 * s2 - b23 * s0) * d,
        (-b10 * c3 + b11 * c1 - b12 * c0) * d,
        (b00 * c3 - b01 * c1 + b02 * c0) * d,
        (-b30 * s3 + b31 * s1 - b32 * s0) * d,
        (b20 * s3 - b21 * s1 + b22 * s0) * d,
        ratio,
    )


@kernel(inputs=[(4, 4)], outputs=[()])
def projective_hadamard_ratio(
    a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33,
):  # fmt: skip
    """``|det H| / prod_i |h_i|`` for the rows ``h_i`` of ``H``, in [0, 1]."""
    r00, r01, r02, r03 = unit_row4(a00, a01, a02, a03)
    r10, r11, r12, r13 = unit_row4(a10, a11, a12, a13)
    r20, r21, r22, r23 = unit_row4(a20, a21, a22, a23)
    r30, r31, r32, r33 = unit_row4(a30, a31, a32, a33)
    det = minors4(
        r00, r01, r02, r03, r10, r11, r12, r13, r20, r21, r22, r23, r30, r31, r32, r33
    )[12]
    return (abs(det),)
