"""Kernels between unit quaternions and the continuous 6D representation.

The 6D representation of Zhou et al. (2019), "On the Continuity of Rotation
Representations in Neural Networks" (CVPR): the first two COLUMNS ``a1, a2`` of
the rotation matrix (active, on column vectors), laid out ``(a1, a2) = (R00, R10,
R20, R01, R11, R21)``. Any pair of non-parallel vectors maps back to a rotation by
Gram-Schmidt, so a network may output 6 free numbers.
"""

from .._engine import kernel
from .matrix import matrix_entries_from_quat, quat_from_matrix
from .vector import cross3, normalize4


@kernel(inputs=[(4,)], outputs=[(6,)])
def rot6d_from_quat(w, x, y, z):
    """The first two columns of the rotation matrix of a unit quaternion."""
    r00, r01, _, r10, r11, _, r20, r21, _ = matrix_entries_from_quat(w, x, y, z)
    return (r00, r10, r20, r01, r11, r21)


@kernel(inputs=[(6,)], outputs=[(4,), ()])
def quat_from_rot6d(a0, a1, a2, c0, c1, c2):
    """Unit quaternion of the Gram-Schmidt frame of two columns, and a conditioning.

    ``b1 = a1 / |a1|``, ``b2 = u / |u|`` with ``u = a2 - (b1 . a2) b1``, ``b3 = b1 x
    b2``, ``R = [b1 b2 b3]`` (columns); then the quaternion of ``R`` (Shepperd,
    :func:`rigidkit.kernels.matrix.quat_from_matrix`). Norms are scaled
    (:func:`~rigidkit.kernels.vector.normalize4`): no overflow, and finite
    gradients where a norm is 0. The second output is ``|u| / |a2|``, the sine
    of the angle between the columns (0 for a zero ``a2``), which callers compare
    with a rounding-level threshold: ``b2`` is undetermined where it is 0 and
    rounding noise where it is a few eps.
    """
    b1x, b1y, b1z, _, n1 = normalize4(a0, a1, a2, 0.0)
    d = b1x * c0 + b1y * c1 + b1z * c2
    ux = c0 - d * b1x
    uy = c1 - d * b1y
    uz = c2 - d * b1z
    b2x, b2y, b2z, _, nu = normalize4(ux, uy, uz, 0.0)
    _, _, _, _, n2 = normalize4(c0, c1, c2, 0.0)
    b3x, b3y, b3z = cross3(b1x, b1y, b1z, b2x, b2y, b2z)
    w, x, y, z, _ = quat_from_matrix(b1x, b2x, b3x, b1y, b2y, b3y, b1z, b2z, b3z)
    sine = where(n1 > 0.0, nu / where(n2 > 0.0, n2, 1.0), 0.0)
    return (w, x, y, z, sine)
