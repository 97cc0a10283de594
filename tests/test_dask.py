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
        q[88] = np.nan
        bad = rk.Rotation.from_quat(dask_array.from_array(q, chunks=(CHUNK, 4))).as_matrix()
        with pytest.raises(rk.NonFiniteError) as info:
            client.compute(bad, sync=True)
        assert info.value.index == (88,)
