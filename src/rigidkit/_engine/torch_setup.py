"""Everything rigidkit sets up for PyTorch, done once, by importing this module.

Imported the first time the engine meets a torch tensor (``namespace_of``), or
at ``import rigidkit`` if torch is already imported; it imports torch. Its top
level builds the namespace adapter (torch does not yet expose the array-API
names the kernels use) and :func:`bind`, and runs the setup registered for torch
(:func:`.post_import.when_imported`): the adapter becomes ``namespace_of``'s,
every kernel is bound to torch, the object classes become torch pytree nodes.

All of it is done by an ``import`` statement on purpose: ``torch.compile``
cannot trace the making of a function or a namespace, but TorchDynamo executes
an ``import`` for real when it meets one (``IMPORT_NAME``), so a first tensor
met inside a compiled function (``fullgraph=True``) still finds everything made.
"""

from __future__ import annotations

import torch

from . import post_import
from .primitives import xp_bindings

__all__ = ["NAMESPACE"]


def _namespace(**names):
    return type("torch", (), names)


def asarray(x, dtype=None, device=None, copy=None):
    if isinstance(x, torch.Tensor):
        out = x
        if dtype is not None and out.dtype != dtype:
            out = out.to(dtype)
        if device is not None and out.device != torch.device(device):
            out = out.to(device)
        return out.clone() if copy else out
    return torch.as_tensor(x, dtype=dtype, device=device)


# A class named torch (its attributes used unbound): TorchDynamo guards a class
# met through an import by identity, where it cannot guard a SimpleNamespace.
NAMESPACE = _namespace(
    float32=torch.float32,
    float64=torch.float64,
    bool=torch.bool,
    sqrt=torch.sqrt,
    sin=torch.sin,
    cos=torch.cos,
    tan=torch.tan,
    asin=torch.asin,
    acos=torch.acos,
    atan=torch.atan,
    atan2=torch.atan2,
    exp=torch.exp,
    log=torch.log,
    abs=torch.abs,
    where=torch.where,
    maximum=torch.maximum,
    minimum=torch.minimum,
    copysign=torch.copysign,
    isfinite=torch.isfinite,
    asarray=asarray,
    stack=lambda arrays, axis=0: torch.stack(tuple(arrays), dim=axis),
    concat=lambda arrays, axis=0: torch.cat(tuple(arrays), dim=axis),
    broadcast_to=lambda x, shape: torch.broadcast_to(x, tuple(shape)),
    reshape=lambda x, shape: torch.reshape(x, tuple(shape)),
    zeros=lambda shape, dtype=None, device=None: torch.zeros(
        tuple(shape), dtype=dtype, device=device
    ),
    all=lambda x, axis=None: torch.all(x) if axis is None else torch.all(x, dim=axis),
    any=lambda x, axis=None: torch.any(x) if axis is None else torch.any(x, dim=axis),
    sum=lambda x, axis=None: torch.sum(x) if axis is None else torch.sum(x, dim=axis),
    isdtype=lambda dtype, kind: (
        dtype.is_floating_point if kind == "real floating" else False
    ),
    nonzero=torch.nonzero,
    ones_like=torch.ones_like,
    zeros_like=torch.zeros_like,
    linalg=torch.linalg,
    max=lambda x, axis=None: torch.amax(x) if axis is None else torch.amax(x, dim=axis),
    matmul=torch.matmul,
)


def bind(k) -> None:
    """Bind kernel ``k`` to torch now (float32 and float64), not at first use.

    ``torch.compile`` cannot trace the making of a function (the rebinding), and
    a kernel's first torch call may come inside a compiled function. Scalars
    are lifted to CPU tensors (``device=None``), which torch combines with
    tensors of any device, so one binding per dtype serves every device.
    """
    for dtype in (torch.float32, torch.float64):
        key = ("torch", str(dtype), "None")
        if key not in k._xp_cache:
            k._xp_cache[key] = k.bound(xp_bindings(NAMESPACE, dtype, None))


# The setup registered for torch, run now, inside this import: the namespace
# becomes namespace_of's, every kernel is bound, the classes become pytree nodes.
post_import.arrived("torch")
