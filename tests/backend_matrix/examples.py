"""One example call per public callable of rigidkit.

An :class:`Example` is a function of arrays (``fn(*args)``, written once, run on
NumPy, JAX, torch and Dask arrays alike), generators of small valid float64 inputs,
the argument to batch (``jax.vmap``/``torch.func.vmap`` stack two draws of it) and the
argument to differentiate (gradients are compared with central finite differences of
the NumPy call). Constrained inputs (rotation matrices, poses, unit quaternions of
the functions that check them) are built inside ``fn`` from free parameters, so the
finite differences stay on the manifold.

Where a transform cannot apply at all (a file reader, a string parser, metadata such
as ``shape``, a Boolean result under ``grad``), ``na`` says why; the cells that are
expected to fail are declared, with their reason, in ``status.py``.

:func:`public_callables` enumerates the public API (``rk.__all__``, the public
modules' ``__all__``, the members of every public class) and ``test_matrix.py`` fails
when one has no example here.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import types
import zlib
from collections.abc import Callable

import numpy as np

import rigidkit as rk

TRANSFORMS = ("jit", "vmap", "grad", "torch_grad", "torch_vmap", "dask", "compile")
TRANSFORM_TITLES = {
    "jit": "jax.jit",
    "vmap": "jax.vmap",
    "grad": "jax.grad",
    "torch_grad": "torch autograd",
    "torch_vmap": "torch.func.vmap",
    "dask": "Dask (lazy)",
    "compile": "torch.compile",
}
GRADS = ("grad", "torch_grad")


# -- inputs: generators of small valid float64 arrays, seeded per example --------------
def V(*shape, lo=-1.0, hi=1.0):
    """Uniform entries in ``[lo, hi)`` (vectors, rotation vectors, twists, points)."""
    return lambda rng: rng.uniform(lo, hi, shape)


def Q(*shape):
    """Unit quaternions, scalar first."""

    def gen(rng):
        q = rng.standard_normal(shape + (4,))
        q = q / np.linalg.norm(q, axis=-1, keepdims=True)
        return q * np.sign(q[..., :1])

    return gen


def S(lo=0.2, hi=0.8):
    """One scalar (shape ``()``)."""
    return lambda rng: np.float64(rng.uniform(lo, hi))


def TIMES(n, lo=0.5, hi=1.5):
    """Increasing stamps, steps in ``[lo, hi)``."""
    return lambda rng: np.cumsum(rng.uniform(lo, hi, n))


@dataclasses.dataclass(frozen=True)
class Example:
    name: str
    fn: Callable
    gens: tuple
    batch: int | None = 0  # the argument vmap stacks two draws of
    diff: int | None = 0  # the argument gradients are taken with respect to
    na: dict = dataclasses.field(default_factory=dict)  # transform -> why it cannot apply
    series: bool = False  # axis 0 of the batched argument is a series, not a batch
    atol: float = 1e-9  # relative to the result's scale, between backends

    def inputs(self, draw: int = 0):
        """The example's NumPy inputs (draw 1 is the second element of a vmap batch)."""
        rng = np.random.default_rng(zlib.crc32(self.name.encode()) + 7919 * draw)
        return [g(rng) for g in self.gens]

    def applies(self, transform: str) -> bool:
        return transform not in self.na


EXAMPLES: dict[str, Example] = {}
# Whole namespaces where no transform applies, with the reason: name prefix -> reason.
NOT_APPLICABLE_MODULES: dict[str, str] = {}


def ex(name, fn, *gens, batch=0, diff=0, na=None, **kw):
    """Register an example; ``name`` is the public spelling (``rk.so3.exp``)."""
    assert name not in EXAMPLES, name
    na = dict(na or {})
    if diff is None:
        na.setdefault("grad", "no differentiable float input")
        na.setdefault("torch_grad", "no differentiable float input")
    if batch is None:
        for t in ("vmap", "torch_vmap", "dask"):
            na.setdefault(t, "no array input to batch")
    EXAMPLES[name] = Example(name, fn, tuple(gens), batch, diff, na, **kw)


def na_all(name, reason):
    """A callable no array transform applies to (files, strings, metadata)."""
    ex(name, None, batch=None, diff=None, na={t: reason for t in TRANSFORMS})


def no_grad(reason):
    return {"grad": reason, "torch_grad": reason}


BOOL = no_grad("Boolean result")
INT = no_grad("integer result")
META = "metadata (shape, dtype, length), no array computation"
FILES = "reads or writes files"
PLOT = "draws with matplotlib"
UNDEFINED = (
    "the operator is not defined for this kind (raises TypeError naming the one to use)"
)
SHAPE_BY_VALUE = (
    "the output's shape depends on the input's values (tracing needs static shapes)"
)
STRINGS = "string or dtype argument, no array computation"
GRAPH = "frame-graph structure (frame names), no array computation"
RANDOM = "draws from a NumPy generator: no array input to transform"
RECORD = "a result record (dataclass of fields), no computation"

so2, se2, so3, se3, sim3, se23 = rk.so2, rk.se2, rk.so3, rk.se3, rk.sim3, rk.se23
conv, eul, quat, kin, jac = (
    rk.conversions,
    rk.euler,
    rk.quaternion,
    rk.kinematics,
    rk.jacobians,
)
planar = kin.planar

# -- the Lie-group modules, one loop ---------------------------------------------------
GROUP_DIMS = {"so2": 1, "se2": 3, "so3": 3, "se3": 6, "sim3": 7, "se23": 9}
for _g, _n in GROUP_DIMS.items():
    _m = getattr(rk, _g)
    _p = f"rk.{_g}."
    ex(_p + "hat", _m.hat, V(_n))
    ex(_p + "vee", lambda x, m=_m: m.vee(m.hat(x)), V(_n))
    ex(_p + "exp", _m.exp, V(_n))
    ex(_p + "log", lambda x, m=_m: m.log(m.exp(x)), V(_n))
    ex(_p + "adjoint", lambda x, m=_m: m.adjoint(m.exp(x)), V(_n))
    ex(_p + "bracket", _m.bracket, V(_n), V(_n))
    for _f in ("ad", "left_jacobian", "right_jacobian", "left_jacobian_inverse"):
        ex(_p + _f, getattr(_m, _f), V(_n))
    ex(_p + "right_jacobian_inverse", _m.right_jacobian_inverse, V(_n))

