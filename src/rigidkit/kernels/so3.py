"""Kernels of the so(3) hat and vee maps."""

from .._engine import kernel


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def hat(wx, wy, wz):
    """Skew matrix ``hat(w)`` with ``hat(w) @ v == cross(w, v)``."""
    return (0.0, -wz, wy, wz, 0.0, -wx, -wy, wx, 0.0)


@kernel(inputs=[(3, 3)], outputs=[(3,)])
def vee(m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """Inverse of ``hat``, from the skew-symmetric part ``(W - W^T) / 2``."""
    return (0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01))
