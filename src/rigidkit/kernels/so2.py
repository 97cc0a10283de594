"""Kernels of SO(2): unit complex numbers ``(c, s) = (cos θ, sin θ)``, 2x2 matrices.

A rotation by ``θ`` is ``e^{iθ} = c + i s``, acting on points ``p = x + i y`` by
complex multiplication; its matrix is ``[[c, -s], [s, c]] = exp(θ J)`` with
``J = [[0, -1], [1, 0]]``. Tangent vectors are 1-vectors ``(θ,)``, radians.
"""

from .._engine import helper, kernel
from .vector import normalize4, renormalize4


@helper
def angle_of(c, s):
    """The angle of ``c + i s`` in (-pi, pi].

    ``atan2`` is accurate to an ulp everywhere (no cancellation near 0 or pi) and
    returns values in [-pi, pi]; ``-pi`` (from ``s = -0.0``, or ``s`` below the
    last ulp of pi) is the same rotation as ``pi`` and is folded onto it.
    """
    a = atan2(s, c)
    return where(a <= -pi, -a, a)


@kernel(inputs=[(2,)], outputs=[(2,), ()])
def complex_normalize(c, s):
    """``z / |z|`` and ``|z|``, scaled by the largest component (no overflow).

    See :func:`~rigidkit.kernels.vector.normalize4`.

    A zero input gives zero components and norm 0, which callers reject.
    """
    c, s, _, _, n = normalize4(c, s, 0.0, 0.0)
    return (c, s, n)


@helper
def complex_from_block(m00, m01, m10, m11):
    """Nearest rotation ``(c, s)`` of a 2x2 block, the block's norm, and its defect.

    ``|M - R|_F^2 = |M|_F^2 + 2 - 2 (c (m00 + m11) + s (m10 - m01))``, so the
    nearest rotation (for any ``M``) is ``(m00 + m11, m10 - m01)`` normalised: no
    SVD needed, and for a rotation matrix it returns ``(c, s)`` to an ulp. The
    sum is scaled by its largest component first (no overflow). The returned norm
    is 0 when every rotation is equally near (a reflection, the zero matrix).

    The defect is ``max(max|M^T M - I|, |det M - 1|)``: 0 for a rotation, 2 for
    a reflection; callers compare it to their tolerance.
    """
    c, s, n = complex_normalize(m00 + m11, m10 - m01)
    e00 = m00 * m00 + m10 * m10 - 1.0
    e11 = m01 * m01 + m11 * m11 - 1.0
    e01 = m00 * m01 + m10 * m11
    det = m00 * m11 - m01 * m10
    err = maximum(maximum(abs(e00), abs(e11)), maximum(abs(e01), abs(det - 1.0)))
    return (c, s, n, err)


@kernel(inputs=[(1,)], outputs=[(2,)])
def complex_from_angle(theta):
    """``exp``: ``(cos θ, sin θ)``."""
    return (cos(theta), sin(theta))


@kernel(inputs=[(1,)], outputs=[(2, 2)])
def matrix_from_angle(theta):
    """``exp(θ J) = [[cos θ, -sin θ], [sin θ, cos θ]]``."""
    c = cos(theta)
    s = sin(theta)
    return (c, -s, s, c)


@kernel(inputs=[(2,)], outputs=[(1,)])
def angle_from_complex(c, s):
    """``log``: the angle in (-pi, pi] of a (not necessarily unit) complex number."""
    return (angle_of(c, s),)


@kernel(inputs=[(2,), (2,)], outputs=[(2,)])
def complex_multiply(c1, s1, c2, s2):
    """Product ``z1 z2``: the rotation by ``θ1 + θ2`` (commutative in 2D).

    Renormalised (:func:`~rigidkit.kernels.vector.renormalize4`), so chains of
    compositions stay unit to a few ulp.
    """
    c, s, _, _ = renormalize4(c1 * c2 - s1 * s2, s1 * c2 + c1 * s2, 0.0, 0.0)
    return (c, s)


@kernel(inputs=[(2,)], outputs=[(2,)])
def complex_conjugate(c, s):
    """Conjugate ``(c, -s)``: the inverse rotation of a unit complex number."""
    return (c, -s)


@kernel(inputs=[(2,), (2,)], outputs=[(2,)])
def complex_apply(c, s, x, y):
    """Rotate the point ``(x, y)``: ``(c x - s y, s x + c y)``."""
    return (c * x - s * y, s * x + c * y)


@kernel(inputs=[(2,)], outputs=[(2, 2)])
def matrix_from_complex(c, s):
    """Rotation matrix ``[[c, -s], [s, c]]`` (active, acting on column vectors)."""
    return (c, -s, s, c)


@kernel(inputs=[(2, 2)], outputs=[(2,), (), ()])
def complex_from_matrix(m00, m01, m10, m11):
    """Nearest unit complex number, block norm and defect (see ``complex_from_block``)."""
    return complex_from_block(m00, m01, m10, m11)


@kernel(inputs=[(2,), (2,)], outputs=[()])
def angle_between(c1, s1, c2, s2):
    """``|angle(z1* z2)|`` in [0, pi]: the angle of the rotation taking z1 to z2."""
    return (abs(atan2(c1 * s2 - s1 * c2, c1 * c2 + s1 * s2)),)


@kernel(inputs=[(1,)], outputs=[(2, 2)])
def hat(theta):
    """``hat(θ) = θ J = [[0, -θ], [θ, 0]]``."""
    return (0.0, -theta, theta, 0.0)


@kernel(inputs=[(2, 2)], outputs=[(1,)])
def vee(m00, m01, m10, m11):
    """Inverse of ``hat``, from the skew-symmetric part ``(W - W^T) / 2``."""
    return (0.5 * (m10 - m01),)


@kernel(inputs=[(2,)], outputs=[(1, 1)])
def adjoint_from_complex(c, s):
    """``Ad = [[1]]``: SO(2) is commutative, ``R exp(θ) R^-1 = exp(θ)``."""
    return (1.0,)


@kernel(inputs=[(1,)], outputs=[(1, 1)])
def jacobian(theta):
    """Left and right Jacobians of SO(2) and their inverses: all ``[[1]]``."""
    return (1.0,)


@kernel(inputs=[(1,)], outputs=[(1, 1)])
def ad(theta):
    """Small adjoint ``ad(θ) = [[0]]`` (so(2) is abelian)."""
    return (0.0,)


@kernel(inputs=[(1,), (1,)], outputs=[(1,)])
def bracket(theta1, theta2):
    """Lie bracket ``[θ1, θ2] = 0`` (so(2) is abelian)."""
    return (0.0,)