ex("rk.so2.complex_from_matrix", lambda a: so2.complex_from_matrix(so2.exp(a)), V(1))
ex("rk.so2.complex_normalize", so2.complex_normalize, V(2, lo=0.5, hi=1.5))
ex("rk.se2.pose_from_matrix", lambda x: se2.pose_from_matrix(se2.exp(x)), V(3))
ex(
    "rk.se2.matrix_from_pose",
    lambda x: se2.matrix_from_pose(se2.pose_from_matrix(se2.exp(x))),
    V(3),
)
_pose = se3.pose_from_twist
ex("rk.se3.pose_from_matrix", lambda x: se3.pose_from_matrix(se3.exp(x)), V(6))
ex("rk.se3.matrix_from_pose", lambda x: se3.matrix_from_pose(_pose(x)), V(6))
ex("rk.se3.pose_from_twist", _pose, V(6))
ex("rk.se3.twist_from_pose", lambda x: se3.twist_from_pose(_pose(x)), V(6))
ex("rk.se3.pose_from_exp_coords", se3.pose_from_exp_coords, V(6))
ex("rk.se3.exp_coords_from_pose", lambda x: se3.exp_coords_from_pose(_pose(x)), V(6))
ex("rk.se3.dual_quat_from_pose", lambda x: se3.dual_quat_from_pose(_pose(x)), V(6))
ex(
    "rk.se3.pose_from_dual_quat",
    lambda x: se3.pose_from_dual_quat(se3.dual_quat_from_pose(_pose(x))),
    V(6),
)
ex("rk.se3.pq_from_pose", lambda x: se3.pq_from_pose(_pose(x)), V(6))
ex("rk.se3.pose_from_pq", lambda x: se3.pose_from_pq(se3.pq_from_pose(_pose(x))), V(6))
ex("rk.se3.pose_distance", lambda x, y: se3.pose_distance(_pose(x), _pose(y)), V(6), V(6))
ex(
    "rk.se3.pose_distance_unchecked",
    lambda x, y: se3.pose_distance_unchecked(_pose(x), _pose(y)),
    V(6),
    V(6),
)
ex("rk.sim3.pose_from_matrix", lambda x: sim3.pose_from_matrix(sim3.exp(x)), V(7))
ex("rk.se23.extpose_from_matrix", lambda x: se23.extpose_from_matrix(se23.exp(x)), V(9))
ex("rk.se23.extpose_from_tangent", se23.extpose_from_tangent, V(9))
ex(
    "rk.se23.matrix_from_extpose",
    lambda x: se23.matrix_from_extpose(se23.extpose_from_tangent(x)),
    V(9),
)
ex(
    "rk.se23.tangent_from_extpose",
    lambda x: se23.tangent_from_extpose(se23.extpose_from_tangent(x)),
    V(9),
)
ex("rk.se23.extpose_from_parts", se23.extpose_from_parts, Q(), V(3), V(3))


# -- conversions, Euler angles, quaternion algebra -------------------------------------
ex("rk.conversions.quat_normalize", conv.quat_normalize, V(4, lo=0.5, hi=1.5))
ex("rk.conversions.quat_canonical", conv.quat_canonical, V(4))
ex("rk.conversions.quat_compose", conv.quat_compose, Q(), Q())
ex("rk.conversions.quat_apply", conv.quat_apply, Q(), V(3))
ex("rk.conversions.quat_angle_between", conv.quat_angle_between, Q(), Q())
ex("rk.conversions.matrix_from_quat", conv.matrix_from_quat, Q())
ex("rk.conversions.quat_from_matrix", lambda w: conv.quat_from_matrix(so3.exp(w)), V(3))
ex("rk.conversions.quat_from_rotvec", conv.quat_from_rotvec, V(3))
ex("rk.conversions.rotvec_from_quat", conv.rotvec_from_quat, Q())
ex("rk.conversions.quat_from_mrp", conv.quat_from_mrp, V(3, lo=-0.5, hi=0.5))
ex("rk.conversions.mrp_from_quat", conv.mrp_from_quat, Q())
ex("rk.conversions.quat_from_axis_angle", conv.quat_from_axis_angle, V(3, lo=0.3), S())
ex("rk.conversions.axis_angle_from_quat", conv.axis_angle_from_quat, Q())
ex("rk.conversions.quat_wxyz_from_xyzw", conv.quat_wxyz_from_xyzw, Q())
ex("rk.conversions.quat_xyzw_from_wxyz", conv.quat_xyzw_from_wxyz, Q())
ex(
    "rk.conversions.nearest_rotation_matrix",
    lambda w, n: conv.nearest_rotation_matrix(so3.exp(w) + 0.1 * n),
    V(3),
    V(3, 3),
)
na_all("rk.conversions.default_atol", STRINGS)

na_all("rk.euler.parse_sequence", STRINGS)
na_all("rk.euler.gimbal_lock_threshold", STRINGS)
na_all("rk.euler.lock_tolerance", STRINGS)
ex("rk.euler.quat_from_euler", lambda a: eul.quat_from_euler("ZYX", a), V(3))
ex("rk.euler.euler_from_quat", lambda q: eul.euler_from_quat("ZYX", q), Q())
ex(
    "rk.euler.euler_from_quat_unchecked",
    lambda q: eul.euler_from_quat_unchecked("xyz", q),
    Q(),
)
ex("rk.euler.matrix_from_euler", lambda a: eul.matrix_from_euler("XYZ", a), V(3))
ex(
    "rk.euler.euler_from_matrix",
    lambda a: eul.euler_from_matrix("ZYX", eul.matrix_from_euler("ZYX", a)),
    V(3),
)

ex("rk.quaternion.multiply", quat.multiply, V(4), V(4))
ex("rk.quaternion.conjugate", quat.conjugate, V(4))
for _f in ("norm", "inv", "left_matrix", "right_matrix"):
    ex(f"rk.quaternion.{_f}", getattr(quat, _f), V(4, lo=0.3))
ex("rk.quaternion.exp", quat.exp, V(4, lo=-0.5, hi=0.5))
ex("rk.quaternion.log", quat.log, V(4, lo=0.3))
ex("rk.quaternion.rotate", quat.rotate, Q(), V(3))

