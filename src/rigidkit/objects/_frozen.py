"""Arrays handed out by an object never alias its storage.

Objects are immutable values: writing into an array that a method or
property returned must not change the object. Accessors that would return the
stored array itself, or a slice of it (``Rotation.as_quat``, ``Transform.translation``,
``Quaternion.w``, ``Projective.as_matrix``, ...), pass it through :func:`frozen`;
everything else an object returns is computed fresh by a kernel and is the caller's
own.

Per namespace, the cheapest array that cannot change the object:

* NumPy: a read-only view (``setflags(write=False)``). Its cost does not grow
  with the batch; a copy's does. Medians of 61 round-robin samples (2 shared
  cores, load ~6): N = 1: view 0.33 us, copy 0.15 us; N = 1e3: view 0.33 us,
  copy 2.5 us; N = 1e6 (quaternions, 32 MB): view 1.4 us, copy 7.5 ms. The copy
  saves 0.2 us at N = 1 only, and would make a result writable at one size and
  read-only at another, so every size gets the view. Writing into it raises
  ``ValueError: assignment destination is read-only``; ``.copy()`` it to edit.
* JAX: the array itself (JAX arrays are immutable).
* Dask: a new array object on the same graph (``x[i] = v`` changes only that
  object), which computes nothing.
* torch (no read-only tensors) and any other namespace: a copy (``clone``, which
  keeps the autograd graph).

>>> import numpy as np
>>> import rigidkit as rk
>>> A_R_B = rk.Rotation.identity()
>>> q = A_R_B.as_quat()
>>> q.flags.writeable
False
>>> q = q.copy()
>>> q *= 2.0                     # the caller's own array now
>>> A_R_B.as_quat()
array([1., 0., 0., 0.])
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import is_torch, namespace_of

__all__ = ["frozen", "owned"]


def frozen(a):
    """``a`` (stored data or a slice of it) in a form the caller cannot write back."""
    if type(a) is np.ndarray:
        v = a.view()
        v.setflags(write=False)  # a little faster than ``v.flags.writeable = False``
        return v
    if is_torch(a):
        return a.clone()
    module = type(a).__module__
    if module.startswith("jax"):
        return a
    if module.startswith("dask"):  # a new array object (x[i] = v rebinds only it): lazy
        return a.copy()
    return namespace_of(a).asarray(a, copy=True)


def owned(a, source):
    """``a`` if it is not (a view of) the caller's array ``source``, else a copy.

    For constructors that would otherwise store the caller's array as is (a later
    write by the caller into ``source`` would then change the object).
    """
    if type(a) is np.ndarray:
        shared = type(source) is np.ndarray and np.may_share_memory(a, source)
        return a.copy() if shared else a
    return frozen(a) if a is source else a
