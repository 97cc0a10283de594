"""Layer 2, the functional layer: arrays in, arrays out, batched over leading axes.

One module per group (``so3``, ``se3``, ``so2``, ``se2``, ``sim3``: its Lie vocabulary)
or representation (``conversions``, ``euler``, ``quaternion``, ``pose_formats``,
``screw``: its conversions), split as the kernels are (``docs/architecture.md``,
"The layers"), and the array algorithms. Each function validates its input
(see :mod:`rigidkit._validate`) and calls the scalar kernels of
:mod:`rigidkit.kernels`; nothing here imports the object layer. The public paths
``rk.so3`` etc. point here. See ``docs/architecture.md``.
"""
