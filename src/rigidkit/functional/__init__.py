"""Layer 2, the functional layer: arrays in, arrays out, batched over leading axes.

One module per group or representation (``so3``, ``se3``, ``so2``, ``se2``, ``sim3``,
``conversions``, ``euler``, ``quaternion``). Each function validates its input
(see :mod:`rigidkit._validate`) and calls the scalar kernels of
:mod:`rigidkit.kernels`; nothing here imports the object layer. The public paths
``rk.so3`` etc. point here. See ``docs/architecture.md``.
"""