# -- rk.* functions --------------------------------------------------------------------
R_ = rk.Rotation.from_quat
ex("rk.slerp", lambda a, b, t: rk.slerp(R_(a), R_(b), t).as_quat(), Q(), Q(), S())
ex("rk.align_vectors", lambda a, b: rk.align_vectors(a, b)[0].as_quat(), V(4, 3), V(4, 3))
ex("rk.align_points", lambda a, b: rk.align_points(a, b).as_matrix(), V(5, 3), V(5, 3))
ex("rk.geodesic_distance", lambda a, b: rk.geodesic_distance(R_(a), R_(b)), Q(), Q())
ex("rk.chordal_distance", lambda a, b: rk.chordal_distance(R_(a), R_(b)), Q(), Q())
ex("rk.quat_continuous", rk.quat_continuous, Q(5), series=True)
ex("rk.unwrap_euler", lambda a: rk.unwrap_euler(3 * a), V(5, 3), series=True)
na_all("rk.set_validation.__init__", "switches input validation on or off; no array input")


# -- the group classes -----------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Kind:
    """How to build one element of a class from free parameters, in ``fn``."""

    cls: type
    make: Callable  # free parameters -> object
    gen: Callable  # generator of the free parameters
    out: Callable  # object -> array (for results that are objects)
    point: int | None  # dimension of the points it acts on
    dof: int | None  # dimension of its tangent space (Lie groups)


KINDS = {
    "Rotation": Kind(
        rk.Rotation, rk.Rotation.from_quat, Q(), lambda o: o.as_matrix(), 3, 3
    ),
    "Transform": Kind(rk.Transform, rk.Transform.exp, V(6), lambda o: o.as_matrix(), 3, 6),
    "Rotation2D": Kind(
        rk.Rotation2D, rk.Rotation2D.exp, V(1), lambda o: o.as_matrix(), 2, 1
    ),
    "Transform2D": Kind(
        rk.Transform2D, rk.Transform2D.exp, V(3), lambda o: o.as_matrix(), 2, 3
    ),
    "Similarity": Kind(
        rk.Similarity, rk.Similarity.exp, V(7), lambda o: o.as_matrix(), 3, 7
    ),
    "ExtendedPose": Kind(
        rk.ExtendedPose, rk.ExtendedPose.exp, V(9), lambda o: o.as_matrix(), 3, 9
    ),
    "Affine": Kind(
        rk.Affine,
        lambda m: rk.Affine(m[..., :3, :3] + 2 * _eye(m, 3), m[..., :3, 3]),
        V(3, 4),
        lambda o: o.as_matrix(),
        3,
        None,
    ),
    "Projective": Kind(
        rk.Projective,
        lambda m: rk.Projective(0.3 * m + 2 * _eye(m, 4)),
        V(4, 4),
        lambda o: o.as_matrix(),
        3,
        None,
    ),
}


def many(gen, n):
    """``n`` draws of ``gen`` stacked (a batch of ``n`` elements)."""
    return lambda rng: np.stack([gen(rng) for _ in range(n)])


# The kind each class's ``include`` example passes (one strictly below it, if any).
INCLUDES = {
    "Transform": "Rotation",
    "Similarity": "Transform",
    "Affine": "Similarity",
    "Projective": "Affine",
    "Transform2D": "Rotation2D",
}


def _eye(like, n):
    """The n x n identity, batched like ``like``, in its namespace (a torch tensor
    plus an ndarray converts the tensor to NumPy: no autograd, no vmap)."""
    zero = like[..., :n, :n] * 0
    if hasattr(zero, "new_tensor"):  # torch
        return zero + zero.new_tensor(np.eye(n))
    return zero + np.eye(n)


def _group_examples(cname, k: Kind):
    p = f"rk.{cname}."
    mk, g, out = k.make, k.gen, k.out
    ex(p + "__init__", lambda x: out(mk(x)), g)
    ex(p + "as_matrix", lambda x: mk(x).as_matrix(), g)
    ex(p + "inv", lambda x: out(mk(x).inv()), g)
    ex(p + "compose", lambda x, y: out(mk(x).compose(mk(y))), g, g)
    ex(p + "__matmul__", lambda x, y: out(mk(x) @ mk(y)), g, g)
    for m in ("__mul__", "__rmul__", "__rmatmul__"):
        na_all(p + m, UNDEFINED)
    ex(p + "apply", lambda x, v: mk(x).apply(v), g, V(k.point))
    ex(p + "approx_equal", lambda x, y: mk(x).approx_equal(mk(y)), g, g, na=BOOL)
    small = KINDS[INCLUDES.get(cname, cname)]
    ex(p + "include", lambda y: out(k.cls.include(small.make(y))), small.gen)
    ex(p + "__getitem__", lambda x: out(mk(x)[1]), many(g, 3), series=True)
    ex(p + "reshape", lambda x: out(mk(x).reshape(3, 1)), many(g, 3), series=True)
    ex(
        p + "concatenate",
        lambda x, y: out(k.cls.concatenate([mk(x), mk(y)])),
        many(g, 2),
        many(g, 3),
        series=True,
    )
    ex(p + "from_matrix", lambda x: out(k.cls.from_matrix(mk(x).as_matrix())), g)
    for m in ("shape", "dtype", "single", "__len__", "__iter__"):
        na_all(p + m, META)
    na_all(p + "identity", "builds a constant from a shape: no array input to transform")
    na_all(p + "random", RANDOM)
    if k.dof is not None:
        t = V(k.dof)
        ex(p + "exp", lambda x: out(k.cls.exp(x)), t)
        ex(p + "log", lambda x: mk(x).log(), g)
        ex(p + "adjoint", lambda x: mk(x).adjoint(), g)
        ex(p + "plus", lambda x, d: out(mk(x).plus(d)), g, t)
        ex(p + "minus", lambda x, y: mk(x).minus(mk(y)), g, g)


for _c, _k in KINDS.items():
    _group_examples(_c, _k)

for _c in ("Transform", "Similarity", "Rotation2D", "Transform2D", "ExtendedPose"):
    _k = KINDS[_c]
    ex(
        f"rk.{_c}.mean",
        lambda x, k=_k: k.out(k.make(x).mean()),
        V(4, _k.dof, lo=-0.3, hi=0.3),
    )
for _c in ("Transform", "Rotation"):
    _k = KINDS[_c]
    ex(f"rk.{_c}.__pow__", lambda x, t, k=_k: k.out(k.make(x) ** t), _k.gen, S())

