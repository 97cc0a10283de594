"""Layer 3, the object layer: thin typed classes holding one array each.

``Rotation``, ``Transform``, ``Rotation2D``, ``Transform2D``, ``Quaternion``,
``Similarity``, ``Affine``, ``Projective``, the group interface ``LieGroup`` and
the container protocol ``BatchedArray``. Classes call the functional layer; no
formula lives here. See ``docs/architecture.md``.
"""
