"""SO(3) benchmark: rigidkit against scipy and the other Python rotation libraries.

Times, in ONE process and side by side, ``rigidkit.Rotation`` and
``scipy.spatial.transform.Rotation`` (and, when installed, numpy-quaternion,
quaternionic and pytransform3d where they have the op) on compose, apply (N
rotations on N vectors, and one rotation on a cloud of N points), inv, as_matrix,
from_matrix (validated), from_euler, as_euler, from_rotvec and as_rotvec, at one
element and at a million; plus the memory-bandwidth floor of each op, the
``import rigidkit`` time and the first call on 1,000 elements in a fresh process
with an empty kernel cache. See README.md in this folder for how each number is
taken.

    python benchmarks/bench_so3.py                       # N = 1 and 1,000,000
    python benchmarks/bench_so3.py --sizes 1 10000 --repeat 5 --json out.json
    python benchmarks/bench_so3.py --ops compose apply --no-fresh
"""

from __future__ import annotations

import argparse
import json
import math
import operator
import os
import platform
import sys
import warnings
from dataclasses import dataclass, field
from functools import partial

_argv = sys.argv[1:]
if "--clock" in _argv[:-1] and _argv[_argv.index("--clock") + 1] == "thread":
    # The thread clock counts only the calling thread: keep BLAS (scipy's apply on
    # a point cloud is a matrix product) on it too. Must precede the NumPy import.
    for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common as C  # noqa: E402

# The single-element and batched targets of issue 2.
SINGLE_LIMIT_US = 3.0
FLOOR_FACTOR = 2.0

LIBS = [
    "rigidkit",
    "rk 1t",
    "rk 2t",
    "scipy",
    "numpy-quaternion",
    "quaternionic",
    "pytransform3d",
]
PEERS = ["scipy", "numpy-quaternion", "quaternionic", "pytransform3d"]
SHORT = {
    "rigidkit": "rigidkit",
    "rk 1t": "rk 1t",
    "rk 2t": "rk 2t",
    "scipy": "scipy",
    "numpy-quaternion": "np-quat",
    "quaternionic": "qtnionic",
    "pytransform3d": "pt3d",
    "floor 1c": "floor 1c",
    "floor 2c": "floor 2c",
    "floor+alloc 1c": "+alloc 1c",
    "floor+alloc 2c": "+alloc 2c",
}
TABLE = dict(
    contenders=LIBS,
    peers=PEERS,
    short=SHORT,
    single_limit_us=SINGLE_LIMIT_US,
    floor_factor=FLOOR_FACTOR,
    mark_unbounded=False,
)


# -- optional libraries ----------------------------------------------------------------


def _try_import(name):
    try:
        return __import__(name, fromlist=["_"]), None
    except Exception as exc:  # not installed, or broken: skip the peer, say why
        return None, f"{type(exc).__name__}: {exc}"


class Libs:
    """The libraries found in this environment (None where missing)."""

    def __init__(self):
        self.notes = {}
        self.rk, err = _try_import("rigidkit")
        if self.rk is None:
            sys.exit(f"rigidkit is not importable ({err}); install it first")
        from scipy.spatial.transform import Rotation as SR

        self.SR = SR
        self.nq, err = _try_import("quaternion")
        if err:
            self.notes["numpy-quaternion"] = f"skipped, not installed ({err})"
        self.qn, err = _try_import("quaternionic")
        if err:
            self.notes["quaternionic"] = f"skipped, not installed ({err})"
        self.pb, err = _try_import("pytransform3d.batch_rotations")
        self.pr, _ = _try_import("pytransform3d.rotations")
        if err:
            self.notes["pytransform3d"] = f"skipped, not installed ({err})"
        self.euler, err = _try_import("rigidkit.functional.euler")
        if err:
            self.notes["rigidkit.euler"] = (
                f"rigidkit from_euler/as_euler skipped: rigidkit.euler missing ({err})"
            )


# -- data ------------------------------------------------------------------------------


