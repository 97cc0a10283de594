"""Scalar kernels, one module per representation; see :mod:`rigidkit._engine`.

Each kernel is a plain function of scalar components. Free names are primitives
(``sqrt``, ``where``, ...) bound per backend, which is why linters see them as
undefined here.
"""
