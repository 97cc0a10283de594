"""Dask arrays stay lazy: every batched op builds a graph and computes nothing.

Each kernel maps over the chunks (the compiled NumPy path per chunk); checks that
need values run per chunk at compute time and name the GLOBAL batch index. The
reference is the same op on the NumPy array. Computes are counted with a Dask
callback that sees every scheduler start.
"""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk
from rigidkit import conversions, se3, so3
from rigidkit.functional import alignment, davenport, distances, symmetry

N = 100
CHUNK = 30  # four chunks: 30, 30, 30, 10


@pytest.fixture
def inputs(rng):
    q = rng.standard_normal((N, 4))
    return {
        "q": q / np.linalg.norm(q, axis=-1, keepdims=True),
        "v": rng.standard_normal((N, 3)),
        "w": rng.uniform(-2.0, 2.0, (N, 3)),
        "xi": rng.uniform(-1.0, 1.0, (N, 6)),
    }


def _counting(dask_array):
    """A context that counts how often a Dask scheduler starts (i.e. computes)."""
    from dask.callbacks import Callback

    class Count(Callback):
        starts = 0

        def _start(self, dsk):
            Count.starts += 1

    return Count()


OPS = {
    "from_quat.as_quat": (lambda q: rk.Rotation.from_quat(q).as_quat(), "q"),
    "as_matrix": (lambda q: rk.Rotation.from_quat(q).as_matrix(), "q"),
    "compose": (
        lambda q: (rk.Rotation.from_quat(q) @ rk.Rotation.from_quat(q)).as_quat(),
        "q",
    ),
    "apply": (lambda q, v: rk.Rotation.from_quat(q) @ v, "q v"),
    "as_euler": (lambda q: rk.Rotation.from_quat(q).as_euler("ZYX"), "q"),
    "as_axis_angle": (lambda q: rk.Rotation.from_quat(q).as_axis_angle()[1], "q"),
    "from_matrix": (
        lambda q: rk.Rotation.from_matrix(rk.Rotation.from_quat(q).as_matrix()).as_quat(),
        "q",
    ),
    "so3.exp": (so3.exp, "w"),
    "so3.log": (lambda w: so3.log(so3.exp(w)), "w"),
    "se3.exp": (se3.exp, "xi"),
    "Transform.apply": (lambda xi, v: rk.Transform.exp(xi) @ v, "xi v"),
    "Transform.inv.log": (lambda xi: rk.Transform.exp(xi).inv().log(), "xi"),
}


@pytest.mark.parametrize("name", list(OPS))
def test_ops_build_graphs_and_compute_nothing(name, inputs, dask_array):
    import dask

    fn, names = OPS[name]
    args = [inputs[n] for n in names.split()]
    chunked = [dask_array.from_array(a, chunks=(CHUNK, a.shape[-1])) for a in args]
    counter = _counting(dask_array)
    with counter:
        out = fn(*chunked)
    assert type(out).__module__.startswith("dask"), type(out)
    assert counter.starts == 0, "building the graph computed something"
    assert out.numblocks[0] == 4  # still chunked along the batch
    with dask.config.set(scheduler="threads"):
        got = out.compute()
    np.testing.assert_allclose(got, fn(*args), rtol=0, atol=1e-12)


def _host_inputs(rng):
    """Inputs of the host-side algorithms: (array, chunks) by name; batch axes chunked."""
    q = rng.standard_normal((10, 6, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return {
        "a": (rng.standard_normal((12, 5, 3)), (4, 5, 3)),
        "b": (rng.standard_normal((12, 5, 3)), (3, 5, 3)),
        "q2d": (q, (4, 2, 4)),  # (time or batch, batch, 4)
        "w2d": (rng.uniform(0.1, 1.0, (10, 6)), (5, 3)),
        "xi": (rng.uniform(-1.0, 1.0, (12, 6)), (4, 6)),
        "euler": (rng.uniform(-3.0, 3.0, (10, 6, 3)), (10, 2, 3)),
        "angles": (rng.uniform(-1.0, 1.0, (12, 3)), (4, 3)),
        "six": (rng.standard_normal((12, 6)), (4, 6)),
    }


_TIMES = np.cumsum(np.linspace(0.5, 1.5, 10))
_QUERY = np.linspace(_TIMES[0], _TIMES[-1], 7)
_DAVENPORT_AXES = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.3]])


def _spline(q, order):
    spline = rk.RotationSpline(_TIMES, rk.Rotation.from_quat(q))
    return spline(_QUERY).as_quat() if order == 0 else spline(_QUERY, order, frame="body")


def _reduce(q):
    return symmetry.quat_reduce(q, symmetry.quat_group("C3"), symmetry.quat_group("O"))[0]


def _geodesic_mean(q, w):
    return rk.Rotation.from_quat(q).mean(w, method="geodesic", axis=1).as_quat()


def _jacobian(q):
    R = rk.Rotation.from_quat(q)
    return rk.jacobians.compose(R, R, side="left")[1]


