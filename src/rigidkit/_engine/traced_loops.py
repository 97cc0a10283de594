"""Loops whose trip count depends on values, inside ``torch.compile``.

Traced code cannot branch on values, so an iteration that stops at convergence
(the Karcher mean, the rotation spline's Newton solve) is, outside JAX's
``lax.while_loop``, unrolled to its largest step count with each result frozen
once converged. Unrolled inside ``torch.compile`` that is a graph of ``max_iter``
copies of the step, which Inductor compiles in minutes (750 s for a mean of
100 steps, torch 2.13 on 2 cores). torch's ``while_loop`` higher-order operator
keeps one copy and stops when the condition does; it has no backward
(torch 2.13: "doesn't support training"), so it serves the values where no
gradient is asked for, and where the caller differentiates a last step
outside it (the implicit derivative at the fixed point).
"""

from __future__ import annotations

from . import namespace
from .namespace import is_torch

__all__ = ["compiled_while", "torch_compiling"]


def torch_compiling(*arrays) -> bool:
    """Whether ``torch.compile`` traces now and every array is a torch tensor
    (``torch.func`` transforms and eager torch stay on the unrolled loop)."""
    for a in arrays:
        if not is_torch(a):
            return False
    return namespace.COMPILER._is_compiling_flag


def needs_grad(*arrays) -> bool:
    """Whether any tensor of ``arrays`` asks for a gradient (static under tracing)."""
    return any(getattr(a, "requires_grad", False) for a in arrays)


def compiled_while(cond, body, state):
    """``while cond(*state): state = body(*state)`` as one graph node.

    ``state`` is a tuple of tensors whose shapes and dtypes the body keeps;
    ``cond`` returns a 0-d boolean tensor. Tensors the two functions capture
    must not alias each other (copy them). Only inside ``torch.compile``
    (:func:`torch_compiling`).
    """
    from torch._higher_order_ops import while_loop

    # Copies: Inductor refuses a state that aliases the loop's other inputs (a
    # mean started from a view of the data: "might be aliasing the input").
    return tuple(while_loop(cond, body, tuple(s.clone() for s in state)))