# Rotation's own members
Rk = KINDS["Rotation"]
rot = rk.Rotation
_p = "rk.Rotation."
ex(_p + "from_quat", lambda q: rot.from_quat(q).as_matrix(), V(4, lo=0.3))
ex(_p + "from_rotvec", lambda w: rot.from_rotvec(w).as_matrix(), V(3))
ex(
    _p + "from_axis_angle",
    lambda a, t: rot.from_axis_angle(a, t).as_matrix(),
    V(3, lo=0.3),
    S(),
)
ex(_p + "from_mrp", lambda m: rot.from_mrp(m).as_matrix(), V(3, lo=-0.5, hi=0.5))
ex(_p + "from_euler", lambda a: rot.from_euler("ZYX", a).as_matrix(), V(3))
_AX = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.3]])
_AX = _AX / np.linalg.norm(_AX, axis=-1, keepdims=True)
ex(
    _p + "from_davenport",
    lambda a: rot.from_davenport(_AX, "intrinsic", a).as_matrix(),
    V(3),
)
ex(_p + "as_davenport", lambda q: R_(q).as_davenport(_AX, "intrinsic"), Q())
ex(_p + "from_6d", lambda x: rot.from_6d(x).as_matrix(), V(6, lo=0.3))
ex(_p + "as_6d", lambda q: R_(q).as_6d(), Q())
ex(_p + "as_quat", lambda q: R_(q).as_quat(canonical=True), Q())
ex(_p + "as_rotvec", lambda q: R_(q).as_rotvec(), Q())
ex(_p + "as_axis_angle", lambda q: R_(q).as_axis_angle(), Q())
ex(_p + "as_mrp", lambda q: R_(q).as_mrp(), Q())
ex(_p + "as_euler", lambda q: R_(q).as_euler("xyz"), Q())
ex(_p + "angle", lambda q: R_(q).angle, Q())
ex(_p + "axis", lambda q: R_(q).axis, Q())
ex(_p + "magnitude", lambda q: R_(q).magnitude(), Q())
ex(_p + "angle_to", lambda a, b: R_(a).angle_to(R_(b)), Q(), Q())
ex(_p + "chordal_distance", lambda a, b: R_(a).chordal_distance(R_(b)), Q(), Q())
ex(
    _p + "swing_twist",
    lambda q: [o.as_matrix() for o in R_(q).swing_twist([0.0, 0.0, 1.0])],
    Q(),
)
ex(_p + "continuous", lambda q: R_(q).continuous().as_quat(), Q(5), series=True)
ex(_p + "mean", lambda q: R_(q).mean().as_matrix(), Q(4))
ex(
    "rk.Rotation.mean[geodesic]",
    lambda q: R_(q).mean(method="geodesic").as_matrix(),
    Q(4),
)
na_all(_p + "create_group", "builds a finite group from its name (a string)")
# Made once, outside the transforms, as a symmetry group is: under torch.compile,
# create_group's NumPy (a search for distinct elements) would be traced too.
_C3 = rot.create_group("C3")
ex(
    _p + "reduce",
    lambda q: R_(q).reduce(_C3).as_quat(canonical=True),
    Q(),
    na=no_grad("piecewise constant choice of the group element"),
)

# Transform's own members
T_ = rk.Transform.exp
_p = "rk.Transform."
ex(_p + "from_exp_coords", lambda x: rk.Transform.from_exp_coords(x).as_matrix(), V(6))
ex(_p + "as_exp_coords", lambda x: T_(x).as_exp_coords(), V(6))
ex(
    _p + "from_dual_quat",
    lambda x: rk.Transform.from_dual_quat(T_(x).as_dual_quat()).as_matrix(),
    V(6),
)
ex(_p + "as_dual_quat", lambda x: T_(x).as_dual_quat(), V(6))
ex(_p + "from_pq", lambda x: rk.Transform.from_pq(T_(x).as_pq()).as_matrix(), V(6))
ex(_p + "as_pq", lambda x: T_(x).as_pq(), V(6))
ex(_p + "rotation", lambda x: T_(x).rotation.as_matrix(), V(6))
ex(_p + "translation", lambda x: T_(x).translation, V(6))
ex(_p + "distance_to", lambda x, y: T_(x).distance_to(T_(y)), V(6), V(6))
ex(
    _p + "from_screw",
    lambda p, d, h, a: rk.Transform.from_screw(p, d, h, a).as_matrix(),
    V(3),
    V(3, lo=0.3),
    S(),
    S(),
)
ex(_p + "as_screw", lambda x: T_(x).as_screw(), V(6))

# the other classes' own members
_p = "rk.Rotation2D."
ex(_p + "from_angle", lambda a: rk.Rotation2D.from_angle(a).as_matrix(), S())
ex(
    _p + "from_complex",
    lambda z: rk.Rotation2D.from_complex(z[..., 0] + 1j * z[..., 1]).as_matrix(),
    V(2, lo=0.3),
)
ex(
    _p + "as_complex",
    lambda a: rk.Rotation2D.exp(a).as_complex(),
    V(1),
    na=no_grad("complex result"),
)
ex(_p + "angle", lambda a: rk.Rotation2D.exp(a).angle, V(1))
ex("rk.Transform2D.rotation", lambda x: rk.Transform2D.exp(x).rotation.as_matrix(), V(3))
ex("rk.Transform2D.translation", lambda x: rk.Transform2D.exp(x).translation, V(3))
_p = "rk.Similarity."
ex(_p + "rotation", lambda x: rk.Similarity.exp(x).rotation.as_matrix(), V(7))
ex(_p + "translation", lambda x: rk.Similarity.exp(x).translation, V(7))
ex(_p + "scale", lambda x: rk.Similarity.exp(x).scale, V(7))
ex(_p + "as_affine", lambda x: rk.Similarity.exp(x).as_affine().as_matrix(), V(7))
ex(_p + "as_projective", lambda x: rk.Similarity.exp(x).as_projective().as_matrix(), V(7))
ex(
    _p + "from_transform",
    lambda x: rk.Similarity.from_transform(T_(x)).as_matrix(),
    V(6),
)
_p = "rk.ExtendedPose."
_X = rk.ExtendedPose.exp
ex(_p + "rotation", lambda x: _X(x).rotation.as_matrix(), V(9))
ex(_p + "velocity", lambda x: _X(x).velocity, V(9))
ex(_p + "position", lambda x: _X(x).position, V(9))
ex(_p + "pose", lambda x: _X(x).pose.as_matrix(), V(9))
_A = KINDS["Affine"].make
ex("rk.Affine.matrix", lambda m: _A(m).matrix, V(3, 4))
ex("rk.Affine.translation", lambda m: _A(m).translation, V(3, 4))
ex("rk.Affine.as_projective", lambda m: _A(m).as_projective().as_matrix(), V(3, 4))
ex(
    "rk.Affine.from_similarity",
    lambda x: rk.Affine.from_similarity(rk.Similarity.exp(x)).as_matrix(),
    V(7),
)
_P = KINDS["Projective"].make
ex("rk.Projective.as_projective", lambda m: _P(m).as_projective().as_matrix(), V(4, 4))
ex(
    "rk.Projective.apply_homogeneous",
    lambda m, x: _P(m).apply_homogeneous(x),
    V(4, 4),
    V(3),
)
ex(
    "rk.Projective.from_affine",
    lambda m: rk.Projective.from_affine(_A(m)).as_matrix(),
    V(3, 4),
)