R_ = rk.Rotation.from_quat

# name: (op, input names, axes of the result that stay chunked, atol). Results that
# iterate to a tolerance per chunk (Karcher, the spline's Newton solve) may stop a
# step apart from the whole batch's: they agree to rounding, not bit for bit.
HOST_OPS = {
    "align_vectors": (lambda a, b: rk.align_vectors(a, b)[0].as_quat(), "a b", (0,), 1e-12),
    "align_vectors.rssd": (lambda a, b: rk.align_vectors(a, b)[1], "a b", (0,), 1e-12),
    "align_points": (lambda a, b: rk.align_points(a, b).as_matrix(), "a b", (0,), 1e-12),
    "umeyama(scale)": (
        lambda a, b: alignment.umeyama(a, b, scale=True),
        "a b",
        (0,),
        1e-12,
    ),
    "Rotation.mean(axis=0)": (lambda q: R_(q).mean(axis=0).as_quat(), "q2d", (0,), 1e-12),
    "Rotation.mean(w, geodesic, axis=1)": (_geodesic_mean, "q2d w2d", (0,), 1e-12),
    "Rotation.mean()": (lambda q: R_(q).mean().as_quat(), "q2d", (), 1e-12),
    "Transform.mean(geodesic)": (
        lambda xi: rk.Transform.exp(xi).mean(method="geodesic").log(),
        "xi",
        (),
        1e-12,
    ),
    "quat_reduce(C3, O)": (_reduce, "q2d", (0, 1), 1e-12),
    "RotationSpline": (lambda q: _spline(q, 0), "q2d", (1,), 1e-12),
    "RotationSpline rate": (lambda q: _spline(q, 1), "q2d", (1,), 1e-12),
    "BSplineSO3": (
        lambda q: rk.BSplineSO3(R_(q))(np.linspace(0.0, 7.0, 9)).as_quat(),
        "q2d",
        (1,),
        1e-12,
    ),
    "Slerp": (lambda q: rk.Slerp(_TIMES, R_(q))(_QUERY).as_quat(), "q2d", (1,), 1e-12),
    "quat_continuous": (lambda q: rk.quat_continuous(q, axis=0), "q2d", (1,), 0.0),
    "unwrap_euler": (lambda e: rk.unwrap_euler(e, axis=0), "euler", (1,), 1e-12),
    "chordal_distance": (
        lambda q: distances.chordal_distance(q, q[::-1]),
        "q2d",
        (0, 1),
        1e-12,
    ),
    "as_6d": (lambda q: R_(q).as_6d(), "q2d", (0, 1), 1e-12),
    "from_6d": (lambda x: rk.Rotation.from_6d(x).as_quat(), "six", (0,), 1e-12),
    "from_davenport": (
        lambda a: davenport.quat_from_davenport(_DAVENPORT_AXES, "e", a),
        "angles",
        (0,),
        1e-12,
    ),
    "as_davenport": (
        lambda q: R_(q).as_davenport(_DAVENPORT_AXES, "i"),
        "q2d",
        (0, 1),
        1e-12,
    ),
    "jacobians.compose": (_jacobian, "q2d", (0, 1), 1e-12),
}


@pytest.mark.parametrize("name", list(HOST_OPS))
def test_host_algorithms_stay_lazy(name, rng, dask_array):
    """Solves, means, searches and sequence ops per chunk: no compute, NumPy's values."""
    fn, names, chunked, atol = HOST_OPS[name]
    given = _host_inputs(rng)
    args = [given[n][0] for n in names.split()]
    lazy = [
        dask_array.from_array(a, chunks=given[n][1]) for a, n in zip(args, names.split())
    ]
    counter = _counting(dask_array)
    with counter:
        out = fn(*lazy)
    assert type(out).__module__.startswith("dask"), type(out)
    assert counter.starts == 0, "building the graph computed something"
    assert all(out.numblocks[a] > 1 for a in chunked), out.numblocks
    got = out.compute(scheduler="threads")
    np.testing.assert_allclose(got, fn(*args), rtol=0, atol=atol)


def test_alignment_errors_at_compute_time_name_the_global_index(rng, dask_array):
    src = rng.standard_normal((12, 5, 3))
    src[7] = src[7, :1] * np.arange(1.0, 6.0)[:, None]  # collinear points
    dst = rng.standard_normal((12, 5, 3))
    with pytest.raises(rk.DegenerateInputError) as eager:
        rk.align_points(src, dst)
    T = rk.align_points(dask_array.from_array(src, chunks=(4, 5, 3)), dst)  # no error yet
    with pytest.raises(rk.DegenerateInputError, match="collinear") as lazy:
        T.as_matrix().compute(scheduler="threads")
    assert lazy.value.index == eager.value.index == (7,)
    assert "at batch index (7,)" in str(lazy.value)
    # An error of the reduced input names the caller's axes (the mean transposes).
    q = rk.Rotation.random(60, rng=rng).as_quat().reshape(6, 10, 4)
    w = np.ones((6, 10))
    w[4, 8] = -1.0
    mean = rk.Rotation.from_quat(dask_array.from_array(q, chunks=(3, 5, 4))).mean(w, axis=0)
    with pytest.raises(rk.DegenerateInputError, match="negative") as info:
        mean.as_quat().compute(scheduler="threads")
    assert info.value.index == (4, 8)