@dataclass
class Data:
    """Inputs for one batch size; ``single`` means one element of shape ()."""

    n: int
    single: bool
    q1: np.ndarray
    q2: np.ndarray
    v: np.ndarray
    q0: np.ndarray  # one rotation, for the point cloud
    cloud: np.ndarray
    m: np.ndarray
    e: dict  # seq -> angles
    rv: np.ndarray
    objects: dict = field(default_factory=dict)  # per-library prebuilt inputs


def unit_quats(rng, shape):
    q = rng.standard_normal(shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def make_data(n, libs, seed=0) -> Data:
    rng = np.random.default_rng(seed)
    single = n == 1
    shape = () if single else (n,)
    q1 = unit_quats(rng, shape)
    q2 = unit_quats(rng, shape)
    v = rng.standard_normal(shape + (3,))
    q0 = unit_quats(rng, ())
    cloud = rng.standard_normal((n, 3))
    m = libs.SR.from_quat(q1.reshape(-1, 4), scalar_first=True).as_matrix()
    m = np.ascontiguousarray(m.reshape(shape + (3, 3)))
    u = rng.uniform(-1.0, 1.0, shape + (3,))
    e = {
        # Tait-Bryan: middle angle in (-pi/2, pi/2); proper: in (0, pi).
        "ZYX": u * np.array([math.pi, math.pi / 2, math.pi]),
        "ZYZ": (u + np.array([0.0, 1.0, 0.0])) * np.array([math.pi, math.pi / 2, math.pi]),
    }
    axis = rng.standard_normal(shape + (3,))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    rv = axis * rng.uniform(0.0, math.pi, shape + (1,))
    return Data(n, single, q1, q2, v, q0, cloud, m, e, rv)


# -- the ops ---------------------------------------------------------------------------


def build_rows(libs: Libs) -> list:
    """Every row, with a builder per library: ``builder(data) -> zero-argument callable``.

    Builders prepare everything that is not the op (library objects, output
    buffers) outside the timed call; ``functools.partial`` keeps the call overhead
    the same for every library. A builder returns None where a library lacks the
    op at that size.
    """
    rk, SR, nq, qn, pb, pr = libs.rk, libs.SR, libs.nq, libs.qn, libs.pb, libs.pr

    def objects(d, lib):
        """The inputs q1, q2, q0 as rotation objects of ``lib`` (built once per size)."""
        make = {
            "rk": rk.Rotation.from_quat,
            "scipy": lambda q: SR.from_quat(q, scalar_first=True),
            "nq": lambda q: nq.from_float_array(q),
            "qn": lambda q: qn.array(q),
        }[lib]
        if lib not in d.objects:
            d.objects[lib] = tuple(make(q) for q in (d.q1, d.q2, d.q0))
        return d.objects[lib]

    buffer, per_size = C.buffer, C.per_size

    def batched(make):
        return lambda d: None if d.single else make(d)

    rows = []

    def row(key, floor, memory_bound, kind, batched_only=False):
        r = C.Row(key, floor, memory_bound, kind, batched_only)
        rows.append(r)
        return r

    # compose ------------------------------------------------------------------
    r = row("compose", ([4, 4], 4), True, "rot")
    r.impls["rigidkit"] = lambda d: partial(operator.matmul, *objects(d, "rk")[:2])
    r.impls["scipy"] = lambda d: partial(operator.mul, *objects(d, "scipy")[:2])
    if nq:
        r.impls["numpy-quaternion"] = lambda d: partial(operator.mul, *objects(d, "nq")[:2])
    if qn:
        r.impls["quaternionic"] = lambda d: partial(operator.mul, *objects(d, "qn")[:2])
    if pb:
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.concatenate_quaternions, d.q1, d.q2),
            lambda d: partial(pb.batch_concatenate_quaternions, d.q1, d.q2),
        )

    r = row("compose out=", ([4, 4], 4), True, "rot")
    r.notes["rigidkit"] = "rk.quaternion.multiply(q1, q2, out=)"
    r.impls["rigidkit"] = lambda d: partial(
        rk.quaternion.multiply, d.q1, d.q2, out=buffer(d.q1.shape)
    )
    if nq:
        r.impls["numpy-quaternion"] = batched(
            lambda d: partial(
                np.multiply, *objects(d, "nq")[:2], out=np.empty_like(objects(d, "nq")[0])
            )
        )
    if pb:
        r.impls["pytransform3d"] = batched(
            lambda d: partial(
                pb.batch_concatenate_quaternions, d.q1, d.q2, out=buffer(d.q1.shape)
            )
        )

    # apply ----------------------------------------------------------------------
    r = row("apply", ([4, 3], 3), True, "vec")
    r.impls["rigidkit"] = lambda d: partial(objects(d, "rk")[0].apply, d.v)
    r.impls["scipy"] = lambda d: partial(objects(d, "scipy")[0].apply, d.v)
    if nq:
        r.notes["numpy-quaternion"] = "as_vector_part(q * from_vector_part(v) * q.conj())"

        def nq_apply(d):
            q = objects(d, "nq")[0]
            return lambda: nq.as_vector_part(q * nq.from_vector_part(d.v) * q.conj())

        r.impls["numpy-quaternion"] = nq_apply
    if pr:
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.q_prod_vector, d.q1, d.v), lambda d: None
        )

    r = row("apply out=", ([4, 3], 3), True, "vec")
    r.impls["rigidkit"] = lambda d: partial(
        objects(d, "rk")[0].apply, d.v, out=buffer(d.v.shape)
    )

    r = row("apply cloud", ([3], 3), True, "vec", batched_only=True)
    r.impls["rigidkit"] = lambda d: partial(objects(d, "rk")[2].apply, d.cloud)
    r.impls["scipy"] = lambda d: partial(objects(d, "scipy")[2].apply, d.cloud)
    if nq:
        r.impls["numpy-quaternion"] = lambda d: partial(
            nq.rotate_vectors, objects(d, "nq")[2], d.cloud
        )
    if qn:
        r.impls["quaternionic"] = lambda d: partial(objects(d, "qn")[2].rotate, d.cloud)

    r = row("apply cloud out=", ([3], 3), True, "vec", batched_only=True)
    r.impls["rigidkit"] = lambda d: partial(
        objects(d, "rk")[2].apply, d.cloud, out=buffer(d.cloud.shape)
    )

    # inv -------------------------------------------------------------------------
    r = row("inv", ([4], 4), True, "rot")
    r.impls["rigidkit"] = lambda d: objects(d, "rk")[0].inv
    r.impls["scipy"] = lambda d: objects(d, "scipy")[0].inv
    if nq:
        r.impls["numpy-quaternion"] = lambda d: partial(np.conjugate, objects(d, "nq")[0])
    if qn:
        r.impls["quaternionic"] = lambda d: objects(d, "qn")[0].conj
    if pb:
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.q_conj, d.q1), lambda d: partial(pb.batch_q_conj, d.q1)
        )

    r = row("inv out=", ([4], 4), True, "rot")
    r.notes["rigidkit"] = "rk.quaternion.conjugate(q, out=)"
    r.impls["rigidkit"] = lambda d: partial(
        rk.quaternion.conjugate, d.q1, out=buffer(d.q1.shape)
    )
    if nq:
        r.impls["numpy-quaternion"] = batched(
            lambda d: partial(
                np.conjugate, objects(d, "nq")[0], out=np.empty_like(objects(d, "nq")[0])
            )
        )

    # as_matrix -------------------------------------------------------------------
    r = row("as_matrix", ([4], 9), True, "mat")
    r.impls["rigidkit"] = lambda d: objects(d, "rk")[0].as_matrix
    r.impls["scipy"] = lambda d: objects(d, "scipy")[0].as_matrix
    if nq:
        r.impls["numpy-quaternion"] = lambda d: partial(
            nq.as_rotation_matrix, objects(d, "nq")[0]
        )
    if qn:
        r.impls["quaternionic"] = lambda d: partial(
            getattr, objects(d, "qn")[0], "to_rotation_matrix"
        )
    if pb:
        r.notes["pytransform3d"] = "normalize_quaternions=False"
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.matrix_from_quaternion, d.q1),
            lambda d: partial(
                pb.matrices_from_quaternions, d.q1, normalize_quaternions=False
            ),
        )

    r = row("as_matrix out=", ([4], 9), True, "mat")
    r.impls["rigidkit"] = lambda d: partial(
        objects(d, "rk")[0].as_matrix, out=buffer(d.q1.shape[:-1] + (3, 3))
    )
    if pb:
        r.impls["pytransform3d"] = batched(
            lambda d: partial(
                pb.matrices_from_quaternions,
                d.q1,
                normalize_quaternions=False,
                out=buffer(d.q1.shape[:-1] + (3, 3)),
            )
        )

    # from_matrix -------------------------------------------------------------------
    r = row("from_matrix", ([9], 4), False, "rot")
    r.impls["rigidkit"] = lambda d: partial(rk.Rotation.from_matrix, d.m)
    r.impls["scipy"] = lambda d: partial(SR.from_matrix, d.m)
    if nq:
        r.notes["numpy-quaternion"] = "nonorthogonal=False, not validated"
        r.impls["numpy-quaternion"] = lambda d: partial(
            nq.from_rotation_matrix, d.m, nonorthogonal=False
        )
    if qn:
        r.notes["quaternionic"] = "nonorthogonal=False, not validated"
        r.impls["quaternionic"] = lambda d: partial(
            qn.array.from_rotation_matrix, d.m, nonorthogonal=False
        )
    if pb:
        r.notes["pytransform3d"] = "batch: not validated; single: strict_check"
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.quaternion_from_matrix, d.m),
            lambda d: partial(pb.quaternions_from_matrices, d.m),
        )

    # Euler ----------------------------------------------------------------------------
    axes = {"ZYX": (2, 1, 0), "ZYZ": (2, 1, 2)}
    for seq in ("ZYX", "ZYZ"):
        r = row(f"from_euler {seq}", ([3], 4), False, "rot")
        if libs.euler:
            r.impls["rigidkit"] = lambda d, s=seq: partial(
                rk.Rotation.from_euler, s, d.e[s]
            )
        r.impls["scipy"] = lambda d, s=seq: partial(SR.from_euler, s, d.e[s])
        if seq == "ZYZ" and nq:
            r.impls["numpy-quaternion"] = lambda d: partial(
                nq.from_euler_angles, d.e["ZYZ"]
            )
        if seq == "ZYZ" and qn:
            r.impls["quaternionic"] = lambda d: partial(
                qn.array.from_euler_angles, d.e["ZYZ"]
            )
        if pb:
            r.notes["pytransform3d"] = "batch: to matrices"
            r.impls["pytransform3d"] = per_size(
                lambda d, s=seq: partial(pr.quaternion_from_euler, d.e[s], *axes[s], False),
                lambda d, s=seq: partial(
                    pb.active_matrices_from_intrinsic_euler_angles, *axes[s], d.e[s]
                ),
            )

        r = row(f"as_euler {seq}", ([4], 3), False, f"euler:{seq}")
        if libs.euler:
            r.impls["rigidkit"] = lambda d, s=seq: partial(objects(d, "rk")[0].as_euler, s)
        r.impls["scipy"] = lambda d, s=seq: partial(objects(d, "scipy")[0].as_euler, s)
        if seq == "ZYZ" and nq:
            r.impls["numpy-quaternion"] = lambda d: partial(
                nq.as_euler_angles, objects(d, "nq")[0]
            )
        if seq == "ZYZ" and qn:
            r.impls["quaternionic"] = lambda d: partial(
                getattr, objects(d, "qn")[0], "to_euler_angles"
            )
        if pr:
            r.impls["pytransform3d"] = per_size(
                lambda d, s=seq: partial(pr.euler_from_quaternion, d.q1, *axes[s], False),
                lambda d: None,
            )

    # rotation vectors -----------------------------------------------------------------
    r = row("from_rotvec", ([3], 4), False, "rot")
    r.impls["rigidkit"] = lambda d: partial(rk.Rotation.from_rotvec, d.rv)
    r.impls["scipy"] = lambda d: partial(SR.from_rotvec, d.rv)
    if nq:
        r.impls["numpy-quaternion"] = lambda d: partial(nq.from_rotation_vector, d.rv)
    if qn:
        r.impls["quaternionic"] = lambda d: partial(qn.array.from_rotation_vector, d.rv)
    if pb:
        r.notes["pytransform3d"] = "batch: to matrices"
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.quaternion_from_compact_axis_angle, d.rv),
            lambda d: partial(pb.matrices_from_compact_axis_angles, d.rv),
        )

    r = row("as_rotvec", ([4], 3), False, "rotvec")
    r.impls["rigidkit"] = lambda d: objects(d, "rk")[0].as_rotvec
    r.impls["scipy"] = lambda d: objects(d, "scipy")[0].as_rotvec
    if nq:
        r.impls["numpy-quaternion"] = lambda d: partial(
            nq.as_rotation_vector, objects(d, "nq")[0]
        )
    if qn:
        r.impls["quaternionic"] = lambda d: partial(
            getattr, objects(d, "qn")[0], "to_rotation_vector"
        )
    if pb:
        r.notes["pytransform3d"] = "batch: to (axis, angle)"
        r.impls["pytransform3d"] = per_size(
            lambda d: partial(pr.compact_axis_angle_from_quaternion, d.q1),
            lambda d: partial(pb.axis_angles_from_quaternions, d.q1),
        )

    # rigidkit with its thread count forced (RIGIDKIT_NUM_THREADS); the plain
    # "rigidkit" column is the library's own choice (it counts idle cores).
    for r in rows:
        if "rigidkit" in r.impls:
            r.impls["rk 1t"] = C.with_threads(r.impls["rigidkit"], 1)
            r.impls["rk 2t"] = C.with_threads(r.impls["rigidkit"], 2)
    return rows