# Quaternion (the general algebra)
Qn = rk.Quaternion
_p = "rk.Quaternion."
ex(_p + "__init__", lambda q: Qn(q).norm(), V(4))
for _m in ("conjugate", "inv", "exp", "log"):
    ex(_p + _m, lambda q, m=_m: getattr(Qn(q), m)()._data, V(4, lo=0.3))
for _m in ("norm", "left_matrix", "right_matrix"):
    ex(_p + _m, lambda q, m=_m: getattr(Qn(q), m)(), V(4, lo=0.3))
for _m in ("w", "x", "y", "z", "scalar", "vector"):
    ex(_p + _m, lambda q, m=_m: getattr(Qn(q), m), V(4))
for _m in ("__add__", "__sub__", "__mul__"):
    ex(
        _p + _m,
        lambda a, b, m=_m: getattr(Qn(a), m)(Qn(b))._data,
        V(4, lo=0.3),
        V(4, lo=0.3),
    )
ex(_p + "__rmul__", lambda s, b: (s * Qn(b))._data, S(), V(4))
ex(_p + "__truediv__", lambda a, s: (Qn(a) / s)._data, V(4), S())
for _m in ("__matmul__", "__rmatmul__"):
    na_all(_p + _m, UNDEFINED)
ex(_p + "__neg__", lambda q: (-Qn(q))._data, V(4))
ex(_p + "__pos__", lambda q: (+Qn(q))._data, V(4))
ex(_p + "rotate", lambda q, v: Qn(q).rotate(v), Q(), V(3))
ex(_p + "from_parts", lambda s, v: Qn.from_parts(s, v)._data, S(), V(3))
ex(_p + "from_rotation", lambda q: Qn.from_rotation(R_(q))._data, Q())
ex(_p + "to_rotation", lambda q: Qn(q).to_rotation().as_matrix(), Q())
ex(_p + "approx_equal", lambda a, b: Qn(a).approx_equal(Qn(b)), V(4), V(4), na=BOOL)
ex(_p + "__getitem__", lambda q: Qn(q)[1]._data, V(3, 4), series=True)
ex(_p + "reshape", lambda q: Qn(q).reshape(3, 1)._data, V(3, 4), series=True)
ex(
    _p + "concatenate",
    lambda a, b: Qn.concatenate([Qn(a), Qn(b)])._data,
    V(2, 4),
    V(3, 4),
    series=True,
)
for _m in ("shape", "dtype", "single", "__len__", "__iter__"):
    na_all(_p + _m, META)


# -- interpolation and splines ---------------------------------------------------------
def _slerp(t, q, s):
    return rk.Slerp(t, R_(q))(s).as_quat()


ex(
    "rk.Slerp.__init__",
    lambda q: rk.Slerp(np.arange(4.0), R_(q))(1.5).as_quat(),
    Q(4),
    series=True,
)
ex(
    "rk.Slerp.__call__",
    lambda s, q: rk.Slerp(np.arange(4.0), R_(q))(s).as_quat(),
    V(3, lo=0.1, hi=2.9),
    Q(4),
    batch=0,
    diff=0,
)
_KNOTS = np.array([0.0, 0.7, 1.9, 3.0, 4.2])
ex(
    "rk.RotationSpline.__init__",
    lambda q: rk.RotationSpline(_KNOTS, R_(q))(1.0).as_quat(),
    Q(5),
    series=True,
)
ex(
    "rk.RotationSpline.__call__",
    lambda s, q: rk.RotationSpline(_KNOTS, R_(q))(s, 1, frame="body"),
    V(3, lo=0.1, hi=4.1),
    Q(5),
)
for _c, _mk, _g in (
    ("BSplineSO3", lambda q: rk.BSplineSO3(R_(q)), Q(6)),
    ("BSplineSE3", lambda x: rk.BSplineSE3(T_(x)), V(6, 6)),
):
    ex(f"rk.{_c}.__init__", lambda x, mk=_mk: mk(x)(1.2).as_matrix(), _g, series=True)
    ex(
        f"rk.{_c}.__call__",
        lambda s, x, mk=_mk: mk(x)(s, 1, frame="body"),
        V(3, lo=0.1, hi=2.9),
        _g,
    )


# -- kinematics ------------------------------------------------------------------------
def _Rdot(w, W):
    R = so3.exp(w)
    return R, R @ so3.hat(W)


