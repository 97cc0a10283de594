"""Kernels of motion: velocities and accelerations of frames, and integration steps.

One module per subject, as in :mod:`rigidkit.applications.kinematics`:
:mod:`.rotation` (turning frames, quaternion rates), :mod:`.twist` (twists, pose
derivatives, points of a body), :mod:`.euler_rates` (the Euler-angle rate matrix),
:mod:`.integration` (steps of SO(3) and SE(3)) and :mod:`.planar` (SO(2), SE(2)).
The groups' own vocabulary (exp, log, Jacobians) is in the group modules one level
up, which these import.
"""