# -- correctness check of what is timed ------------------------------------------------


def as_numpy_matrix(x, libs):
    """Rotation-valued result of any library -> rotation matrices, shape (..., 3, 3)."""
    if isinstance(x, libs.rk.Rotation):
        return np.asarray(x.as_matrix())
    if isinstance(x, libs.SR):
        return x.as_matrix()
    if libs.qn is not None and isinstance(x, libs.qn.array):
        return np.asarray(x.to_rotation_matrix)
    if libs.nq is not None and (
        isinstance(x, libs.nq.quaternion) or getattr(x, "dtype", None) == libs.nq.quaternion
    ):
        return libs.nq.as_rotation_matrix(x)
    x = np.asarray(x)
    if x.shape[-2:] == (3, 3):
        return x
    if x.shape[-1] == 4:
        s = x.shape[:-1]
        return (
            libs.SR.from_quat(x.reshape(-1, 4), scalar_first=True)
            .as_matrix()
            .reshape(s + (3, 3))
        )
    raise TypeError(f"cannot read a rotation from shape {x.shape}")


def canonical(kind, lib, x, libs):
    if kind in ("rot", "mat"):
        return as_numpy_matrix(x, libs)
    if kind == "vec":
        return np.asarray(x)
    x = np.asarray(x)
    s = x.shape[:-1]
    if kind == "rotvec":
        if x.shape[-1] == 4:  # pytransform3d: (axis, angle)
            x = x[..., :3] * x[..., 3:]
        return libs.SR.from_rotvec(x.reshape(-1, 3)).as_matrix().reshape(s + (3, 3))
    seq = kind.split(":")[1]
    return libs.SR.from_euler(seq, x.reshape(-1, 3)).as_matrix().reshape(s + (3, 3))