_k = "rk.kinematics."
ex(
    _k + "angular_velocity",
    lambda w, W: kin.angular_velocity(*_Rdot(w, W), frame="body"),
    V(3),
    V(3),
)
ex(
    _k + "rotation_derivative",
    lambda w, W: kin.rotation_derivative(so3.exp(w), W, frame="world"),
    V(3),
    V(3),
)
ex(
    _k + "angular_acceleration",
    lambda w, W, A: kin.angular_acceleration(
        *_Rdot(w, W), so3.exp(w) @ (so3.hat(A) + so3.hat(W) @ so3.hat(W)), frame="body"
    ),
    V(3),
    V(3),
    V(3),
)
ex(
    _k + "rotation_second_derivative",
    lambda w, W, A: kin.rotation_second_derivative(so3.exp(w), W, A, frame="body"),
    V(3),
    V(3),
    V(3),
)
ex(
    _k + "quaternion_derivative",
    lambda q, W: kin.quaternion_derivative(q, W, frame="body"),
    Q(),
    V(3),
)
ex(
    _k + "quaternion_second_derivative",
    lambda q, W, A: kin.quaternion_second_derivative(q, W, A, frame="world"),
    Q(),
    V(3),
    V(3),
)
ex(
    _k + "angular_velocity_from_quaternion_derivative",
    lambda q, d: kin.angular_velocity_from_quaternion_derivative(q, d, frame="body"),
    Q(),
    V(4),
)
_E = V(3, lo=-0.6, hi=0.6)
ex(_k + "euler_rate_matrix", lambda a: kin.euler_rate_matrix("ZYX", a, frame="body"), _E)
ex(
    _k + "euler_rate_matrix_inverse",
    lambda a: kin.euler_rate_matrix_inverse("ZYX", a, frame="body"),
    _E,
)
ex(
    _k + "euler_rate_matrix_derivative",
    lambda a, r: kin.euler_rate_matrix_derivative("ZYX", a, r, frame="world"),
    _E,
    V(3),
)
ex(
    _k + "angular_velocity_from_euler_rates",
    lambda a, r: kin.angular_velocity_from_euler_rates("xyz", a, r, frame="body"),
    _E,
    V(3),
)
ex(_k + "euler_rates", lambda a, w: kin.euler_rates("ZYX", a, w, frame="body"), _E, V(3))
ex(
    _k + "angular_acceleration_from_euler_rates",
    lambda a, r, d: kin.angular_acceleration_from_euler_rates(
        "ZYX", a, r, d, frame="world"
    ),
    _E,
    V(3),
    V(3),
)
ex(
    _k + "euler_accelerations",
    lambda a, r, al: kin.euler_accelerations("ZYX", a, r, al, frame="body"),
    _E,
    V(3),
    V(3),
)
ex(
    _k + "integrate_angular_velocity",
    lambda w, W: kin.integrate_angular_velocity(so3.exp(w), W, 0.1, frame="body"),
    V(3),
    V(5, 3),
)
ex(
    _k + "integrate_angular_velocity[rk4]",
    lambda w, W: kin.integrate_angular_velocity(
        so3.exp(w), W, 0.1, frame="world", method="rk4"
    ),
    V(3),
    V(5, 3),
)
ex(
    _k + "integrate_twist",
    lambda x, X: kin.integrate_twist(se3.exp(x), X, 0.1, frame="body"),
    V(6),
    V(5, 6),
)
ex(
    _k + "integrate_twist[midpoint]",
    lambda x, X: kin.integrate_twist(se3.exp(x), X, 0.1, frame="world", method="midpoint"),
    V(6),
    V(5, 6),
)


def _Tdot(x, X):
    T = se3.exp(x)
    return T, T @ se3.hat(X)


ex(
    _k + "twist_from_derivative",
    lambda x, X: kin.twist_from_derivative(*_Tdot(x, X), frame="body"),
    V(6),
    V(6),
)
ex(
    _k + "transform_derivative",
    lambda x, X: kin.transform_derivative(se3.exp(x), X, frame="world"),
    V(6),
    V(6),
)
ex(
    _k + "transform_second_derivative",
    lambda x, X, D: kin.transform_second_derivative(se3.exp(x), X, D, frame="body"),
    V(6),
    V(6),
    V(6),
)
ex(
    _k + "spatial_acceleration_matrix",
    lambda X, D: kin.spatial_acceleration_matrix(X, D, frame="body"),
    V(6),
    V(6),
)
ex(_k + "twist_to_world", lambda x, X: kin.twist_to_world(se3.exp(x), X), V(6), V(6))
ex(_k + "twist_to_body", lambda x, X: kin.twist_to_body(se3.exp(x), X), V(6), V(6))
ex(_k + "point_velocity", kin.point_velocity, V(3), V(3), V(3))
ex(_k + "point_acceleration", kin.point_acceleration, V(3), V(3), V(3), V(3))
ex(_k + "screw_from_twist", kin.screw_from_twist, V(6))
ex(_k + "twist_from_screw", kin.twist_from_screw, V(3), V(3, lo=0.3), S(), S())
ex(
    _k + "angular_velocity_from_samples",
    lambda W, t: kin.angular_velocity_from_samples(so3.exp(W), t, frame="body"),
    V(5, 3),
    TIMES(5),
    series=True,
)
ex(
    _k + "twist_from_samples",
    lambda X, t: kin.twist_from_samples(se3.exp(X), t, frame="world"),
    V(5, 6),
    TIMES(5),
    series=True,
)
_k = "rk.kinematics.planar."
ex(
    _k + "angular_velocity",
    lambda a, w: planar.angular_velocity(so2.exp(a), so2.exp(a) @ so2.hat(w), frame="body"),
    V(1),
    V(1),
)
ex(
    _k + "rotation_derivative",
    lambda a, w: planar.rotation_derivative(so2.exp(a), w, frame="world"),
    V(1),
    V(1),
)
ex(
    _k + "twist_from_derivative",
    lambda x, X: planar.twist_from_derivative(
        se2.exp(x), se2.exp(x) @ se2.hat(X), frame="body"
    ),
    V(3),
    V(3),
)
ex(
    _k + "transform_derivative",
    lambda x, X: planar.transform_derivative(se2.exp(x), X, frame="world"),
    V(3),
    V(3),
)
ex(_k + "twist_to_world", lambda x, X: planar.twist_to_world(se2.exp(x), X), V(3), V(3))
ex(_k + "twist_to_body", lambda x, X: planar.twist_to_body(se2.exp(x), X), V(3), V(3))
ex(_k + "point_velocity", planar.point_velocity, V(1), V(2), V(2))
ex(_k + "point_acceleration", planar.point_acceleration, V(1), V(1), V(2), V(2))
ex(
    _k + "integrate_angular_velocity",
    lambda a, w: planar.integrate_angular_velocity(so2.exp(a), w, 0.1, frame="body"),
    V(1),
    V(5, 1),
)
ex(
    _k + "integrate_twist",
    lambda x, X: planar.integrate_twist(se2.exp(x), X, 0.1, frame="world"),
    V(3),
    V(5, 3),
)
ex(
    _k + "angular_velocity_from_samples",
    lambda a, t: planar.angular_velocity_from_samples(so2.exp(a), t, frame="body"),
    V(5, 1),
    TIMES(5),
    series=True,
)
ex(
    _k + "twist_from_samples",
    lambda X, t: planar.twist_from_samples(se2.exp(X), t, frame="body"),
    V(5, 3),
    TIMES(5),
    series=True,
)