def test_two_batch_axes_and_broadcasting(inputs, dask_array):
    q = inputs["q"][:60].reshape(6, 10, 4)
    dq = dask_array.from_array(q, chunks=(2, 5, 4))
    v = inputs["v"][0]  # one vector for the whole batch (NumPy, broadcast)
    out = rk.Rotation.from_quat(dq) @ v
    assert out.shape == (6, 10, 3) and out.numblocks == (3, 2, 1)
    np.testing.assert_allclose(out.compute(), rk.Rotation.from_quat(q) @ v, atol=1e-12)


@pytest.mark.parametrize(
    "spoil, error, index",
    [
        (lambda a: a.__setitem__((77,), 0.0), rk.ZeroNormError, (77,)),
        (lambda a: a.__setitem__((31, 2), np.nan), rk.NonFiniteError, (31,)),
        (lambda a: a.__setitem__((95, 0), np.inf), rk.NonFiniteError, (95,)),
    ],
)
def test_errors_at_compute_time_name_the_global_index(
    spoil, error, index, inputs, dask_array
):
    q = inputs["q"].copy()
    spoil(q)
    # Eagerly the NumPy path raises at once; the graph raises only when computed.
    with pytest.raises(error) as eager:
        rk.Rotation.from_quat(q)
    R = rk.Rotation.from_quat(dask_array.from_array(q, chunks=(CHUNK, 4)))
    M = R.as_matrix()  # no error yet
    with pytest.raises(error) as lazy:
        M.compute(scheduler="threads")
    assert lazy.value.index == eager.value.index == index
    assert f"at batch index {index}" in str(lazy.value)


def test_not_a_rotation_names_the_global_index(inputs, dask_array):
    M = rk.Rotation.from_quat(inputs["q"]).as_matrix().copy()
    M[64] *= 1.1
    lazy = rk.Rotation.from_matrix(dask_array.from_array(M, chunks=(CHUNK, 3, 3)))
    with pytest.raises(rk.NotARotationError, match=r"batch index \(64,\).*scales by 1\.1"):
        lazy.as_quat().compute(scheduler="threads")
    # Two batch axes: the index is global on both.
    M2 = np.broadcast_to(np.eye(3), (4, 6, 3, 3)).copy()
    M2[3, 4, 0, 1] = 0.5
    lazy2 = so3.log(dask_array.from_array(M2, chunks=(2, 4, 3, 3)))
    with pytest.raises(rk.NotARotationError) as info:
        lazy2.compute(scheduler="threads")
    assert info.value.index == (3, 4)


def test_validation_switch_builds_no_checks(inputs, dask_array):
    q = inputs["q"].copy()
    q[5] = 0.0
    with rk.set_validation(False):
        out = conversions.quat_normalize(dask_array.from_array(q, chunks=(CHUNK, 4)))
    got = out.compute(scheduler="threads")  # no error: the zero stays unnormalised
    np.testing.assert_allclose(got[6:], q[6:], atol=1e-15)


@pytest.mark.needs("distributed")
def test_local_cluster_of_two_processes(inputs, dask_array):
    """Two worker processes: kernels and checks travel by name and pickle."""
    from distributed import Client, LocalCluster

    q = inputs["q"].copy()
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        dq = dask_array.from_array(q, chunks=(CHUNK, 4))
        R = rk.Rotation.from_quat(dq)
        euler, M = client.compute([R.as_euler("XYZ"), (R @ R).as_matrix()], sync=True)
        ref = rk.Rotation.from_quat(q)
        np.testing.assert_allclose(euler, ref.as_euler("XYZ"), atol=1e-12)
        np.testing.assert_allclose(M, (ref @ ref).as_matrix(), atol=1e-12)
        # A host-side solve per chunk and a mean travel too (pickled callables).
        a = q[:60, :3].reshape(12, 5, 3)
        b = rk.Rotation.from_quat(q[:12, None]).inv() @ a
        lazy_a = dask_array.from_array(a, chunks=(4, 5, 3))
        aligned, mean = client.compute(
            [rk.align_vectors(lazy_a, b)[0].as_quat(), R.mean(axis=0).as_quat()], sync=True
        )
        np.testing.assert_allclose(aligned, rk.align_vectors(a, b)[0].as_quat(), atol=1e-12)
        np.testing.assert_allclose(mean, ref.mean(axis=0).as_quat(), atol=1e-12)
        q[88] = np.nan
        bad = rk.Rotation.from_quat(dask_array.from_array(q, chunks=(CHUNK, 4))).as_matrix()
        with pytest.raises(rk.NonFiniteError) as info:
            client.compute(bad, sync=True)
        assert info.value.index == (88,)