def check_rows(rows, libs, sizes=(1, 5)) -> dict:
    """Run every contender on small inputs and compare with scipy: (row, lib) -> error."""

    def error(res, ref):
        err = float(np.max(np.abs(res - ref)))
        return None if err <= 1e-9 else f"differs from scipy by {err:.3g}"

    return C.check_rows(
        rows,
        lambda n: make_data(n, libs, seed=1),
        lambda kind, lib, x: canonical(kind, lib, x, libs),
        error,
        sizes,
    )


# -- fresh-process measurements --------------------------------------------------------

FIRST_CALL_CODE = r"""
import json, os, sys, time, warnings
warnings.simplefilter("ignore")
import numpy as np
t0 = time.perf_counter()
import rigidkit as rk
t_import = time.perf_counter() - t0
numba_after_import = "numba" in sys.modules
rng = np.random.default_rng(0)
out = {"import_s": t_import, "numba_after_import": numba_after_import, "sizes": {}}
cache = os.environ["RIGIDKIT_CACHE_DIR"]

def files():
    n = 0
    for root, _, fs in os.walk(cache):
        n += sum(f.endswith((".py", ".nbi", ".nbc")) for f in fs)
    return n

for n in SIZES:
    q = rng.standard_normal((n, 4)); q /= np.linalg.norm(q, axis=-1, keepdims=True)
    R = rk.Rotation.from_quat(q)
    R2 = rk.Rotation.from_quat(q[::-1].copy())
    v = rng.standard_normal((n, 3))
    w, x, y, z = np.moveaxis(q, -1, 0)  # matrices by hand: no rigidkit call before timing
    m = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                  2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                  2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
                 axis=-1).reshape(n, 3, 3)
    e = rng.uniform(-1.0, 1.0, (n, 3))
    ops = {
        "compose": lambda: R @ R2,
        "apply": lambda: R.apply(v),
        "inv": lambda: R.inv(),
        "as_matrix": lambda: R.as_matrix(),
        "from_matrix": lambda: rk.Rotation.from_matrix(m),
        "from_euler ZYX": lambda: rk.Rotation.from_euler("ZYX", e),
        "as_euler ZYX": lambda: R.as_euler("ZYX"),
        "from_rotvec": lambda: rk.Rotation.from_rotvec(v),
        "as_rotvec": lambda: R.as_rotvec(),
    }
    res = {}
    for name, fn in ops.items():
        before = files()
        try:
            t0 = time.perf_counter(); fn(); t1 = time.perf_counter() - t0
            t0 = time.perf_counter(); fn(); t2 = time.perf_counter() - t0
        except Exception as exc:
            res[name] = {"error": f"{type(exc).__name__}: {exc}"[:160]}
            continue
        res[name] = {"first_s": t1, "second_s": t2, "compiled": files() > before}
    out["sizes"][str(n)] = res
out["numba_imported"] = "numba" in sys.modules
print(json.dumps(out))
"""


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[1, 1_000_000])
    p.add_argument("--repeat", type=int, default=7, help="timed samples per contender")
    p.add_argument(
        "--warmup", type=int, default=2, help="untimed calls first (JIT compile)"
    )
    p.add_argument("--min-sample", type=float, default=0.02, help="seconds per sample")
    p.add_argument("--ops", nargs="+", help="only rows whose name starts with one of these")
    p.add_argument(
        "--libs",
        nargs="+",
        default=LIBS + ["floor"],
        help="contenders to time (default: all installed, and the floor)",
    )
    p.add_argument("--import-repeat", type=int, default=7)
    p.add_argument("--first-call-sizes", type=int, nargs="*", default=[1000])
    p.add_argument("--no-fresh", action="store_true", help="skip import / first-call runs")
    p.add_argument("--no-check", action="store_true", help="skip the correctness check")
    p.add_argument(
        "--clock",
        choices=["wall", "thread"],
        default="wall",
        help="wall clock (default), or CPU time of the calling thread: steadier on a "
        "machine busy with other work, but then everything runs on one thread",
    )
    p.add_argument("--json", metavar="FILE", help="also write all samples as JSON")
    args = p.parse_args(argv)
    C.set_clock(args.clock)
    if args.clock == "thread":
        # Work done on other threads would not be counted: keep everything on one.
        os.environ["RIGIDKIT_NUM_THREADS"] = "1"
        args.libs = [lib for lib in args.libs if lib != "rk 2t"]
        threads = [1]
    else:
        threads = sorted({1, min(2, C.cpu_count())})

    libs = Libs()
    rows = build_rows(libs)
    if args.ops:
        rows = [r for r in rows if any(r.key.startswith(o) for o in args.ops)]
    contenders = [c for c in LIBS if c in args.libs]

    print(
        f"rigidkit {libs.rk.__version__}, numpy {np.__version__}, "
        f"python {platform.python_version()}"
    )
    import scipy

    vers = [f"scipy {scipy.__version__}"]
    from importlib.metadata import PackageNotFoundError, version

    for name in ("numpy-quaternion", "quaternionic", "pytransform3d"):
        try:
            vers.append(f"{name} {version(name)}")
        except PackageNotFoundError:
            pass
    print(", ".join(vers))
    print(
        f"{C.cpu_count()} cores ({platform.machine()}), "
        f"load average {C.load_average()} at the start"
    )
    for lib, note in libs.notes.items():
        print(f"note: {lib}: {note}")
    print(
        f"warm-up {args.warmup} untimed calls (JIT compile excluded), then the median of "
        f"{args.repeat} round-robin samples of >= {args.min_sample * 1e3:g} ms each; "
        + (
            "wall clock"
            if args.clock == "wall"
            else "CPU time of the calling thread, everything on ONE thread"
        )
    )

    checks = {} if args.no_check else check_rows(rows, libs)
    for (key, lib), msg in checks.items():
        print(f"CHECK {key} / {lib}: {msg}")

    record = {
        "meta": {"load": C.load_average(), "cores": C.cpu_count(), "clock": args.clock},
        "sizes": {},
    }
    for n in args.sizes:
        d = make_data(n, libs)
        results = {}
        for r in rows:
            if r.batched_only and d.single:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # GimbalLockWarning and the like: not timed
                results[r.key] = C.time_row(
                    r,
                    d,
                    contenders,
                    threads=threads,
                    floor="floor" in args.libs,
                    repeat=args.repeat,
                    warmup=args.warmup,
                    min_sample=args.min_sample,
                )
            print(f"  timed {r.key:>18} at N={n}", file=sys.stderr, flush=True)
        print()
        print(C.report_size(n, rows, results, checks, **dict(TABLE, contenders=contenders)))
        record["sizes"][str(n)] = results
        del d

    if not args.no_fresh:
        print()
        imp = C.import_times("rigidkit", args.import_repeat)
        own = C.import_times("rigidkit", args.import_repeat, preimport="numpy")
        bare = C.import_times("numpy", args.import_repeat)
        heavy = ", ".join(imp["heavy"]) or "none"
        print(
            f"import rigidkit: {imp['median'] * 1e3:.1f} ms including numpy (numpy alone "
            f"{bare['median'] * 1e3:.1f} ms), "
            f"{own['median'] * 1e3:.1f} ms with numpy already imported (median of "
            f"{args.import_repeat} fresh processes; target < 150 ms); heavy modules "
            f"imported: {heavy}"
        )
        prof = C.import_profile("rigidkit")
        print(
            "  largest self times (-X importtime, one run): "
            + ", ".join(f"{name} {ms:.1f} ms" for ms, name in prof)
        )
        record["import"] = {
            "with_numpy": imp,
            "numpy_preimported": own,
            "numpy_alone": bare,
            "profile": prof,
        }
        if args.first_call_sizes:
            fc = C.fresh_process(FIRST_CALL_CODE, args.first_call_sizes)
            record["first_call"] = fc
            print(C.report_fresh(fc, args.first_call_sizes))

    if args.json:
        with open(args.json, "w") as fh:
            json.dump(record, fh, indent=1, default=str)
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