# -- Jacobians -------------------------------------------------------------------------
_j = "rk.jacobians."
ex(_j + "compose", lambda a, b: jac.compose(R_(a), R_(b))[1:], Q(), Q())
ex(_j + "between", lambda a, b: jac.between(R_(a), R_(b))[1:], Q(), Q())
ex(_j + "minus", lambda a, b: jac.minus(R_(a), R_(b)), Q(), Q())
ex(_j + "inv", lambda a: jac.inv(R_(a))[1:], Q())
ex(_j + "log", lambda a: jac.log(R_(a)), Q())
ex(_j + "apply", lambda a, v: jac.apply(R_(a), v), Q(), V(3))
ex(_j + "exp", lambda w: jac.exp(rk.Rotation, w)[1:], V(3))
ex(_j + "plus", lambda a, w: jac.plus(R_(a), w)[1:], Q(), V(3))

# -- inertial --------------------------------------------------------------------------
ine = rk.inertial
_i = "rk.inertial."
_IMU = (V(5, 3), V(5, 3, lo=-10.0, hi=10.0))
ex(
    _i + "integrate",
    lambda x, g, a: ine.integrate(_X(x), g, a, 0.01).as_matrix(),
    V(9),
    *_IMU,
)
ex(_i + "preintegrate", lambda g, a: ine.preintegrate(g, a, 0.01), *_IMU)


def _pim(g, a):
    return ine.preintegrate(g, a, 0.01, noise=ine.ImuNoise(1e-3, 1e-2, 1e-4, 1e-3))


_p = _i + "Preintegrated."
ex(_p + "__init__", lambda g, a: _pim(g, a).covariance, *_IMU)
ex(
    _p + "corrected",
    lambda g, a: _pim(g, a).corrected(0.01 + 0 * g[..., 0, :], 0.1 + 0 * a[..., 0, :]),
    *_IMU,
)
ex(_p + "predict", lambda g, a, x: _pim(g, a).predict(_X(x)).as_matrix(), *_IMU, V(9))
ex(_p + "residual", lambda g, a, x, y: _pim(g, a).residual(_X(x), _X(y)), *_IMU, V(9), V(9))
for _m in (
    "delta_R",
    "delta_v",
    "delta_p",
    "delta_t",
    "jacobian_gyro_bias",
    "jacobian_accel_bias",
):
    ex(_p + _m, lambda g, a, m=_m: getattr(_pim(g, a), m), *_IMU)
ex(_p + "__getitem__", lambda g, a: _pim(g, a)[1].covariance, V(3, 5, 3), V(3, 5, 3))
na_all(_p + "shape", META)
na_all(_i + "ImuNoise.__init__", "a record of four noise densities (floats)")
na_all(_i + "ImuLog.__init__", RECORD)
na_all(_i + "to_gtsam", "builds a GTSAM object (C++), not an array")
na_all(_i + "from_gtsam", "reads a GTSAM object (C++), not an array")
ex(
    _i + "split_windows",
    lambda g, a: ine.split_windows(np.arange(5) * 0.1, g, a, np.array([0.0, 0.25])),
    *_IMU,
    series=True,
)
_CTRL = V(6, 6, lo=-0.5, hi=0.5)
_TQ = np.array([1.1, 1.7, 2.3])
ex(
    _i + "imu_from_trajectory",
    lambda x: ine.imu_from_trajectory(rk.BSplineSE3(T_(x)), _TQ),
    _CTRL,
    series=True,
)
ex(
    _i + "states_from_trajectory",
    lambda x: ine.states_from_trajectory(rk.BSplineSE3(T_(x)), _TQ).as_matrix(),
    _CTRL,
    series=True,
)
na_all(_i + "simulate_imu", RANDOM + " (white noise and random walks)")

# -- trajectories, their metrics and files ---------------------------------------------
_STAMPS = np.arange(6) * 0.5
_TX = V(6, 6, lo=-0.5, hi=0.5)


def _traj(x, stamps=_STAMPS):
    return rk.Trajectory(stamps, T_(x))


_t = "rk.Trajectory."
ex(_t + "__init__", lambda x: _traj(x).poses.as_matrix(), _TX, series=True)
ex(_t + "poses", lambda x: _traj(x).poses.as_matrix(), _TX, series=True)
ex(
    _t + "stamps",
    lambda t: rk.Trajectory(t, rk.Transform.identity(6)).stamps,
    TIMES(6),
    series=True,
)
ex(_t + "positions", lambda x: _traj(x).positions, _TX, series=True)
ex(_t + "path_length", lambda x: _traj(x).path_length, _TX, series=True)
ex(
    _t + "duration",
    lambda t: rk.Trajectory(t, rk.Transform.identity(6)).duration,
    TIMES(6),
    series=True,
)
ex(
    _t + "at",
    lambda x: _traj(x).at(np.array([0.2, 1.3])).poses.as_matrix(),
    _TX,
    series=True,
)
ex(
    _t + "transform",
    lambda x, y: _traj(x).transform(T_(y)).poses.as_matrix(),
    _TX,
    V(6),
    series=True,
)
ex(_t + "velocities", lambda x: _traj(x).velocities("body"), _TX, series=True)
ex(_t + "__getitem__", lambda x: _traj(x)[1:3].poses.as_matrix(), _TX, series=True)
for _m in ("shape", "__len__", "__iter__"):
    na_all(_t + _m, META)

_t = "rk.trajectory."
ex(
    _t + "align",
    # (aligned_est, ref_S_est): the aligned poses and the fitted transform
    lambda x, y: [
        r.as_matrix() if isinstance(r, rk.Transform) else r.poses.as_matrix()
        for r in rk.trajectory.align(_traj(x), _traj(y))
    ],
    _TX,
    _TX,
    series=True,
)
ex(
    _t + "ape",
    lambda x, y: rk.trajectory.ape(_traj(x), _traj(y)).errors,
    _TX,
    _TX,
    series=True,
)
ex(
    _t + "rpe",
    lambda x, y: rk.trajectory.rpe(_traj(x), _traj(y)).errors,
    _TX,
    _TX,
    series=True,
)
ex(
    _t + "associate",
    lambda x, y: [
        t.poses.as_matrix()
        for t in rk.trajectory.associate(_traj(x), _traj(y, _STAMPS + 0.001))
    ],
    _TX,
    _TX,
    series=True,
)
ex(
    _t + "pair_indices",
    lambda x: rk.trajectory.pair_indices(T_(x), 0.5, unit="meters"),
    _TX,
    series=True,
    na={
        **INT,
        "jit": SHAPE_BY_VALUE,
        "vmap": SHAPE_BY_VALUE,
        "torch_vmap": SHAPE_BY_VALUE,
        "dask": "pairs in metres come from the distances travelled (a walk on the "
        "host): their number, the output's shape, is known only once computed",
    },
)
ex(
    _t + "statistics",
    lambda e: rk.trajectory.statistics(e),
    V(6, lo=0.0, hi=1.0),
    series=True,
)
na_all(
    _t + "kitti_errors",
    "the KITTI protocol needs 100-800 m of trajectory (a sweep-size input); "
    "its segment search is a NumPy host loop",
)
for _m in ("plot", "plot_error_colored", "plot_errors"):
    na_all(_t + _m, PLOT)
