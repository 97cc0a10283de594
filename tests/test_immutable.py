"""Objects are immutable values: nothing a caller does to a returned array changes them.

Every public method and property of every object class (``rigidkit.objects``) is
called, every array it returns (also inside tuples, and the arrays of the objects it
returns, one level down: ``T.rotation.as_quat()``) is written to in place, and the
object's stored array must equal a copy taken before. A NumPy result may be a
read-only view instead (writing then raises ``ValueError``, and the test checks that
it does). The same holds on torch, where no tensor is read-only, so each is a copy.
A constructor must not keep the caller's array either (a write into the input after
construction changes nothing).

The reference is the snapshot itself; the test enumerates the methods with
``dir()``, so a method added later is covered (one that needs arguments must be
listed in ``ARGS``, or the test fails and says so).
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import rigidkit as rk
from conftest import GROUP_KINDS
from rigidkit.objects._batch import BatchedArray

CLASSES = [*GROUP_KINDS, rk.Quaternion]


def sample(cls, shape):
    """A valid instance of ``cls`` with batch ``shape`` (NumPy storage)."""
    if cls is rk.Quaternion:
        return rk.Quaternion(np.random.default_rng(1).standard_normal(shape + (4,)))
    return cls.random(shape, rng=7)


def args_for(obj, name):
    """Positional arguments of ``obj.name`` (a method that needs some), or None."""
    pdim = getattr(obj, "point_dim", 3)
    table = {
        "apply": (np.full(pdim, 0.5),),
        "apply_homogeneous": (np.full(3, 0.5),),
        "rotate": (np.full(3, 0.5),),
        "as_euler": ("ZYX",),
        "plus": (np.full(getattr(obj, "dof", 3), 0.1),),
        "minus": (obj,),
        "approx_equal": (obj,),
        "distance_to": (obj,),
        "angle_to": (obj,),
        "chordal_distance": (obj,),
        "swing_twist": (np.array([0.0, 0.0, 1.0]),),
        "as_davenport": (np.eye(3)[[2, 0, 2]], "e"),
        "compose": (obj,),
        "reshape": (obj.shape,),
    }
    return table.get(name)


def public_members(cls):
    """``(name, kind)`` for each public method (bound, not a constructor) and property."""
    out = []
    for name, member in inspect.getmembers(cls):
        if name.startswith("_"):
            continue
        raw = inspect.getattr_static(cls, name)
        if isinstance(raw, property):
            out.append((name, "property"))
        elif isinstance(raw, (classmethod, staticmethod)):
            continue  # constructors: test_constructors_do_not_keep_the_input
        elif callable(member):
            out.append((name, "method"))
    return out


def call(obj, name, kind):
    if kind == "property":
        return getattr(obj, name)
    method = getattr(obj, name)
    args = args_for(obj, name)
    if args is not None:
        return method(*args)
    params = [
        p
        for p in inspect.signature(method).parameters.values()
        if p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
    ]
    assert not params, f"{type(obj).__name__}.{name} needs arguments: add them to ARGS"
    return method()


def leaves(result, depth=0):
    """Arrays in ``result``: itself, inside tuples/lists/dicts, and in the objects it
    returns (through their own public members, one level down)."""
    if isinstance(result, (tuple, list)):
        for r in result:
            yield from leaves(r, depth)
    elif isinstance(result, dict):
        for r in result.values():
            yield from leaves(r, depth)
    elif isinstance(result, BatchedArray):
        if depth == 0:
            for name, kind in public_members(type(result)):
                yield from leaves(call(result, name, kind), depth + 1)
    elif hasattr(result, "shape") and hasattr(result, "dtype"):
        yield result


def scribble_numpy(a):
    """Write into ``a`` in place; a read-only array must refuse."""
    if not isinstance(a, np.ndarray):
        return  # NumPy scalars are immutable
    if not a.flags.writeable:
        with pytest.raises(ValueError):
            a[...] = 0
        return
    if a.dtype == bool:
        a[...] = ~a
    else:
        a[...] = 12345.0


def scribble_torch(torch, a):
    with torch.no_grad():
        if a.dtype == torch.bool:
            a.logical_not_()
        else:
            a.add_(12345.0)


def check_unchanged(obj, before, name):
    np.testing.assert_array_equal(
        np.asarray(obj._data), before, err_msg=f"{type(obj).__name__}.{name} aliases"
    )


@pytest.mark.parametrize("cls", CLASSES, ids=lambda c: c.__name__)
@pytest.mark.parametrize("shape", [(), (3,)], ids=["single", "batch"])
def test_returned_arrays_do_not_alias_the_object(cls, shape):
    obj = sample(cls, shape)
    before = np.array(obj._data, copy=True)
    names = public_members(cls)
    assert names, cls
    for name, kind in names:
        for leaf in leaves(call(obj, name, kind)):
            scribble_numpy(leaf)
        check_unchanged(obj, before, name)


def test_the_reported_cases():
    """The three cases of the issue, spelled as a user would."""
    A_R_B = rk.Rotation.random((), rng=3)
    q0 = A_R_B.as_quat().copy()
    q = A_R_B.as_quat()
    with pytest.raises(ValueError):
        q *= 2
    np.testing.assert_array_equal(A_R_B.as_quat(), q0)
    assert np.isclose(np.linalg.det(A_R_B.as_matrix()), 1.0)

    A_T_B = rk.Transform.random((), rng=4)
    t0 = A_T_B.translation.copy()
    with pytest.raises(ValueError):
        A_T_B.translation[0] = 99.0
    with pytest.raises(ValueError):
        A_T_B.rotation.as_quat()[:] = [0.0, 1.0, 0.0, 0.0]
    np.testing.assert_array_equal(A_T_B.translation, t0)
    # The copy is the caller's to edit.
    t = A_T_B.translation.copy()
    t[0] = 99.0
    np.testing.assert_array_equal(A_T_B.translation, t0)


@pytest.mark.parametrize("cls", CLASSES, ids=lambda c: c.__name__)
def test_returned_tensors_do_not_alias_the_object(cls, torch):
    base = sample(cls, (3,))
    obj = cls._wrap(torch.as_tensor(np.array(base._data)))
    before = np.array(base._data, copy=True)
    for name, kind in public_members(cls):
        for leaf in leaves(call(obj, name, kind)):
            if isinstance(leaf, torch.Tensor):
                scribble_torch(torch, leaf)
            else:
                scribble_numpy(leaf)
        np.testing.assert_array_equal(
            obj._data.numpy(), before, err_msg=f"{cls.__name__}.{name} aliases"
        )


def constructors():
    """``(name, build)``: each public constructor from a fresh caller-owned array."""
    rng = np.random.default_rng(5)
    q = rng.standard_normal((3, 4))
    R = rk.Rotation.from_quat(q)
    M4 = rk.Transform.random(3, rng=1).as_matrix()
    yield "Rotation.from_quat", lambda a: rk.Rotation.from_quat(a), q
    yield "Rotation.from_matrix", lambda a: rk.Rotation.from_matrix(a), R.as_matrix()
    yield "Rotation.from_rotvec", lambda a: rk.Rotation.from_rotvec(a), R.as_rotvec()
    yield "Rotation.from_mrp", lambda a: rk.Rotation.from_mrp(a), R.as_mrp()
    yield (
        "Rotation.from_euler",
        lambda a: rk.Rotation.from_euler("ZYX", a),
        R.as_euler("ZYX"),
    )
    yield "Transform(translation=)", lambda a: rk.Transform(translation=a), q[:, :3]
    yield "Transform.from_matrix", lambda a: rk.Transform.from_matrix(a), M4
    yield "Transform.exp", lambda a: rk.Transform.exp(a), rng.standard_normal((3, 6))
    T = rk.Transform.from_matrix(M4)
    yield (
        "Transform.from_dual_quat",
        lambda a: rk.Transform.from_dual_quat(a),
        T.as_dual_quat(),
    )
    yield "Transform.from_exp_coords", lambda a: rk.Transform.from_exp_coords(a), T.log()
    yield "Transform.from_pq", lambda a: rk.Transform.from_pq(a), T.as_pq()
    yield "Rotation.from_6d", lambda a: rk.Rotation.from_6d(a), R.as_6d()
    yield (
        "Rotation.from_davenport(angles)",
        lambda a: rk.Rotation.from_davenport(np.eye(3)[[2, 1, 2]], "e", a),
        R.as_euler("zyz"),
    )
    yield "Rotation2D", lambda a: rk.Rotation2D(a), q[:, :2]
    yield "Transform2D", lambda a: rk.Transform2D(translation=a), q[:, :2]
    yield "Similarity", lambda a: rk.Similarity(translation=a), q[:, :3]
    yield "Similarity(scale=)", lambda a: rk.Similarity(scale=a), np.abs(q[:, 0]) + 1
    yield "Affine(matrix=)", lambda a: rk.Affine(matrix=a), M4[:, :3, :3]
    yield "Affine.from_matrix", lambda a: rk.Affine.from_matrix(a), M4
    yield "Projective", lambda a: rk.Projective(a), M4
    yield "Quaternion", lambda a: rk.Quaternion(a), q


@pytest.mark.parametrize("case", list(constructors()), ids=lambda c: c[0])
def test_constructors_do_not_keep_the_input(case):
    _, build, source = case
    source = np.array(source, copy=True)
    obj = build(source)
    before = np.array(obj._data, copy=True)
    source[...] = 0.5  # the caller reuses its buffer
    np.testing.assert_array_equal(np.asarray(obj._data), before)


def test_quaternion_array_protocol_is_read_only_or_a_copy():
    Q = rk.Quaternion([1.0, 2.0, 3.0, 4.0])
    a = np.asarray(Q)
    with pytest.raises(ValueError):
        a[0] = 0.0
    b = np.array(Q)  # copy=True
    b[0] = 0.0
    np.testing.assert_array_equal(np.asarray(Q), [1.0, 2.0, 3.0, 4.0])
