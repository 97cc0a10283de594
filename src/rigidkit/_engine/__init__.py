"""The kernel engine: one scalar formula, bound to every backend (see DESIGN.md)."""

from .kernel import Helper, Kernel, helper, kernel
from .namespace import float_dtype_of, is_numpy, is_torch, namespace_of

__all__ = [
    "Helper",
    "Kernel",
    "helper",
    "kernel",
    "namespace_of",
    "float_dtype_of",
    "is_numpy",
    "is_torch",
]