na_all(_t + "save_report", FILES)
na_all(_t + "MetricResult.__init__", RECORD)
na_all(_t + "KittiResult.__init__", RECORD)
for _m in ("read_trajectory", "write_trajectory", "read_tf", "read_poses"):
    na_all("rk.io." + _m, FILES)

# -- frame graphs and uncertain poses --------------------------------------------------
_f = "rk.FrameGraph."


def _graph(x, y):
    g = rk.FrameGraph()
    g.add("world", "base", T_(x))
    g.add("base", "camera", T_(y))
    return g


ex(
    _f + "__init__",
    lambda x, y: _graph(x, y).get("world", "camera").as_matrix(),
    V(6),
    V(6),
)
ex(_f + "add", lambda x, y: _graph(x, y).get("camera", "world").as_matrix(), V(6), V(6))
ex(_f + "get", lambda x, y: _graph(x, y).get("base", "camera").as_matrix(), V(6), V(6))


def _updated(x, y):
    g = _graph(x, x)
    g.update_static("base", "camera", T_(y))
    return g.get("world", "camera").as_matrix()


ex(_f + "update_static", _updated, V(6), V(6))


def _velocity(X):
    g = rk.FrameGraph()
    g.add("world", "body", T_(X), stamps=np.arange(4) * 0.5)
    return g.velocity("world", "body", 0.7, frame="body")


ex(_f + "velocity", _velocity, V(4, 6, lo=-0.5, hi=0.5), series=True)
for _m in ("remove", "frames", "edges", "parent", "children", "path", "can_transform"):
    na_all(_f + _m, GRAPH)
for _m in ("to_dot", "to_json", "from_json"):
    na_all(_f + _m, GRAPH + " (text)")

_u = "rk.UncertainTransform."
_COV = np.diag([0.01, 0.02, 0.03, 0.001, 0.002, 0.003])


def _ut(x, c):
    return rk.UncertainTransform(T_(x), (1.0 + c) * _COV)


ex(_u + "__init__", lambda x, c: _ut(x, c).cov, V(6), S())
ex(_u + "mean", lambda x, c: _ut(x, c).mean.as_matrix(), V(6), S())
ex(_u + "cov", lambda x, c: _ut(x, c).cov, V(6), S())
ex(_u + "inv", lambda x, c: _ut(x, c).inv().cov, V(6), S())
ex(_u + "to_side", lambda x, c: _ut(x, c).to_side("left").cov, V(6), S())
ex(_u + "compose", lambda x, y, c: _ut(x, c).compose(_ut(y, c)).cov, V(6), V(6), S())
ex(_u + "__matmul__", lambda x, y, c: (_ut(x, c) @ _ut(y, c)).cov, V(6), V(6), S())
ex(_u + "between", lambda x, y, c: _ut(x, c).between(_ut(y, c)).cov, V(6), V(6), S())
ex(_u + "transform_point", lambda x, c, p: _ut(x, c).transform_point(p), V(6), S(), V(3))
for _m in ("side", "shape"):
    na_all(_u + _m, META)

NOT_APPLICABLE_MODULES["rk.symbolic."] = (
    "SymPy expressions of the kernels: symbols in, symbols out; no array transform applies"
)


# -- the public API, enumerated --------------------------------------------------------
OPERATORS = {
    "__init__",
    "__call__",
    "__matmul__",
    "__rmatmul__",
    "__pow__",
    "__mul__",
    "__rmul__",
    "__add__",
    "__sub__",
    "__neg__",
    "__pos__",
    "__truediv__",
    "__getitem__",
    "__len__",
    "__iter__",
}


def _ours(obj) -> bool:
    return getattr(obj, "__module__", "").split(".")[0] == "rigidkit"


def _class_members(prefix, cls):
    out = []
    for n in dir(cls):
        if n.startswith("_") and n not in OPERATORS:
            continue
        owner = next((k for k in cls.__mro__ if n in vars(k)), None)
        if owner is None or not _ours(owner):
            continue
        attr = inspect.getattr_static(cls, n)
        if isinstance(attr, (classmethod, staticmethod)):
            attr = attr.__func__
        if inspect.isclass(attr):
            continue  # a class attribute naming a class (a spline's ``kind``)
        if isinstance(attr, (property, functools.cached_property)) or callable(attr):
            out.append(f"{prefix}.{n}")
    return out


def public_callables() -> list[str]:
    """Every public callable of rigidkit, spelled ``rk.<module>.<name>`` /
    ``rk.<Class>.<member>``; a function or class reached twice is listed once."""
    seen: set[int] = set()
    names: list[str] = []

    def visit(prefix, obj):
        if id(obj) in seen:
            return
        if inspect.isclass(obj):
            if issubclass(obj, BaseException):
                return
            seen.add(id(obj))
            names.extend(_class_members(prefix, obj))
        elif isinstance(obj, types.ModuleType):
            seen.add(id(obj))
            for n in obj.__all__:
                visit(f"{prefix}.{n}", getattr(obj, n))
        elif callable(obj) and _ours(obj):
            seen.add(id(obj))
            names.append(prefix)

    for n in rk.__all__:
        visit(f"rk.{n}", getattr(rk, n))
    return names


def example_for(name: str) -> Example | None:
    """The example of a public callable; ``None`` where the name has none."""
    if name in EXAMPLES:
        return EXAMPLES[name]
    for prefix, reason in NOT_APPLICABLE_MODULES.items():
        if name.startswith(prefix):
            return Example(name, None, (), None, None, {t: reason for t in TRANSFORMS})
    return None
