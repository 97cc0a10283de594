"""What the functional modules of the groups share: the vocabulary and the right Jacobians.

Every group module (``so3``, ``se3``, ``so2``, ``se2``, ``sim3``) offers the same Lie
vocabulary, :data:`VOCABULARY` (one name per concept in every group). Of the four
Jacobians a module writes only the left one and its inverse (kernels, with their
formulas and series); the right ones are derived here, once for all groups:

    ``exp(x + d) ~ exp(J_l(x) d) exp(x)``  (left)     ``exp(x + d) ~ exp(x) exp(J_r(x) d)``
    (right), and ``J_r(x) = J_l(-x)``, ``J_r(x)^-1 = J_l(-x)^-1``,

because ``exp(-x) = exp(x)^-1`` in every matrix Lie group: inverting
``exp(-x - d) ~ exp(-J_l(-x) d) exp(-x)`` gives ``exp(x + d) ~ exp(x) exp(J_l(-x) d)``.

>>> import numpy as np
>>> from rigidkit import se3
>>> xi = np.array([0.3, -0.1, 0.2, 0.1, -0.2, 0.3])
>>> bool(np.allclose(se3.right_jacobian(xi), se3.left_jacobian(-xi), rtol=0, atol=1e-15))
True
"""

from __future__ import annotations

from .._validate import finite_array

__all__ = ["VOCABULARY", "right_jacobians"]

VOCABULARY = (
    "hat",
    "vee",
    "exp",
    "log",
    "adjoint",
    "ad",
    "bracket",
    "left_jacobian",
    "right_jacobian",
    "left_jacobian_inverse",
    "right_jacobian_inverse",
)

_DOC = """{title} of {group}: {relation}; ``{symbol}(x) = {left}(-x)``.

Derived from the left one for every group (:mod:`rigidkit.functional._lie`).

Parameters
----------
x : array_like, shape (..., {dof})
    {tangent}, finite.

Returns
-------
ndarray, shape (..., {dof}, {dof})

See Also
--------
{see_also}
"""


def right_jacobians(module, group, dof, tangent, left, left_inverse):
    """``right_jacobian, right_jacobian_inverse`` of a group from its left kernels.

    ``module`` is the ``__name__`` of the group module the functions belong to,
    ``tangent`` names its tangent vectors (shape (..., dof)) in messages and docs,
    ``left`` and ``left_inverse`` are the kernels of ``J_l`` and ``J_l^-1``.
    """

    def right_jacobian(x):
        return left(-finite_array(x, (dof,), tangent))

    def right_jacobian_inverse(x):
        return left_inverse(-finite_array(x, (dof,), tangent))

    docs = {
        right_jacobian: (
            "Right Jacobian",
            "``exp(x + d) ~ exp(x) exp(J_r(x) d)``",
            "J_r",
            "left_jacobian, right_jacobian_inverse",
        ),
        right_jacobian_inverse: (
            "Inverse of the right Jacobian",
            "``log(exp(x) exp(d)) ~ x + J_r(x)^-1 d``",
            "J_r^-1",
            "left_jacobian_inverse, right_jacobian",
        ),
    }
    for fn, (title, relation, symbol, see_also) in docs.items():
        fn.__doc__ = _DOC.format(
            title=title,
            group=group,
            relation=relation,
            symbol=symbol,
            left=symbol.replace("_r", "_l"),
            dof=dof,
            tangent=tangent.capitalize(),
            see_also=see_also,
        )
        fn.__module__ = module
        fn.__qualname__ = fn.__name__
    return right_jacobian, right_jacobian_inverse
