"""The kernel engine: one scalar formula, bound to every backend.

The layers above declare against this surface and never generate, ``exec`` or
compile code themselves (``tests/test_layers.py`` checks):

* formulas: :func:`kernel`, :func:`helper` (:class:`Kernel`, :class:`Helper`),
  and :func:`rebind`, a kernel's or helper's function with other primitives;
* array namespaces: :func:`namespace_of`, :func:`float_dtype_of`, ...;
* owned fast paths: :func:`owned_function`, a function of objects that goes
  straight to a kernel's compiled loop (``a @ b``, ``inv``, ``as_matrix``,
  ``rk.slerp``);
* host loops compiled in the background: :func:`in_background` queues a build
  for the engine's one compile thread, which calls :func:`compile_scan` (the
  sequential scan of a chain kernel), :func:`compile_fold` (a running state and
  sums, only the last kept) or :func:`compile_host_loop` (a function in
  numba's subset); :func:`run_split` splits a call over the idle cores, and
  :func:`numba_available` says whether any of this can happen;
* shared state: :class:`Lock` (``threading.Lock``), for the layers above that
  guard data read and written from several threads (``rk.FrameGraph``); they
  start no threads themselves;
* the install step: :func:`precompile` (kernels' loops into the disk cache,
  :func:`cache_dir`) and :func:`waiting_for_loops` (every batch compiles).
"""

from threading import Lock  # for the layers above, which import no threading

from .binding import rebind
from .host_loops import (
    compile_fold,
    compile_host_loop,
    compile_scan,
    idle_workers,
    run_split,
)
from .kernel import Helper, Kernel, helper, kernel, waiting_for_loops
from .namespace import float_dtype_of, is_numpy, is_torch, namespace_of
from .numba_backend import available as numba_available
from .numba_backend import cache_dir, drain, in_background, precompile
from .owned import owned_function

__all__ = [
    "Helper",
    "Kernel",
    "Lock",
    "cache_dir",
    "compile_fold",
    "compile_host_loop",
    "compile_scan",
    "drain",
    "float_dtype_of",
    "helper",
    "idle_workers",
    "in_background",
    "is_numpy",
    "is_torch",
    "kernel",
    "namespace_of",
    "numba_available",
    "owned_function",
    "precompile",
    "rebind",
    "run_split",
    "waiting_for_loops",
]

# jax or torch imported before rigidkit: set them up now (see post_import).
import sys as _sys  # noqa: E402

from . import post_import as _post_import  # noqa: E402

if "torch" in _sys.modules:
    from . import torch_setup as _torch_setup  # noqa: F401
_post_import.settle()
