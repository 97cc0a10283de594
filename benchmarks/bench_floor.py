"""The call floor at small N: what a numba-bound class API pays before any work.

Issue 9 asks for ``compose`` and ``inv`` within 2x of the fastest peer at every
N. Below about 1,000 elements that peer is numpy-quaternion, whose product and
conjugate are C ufuncs on a quaternion dtype. This script takes that call apart,
side by side in one process (median of round-robin samples), at N = 1, 10, 100,
1,000:

* ``np-quat``: numpy-quaternion's ``qa * qb`` / ``qa.conj()`` (the peer);
* ``numba + empty``: rigidkit's own compiled loop called directly with a fresh
  ``np.empty`` output, no check at all: the least any function that runs a numba
  loop and returns a new array can cost;
* ``numba + empty + object``: the same, wrapped into a new ``Rotation`` (the
  least a method returning an object can cost);
* ``functional``: ``rk.conversions.quat_compose`` / ``rk.quaternion.conjugate`` (the
  kernel's generated entry point: shape, dtype and contiguity checks);
* ``Rotation``: ``a @ b`` / ``a.inv()``.

The last column is the floor over the peer: where it is above 2, no numba-bound
class API can meet the 2x target, however lean its checks.

Run: ``python benchmarks/bench_floor.py [--clock thread]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _common import fmt, interleaved_medians, set_clock, table


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 10, 100, 1000])
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--clock", choices=("wall", "thread"), default="wall")
    args = ap.parse_args()
    set_clock(args.clock)

    import quaternion  # numpy-quaternion

    import rigidkit as rk
    from rigidkit._engine.dispatch import entry_point
    from rigidkit.functional import conversions as conv
    from rigidkit.functional import quaternion as quat

    rng = np.random.default_rng(0)
    big = rk.Rotation.from_quat(rng.standard_normal((5000, 4)))
    big @ big, big.inv()  # start the compiled loops
    deadline = time.time() + 60
    while not (
        conv.quat_compose._ready.get((False, False)) and quat.conjugate._ready.get((False,))
    ):
        if time.time() > deadline:
            raise SystemExit("the compiled loops did not load within 60 s")
        time.sleep(0.2)
        big @ big, big.inv()
    # The compiled entry points, as the fast path calls them (no numba typing).
    f64 = np.dtype(np.float64)
    compose_loop = entry_point(conv.quat_compose._ready[(False, False)][f64])
    conj_loop = entry_point(quat.conjugate._ready[(False,)][f64])

    rows = []
    for n in args.sizes:
        a = rk.Rotation.from_quat(rng.standard_normal((n, 4)))
        b = rk.Rotation.from_quat(rng.standard_normal((n, 4)))
        for op, fns in _contenders(a, b, compose_loop, conj_loop, conv, quat, quaternion):
            res = interleaved_medians(fns, repeat=args.repeat)
            us = {k: v["median"] * 1e6 for k, v in res.items()}
            rows.append(
                [op, f"{n:,}"]
                + [fmt(us[k]) for k in NAMES]
                + [f"{us['numba + empty + object'] / us['np-quat']:.2f}x"]
            )
    headers = ["op", "N", *NAMES, "floor/np-quat"]
    print("us per call (median); floor = numba + empty + object")
    print(table(headers, rows, left=2))
    print()
    print(_matrix_floor(rk, args.repeat))


def _matrix_floor(rk, repeat) -> str:
    """SE(3) ``as_matrix``: scipy copies the 4x4 matrices it stores; we compute
    them from poses (7 numbers). The floor of any loop that writes 16 doubles per
    element with scalar stores (numba does not vectorise them): a loop that only
    stores (the pose's 7 numbers copied and 9 constants, no arithmetic)."""
    import numba
    from scipy.spatial.transform import RigidTransform

    @numba.njit(error_model="numpy", nogil=True)
    def stores_only(p, out):
        for i in range(p.shape[0]):
            out[i, 0, 0] = p[i, 0]
            out[i, 0, 1] = p[i, 1]
            out[i, 0, 2] = p[i, 2]
            out[i, 0, 3] = p[i, 4]
            out[i, 1, 0] = p[i, 3]
            out[i, 1, 1] = p[i, 0]
            out[i, 1, 2] = p[i, 1]
            out[i, 1, 3] = p[i, 5]
            out[i, 2, 0] = p[i, 2]
            out[i, 2, 1] = p[i, 3]
            out[i, 2, 2] = p[i, 0]
            out[i, 2, 3] = p[i, 6]
            out[i, 3, 0] = 0.0
            out[i, 3, 1] = 0.0
            out[i, 3, 2] = 0.0
            out[i, 3, 3] = 1.0

    rng = np.random.default_rng(1)
    rows = []
    for n in (100, 1000, 10000):
        T = rk.Transform.from_matrix(_random_matrices(rk, rng, n))
        S = RigidTransform.from_matrix(T.as_matrix())
        pose = T._pose  # the stored (n, 7) poses
        stores_only(pose, np.empty((n, 4, 4)))
        fns = {
            "scipy (copy)": S.as_matrix,
            "stores only + empty": lambda p=pose, n=n: stores_only(p, np.empty((n, 4, 4))),
            "rigidkit": T.as_matrix,
        }
        res = interleaved_medians(fns, repeat=repeat)
        us = {k: v["median"] * 1e6 for k, v in res.items()}
        rows.append(
            [
                f"{n:,}",
                *(fmt(us[k]) for k in fns),
                f"{us['stores only + empty'] / us['scipy (copy)']:.2f}x",
            ]
        )
    head = "SE(3) as_matrix, us per call (median)"
    return head + "\n" + table(["N", *fns, "stores/scipy"], rows)


def _random_matrices(rk, rng, n):
    q = rng.standard_normal((n, 4))
    R = rk.Rotation.from_quat(q).as_matrix()
    M = np.zeros((n, 4, 4))
    M[:, :3, :3] = R
    M[:, :3, 3] = rng.standard_normal((n, 3))
    M[:, 3, 3] = 1.0
    return M


NAMES = ("np-quat", "numba + empty", "numba + empty + object", "functional", "Rotation")


def _contenders(a, b, compose_loop, conj_loop, conv, quat, quaternion):
    """``(op, {name: callable})`` for ``compose`` and ``inv`` of batches ``a``, ``b``."""
    n = a.shape[0]
    wrap = type(a)._wrap
    ra, rb = a._quat, b._quat  # the stored (read-only, C-contiguous) arrays
    npa = quaternion.as_quat_array(a.as_quat())
    npb = quaternion.as_quat_array(b.as_quat())
    return (
        (
            "compose",
            {
                "np-quat": lambda: npa * npb,
                "numba + empty": lambda: compose_loop(ra, rb, np.empty((n, 4))),
                "numba + empty + object": lambda: wrap(
                    compose_loop(ra, rb, np.empty((n, 4)))
                ),
                "functional": lambda: conv.quat_compose(ra, rb),
                "Rotation": lambda: a @ b,
            },
        ),
        (
            "inv",
            {
                "np-quat": lambda: npa.conj(),
                "numba + empty": lambda: conj_loop(ra, np.empty((n, 4))),
                "numba + empty + object": lambda: wrap(conj_loop(ra, np.empty((n, 4)))),
                "functional": lambda: quat.conjugate(ra),
                "Rotation": lambda: a.inv(),
            },
        ),
    )


if __name__ == "__main__":
    main()
