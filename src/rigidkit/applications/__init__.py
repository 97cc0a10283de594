"""Layer 4, applications built on the layers below: the command line, the SymPy
derivations (``rk.symbolic``), and kinematics, interpolation and alignment.

See ``docs/architecture.md``.
"""
