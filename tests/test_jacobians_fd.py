"""The Lie-group Jacobians of every group, against central finite differences.

One test for all Lie groups of the registry (:mod:`rigidkit.objects.registry`:
``Rotation`` = SO(3), ``Transform`` = SE(3), ``Rotation2D`` = SO(2), ``Transform2D`` =
SE(2), ``Similarity`` = Sim(3), and any group added later); a group whose Jacobians
are not written yet is skipped with the reason. Every implementation
found is checked: the functional ``rk.<module>.left_jacobian`` and friends, and the
class's own where it has one.

Convention under test (left Jacobian on the left, right on the right)::

    exp(tau + d) ~ exp(J_l(tau) d) exp(tau) ~ exp(tau) exp(J_r(tau) d)
    log(exp(d) exp(tau)) ~ tau + J_l(tau)^-1 d,  log(exp(tau) exp(d)) ~ tau + J_r(tau)^-1 d

The references never go through rigidkit's exp or log: ``E(tau) = scipy.linalg.expm(
hat(tau))`` and ``scipy.linalg.logm``. For a direction ``d`` and step ``h``,

* ``hat(J_l d) ~ (E(tau + h d) - E(tau - h d)) / 2h @ E(-tau)`` and
  ``hat(J_r d) ~ E(-tau) @ (E(tau + h d) - E(tau - h d)) / 2h``: no logarithm,
  so the check holds at and across pi too;
* the inverses twice: ``J^-1 (J d)_fd = d`` at every point (pi included), and the
  derivative of the logarithm, ``(logm(E(h d) E(tau)) - logm(E(-h d) E(tau))) / 2h
  ~ J_l^-1 d`` (and the mirror for the right side), where ``logm`` is the principal
  logarithm of both sides of the step (rotation angle below ``pi - 1e-3``).

``vee`` of the difference quotient is its least-squares coordinates on the
generators ``hat(e_k)`` (the difference quotient leaves the Lie algebra by O(h^2)).

Points: random tangents (rotation angle uniform in (0.1, pi - 0.1), the other
components standard normal), exactly 0, a whole tangent of norm 1e-8, a rotation
part of 0 or 1e-8 beside O(1) translation / scale, pi - 1e-6 and pi. Directions: each
basis vector (the whole matrix) and three random unit vectors.

Tolerance: central differences with ``h = 1e-5`` err by ``h^2/6 |f'''|`` (truncation)
plus ``eps |E| / h`` (rounding), ~1e-11 for entries of order 1; both grow with
``|E(tau)| |E(-tau)|`` (the scale ``e^s`` of Sim(3), the translation of SE(n)), so
``FD_TOL = 1e-9`` is relative to ``(1 + |tau|)^2 |E(tau)| |E(-tau)|`` (and, for the
inverses, to ``1 + |J^-1|`` more). The largest error measured over five seeds is
1.7e-11 of that scale (the rounding of logm over ``2h``); a Jacobian of the wrong side
is off by O(1) (``test_power``).
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass

import numpy as np
import pytest
import scipy.linalg as sl

from conftest import LIE_GROUPS
from rigidkit.objects import registry

H = 1e-5
FD_TOL = 1e-9
NAMES = (
    "left_jacobian",
    "right_jacobian",
    "left_jacobian_inverse",
    "right_jacobian_inverse",
)


@dataclass(frozen=True)
class Group:
    cls: type
    alg: object  # the functional module: hat, and the Jacobians where written
    rot: slice  # the rotation components of the tangent

    def __repr__(self):
        return self.cls.__name__

    @property
    def dof(self) -> int:
        return self.cls.dof

    def hat(self, tau):
        return np.asarray(self.alg.hat(tau), dtype=np.float64)

    def implementations(self, name):
        """Every implementation of Jacobian ``name``: ``[(label, function)]``."""
        found = []
        fn = getattr(self.alg, name, None)
        if fn is not None:
            found.append((f"{self.alg.__name__}.{name}", fn))
        # A class-level Jacobian of a tangent (classmethod or staticmethod).
        static = inspect.getattr_static(self.cls, name, None)
        if isinstance(static, (classmethod, staticmethod)):
            found.append((f"{self.cls.__name__}.{name}", getattr(self.cls, name)))
        return found


def _group(cls):
    spec = registry.spec(cls)
    return Group(cls, spec.algebra, spec.part("rotation"))


# Every Lie group of the registry (:mod:`rigidkit.objects.registry`), not a list.
GROUPS = [_group(cls) for cls in LIE_GROUPS]
KINDS = ["random", "zero", "tiny", "zero rotation", "tiny rotation", "near pi", "pi"]


def tangents(G: Group, kind: str, rng) -> np.ndarray:
    """Tangent vectors of ``G`` (a batch of 3, or of 1) of the given kind."""
    n = 3 if kind == "random" else 1
    tau = rng.standard_normal((n, G.dof))
    k = G.rot.stop - G.rot.start
    direction = rng.standard_normal((n, k))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    angle = {
        "random": rng.uniform(0.1, math.pi - 0.1, n),
        "zero": np.zeros(n),
        "tiny": np.ones(n),  # then the whole tangent is scaled to 1e-8
        "zero rotation": np.zeros(n),
        "tiny rotation": np.full(n, 1e-8),
        "near pi": np.full(n, math.pi - 1e-6),
        "pi": np.full(n, math.pi),
    }[kind]
    tau[:, G.rot] = direction * angle[:, None]
    if kind == "zero":
        tau[:] = 0.0
    if kind == "tiny":
        tau *= 1e-8 / np.linalg.norm(tau, axis=-1, keepdims=True)
    return tau


def directions(G: Group, rng) -> np.ndarray:
    """Rows: the basis vectors, then three random unit vectors."""
    d = rng.standard_normal((3, G.dof))
    return np.vstack([np.eye(G.dof), d / np.linalg.norm(d, axis=-1, keepdims=True)])


def expm(G: Group, tau) -> np.ndarray:
    return sl.expm(G.hat(np.asarray(tau, dtype=np.float64)))


def vee(G: Group, M) -> np.ndarray:
    """Coordinates of ``M`` on the generators ``hat(e_k)``, by least squares."""
    gens = np.stack([G.hat(e).ravel() for e in np.eye(G.dof)], axis=-1)
    return np.linalg.lstsq(gens, np.ravel(M), rcond=None)[0]


def fd_jacobian(G: Group, tau, dirs, side) -> np.ndarray:
    """``J d`` for each row ``d`` of ``dirs`` (one column each), from expm alone."""
    E_inv = expm(G, -tau)
    cols = []
    for d in dirs:
        dE = (expm(G, tau + H * d) - expm(G, tau - H * d)) / (2 * H)
        cols.append(vee(G, dE @ E_inv if side == "left" else E_inv @ dE))
    return np.stack(cols, axis=-1)


def fd_log_derivative(G: Group, tau, dirs, side) -> np.ndarray:
    """``J^-1 d`` for each row ``d`` of ``dirs``: the derivative of logm."""
    E = expm(G, tau)

    def log_at(t):
        step = expm(G, t)
        return vee(G, np.real(sl.logm(step @ E if side == "left" else E @ step)))

    return np.stack([(log_at(H * d) - log_at(-H * d)) / (2 * H) for d in dirs], axis=-1)


def scale_of(G: Group, tau) -> float:
    """What the finite-difference error grows with (see the module docstring)."""
    size = np.abs(expm(G, tau)).max() * np.abs(expm(G, -tau)).max()
    return (1.0 + np.linalg.norm(tau)) ** 2 * size


def implementations_or_skip(G: Group):
    impls = {name: G.implementations(name) for name in NAMES}
    missing = [name for name, found in impls.items() if not found]
    if missing:
        pytest.skip(f"{G!r} has no {', '.join(missing)}")
    return impls


def evaluate(fn, tau) -> list[np.ndarray]:
    """``fn`` on the whole batch and on each element alone (the one-element path)."""
    batch = np.asarray(fn(tau), dtype=np.float64)
    assert batch.shape == tau.shape + (tau.shape[-1],)
    singles = [np.asarray(fn(t), dtype=np.float64) for t in tau]
    for one, row in zip(singles, batch, strict=True):
        np.testing.assert_allclose(one, row, rtol=0, atol=1e-15 * (1 + np.abs(row).max()))
    return list(batch)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("G", GROUPS, ids=repr)
def test_jacobians_by_finite_differences(G, kind, rng):
    impls = implementations_or_skip(G)
    tau_batch = tangents(G, kind, rng)
    dirs = directions(G, rng)
    for i, tau in enumerate(tau_batch):
        tol = FD_TOL * scale_of(G, tau)
        angle = np.linalg.norm(tau[G.rot])
        for side in ("left", "right"):
            fd = fd_jacobian(G, tau, dirs, side)
            for label, fn in impls[f"{side}_jacobian"]:
                J = evaluate(fn, tau_batch)[i]
                err = np.abs(J @ dirs.T - fd).max()
                assert err <= tol, (label, kind, tau, err / tol)
            for label, fn in impls[f"{side}_jacobian_inverse"]:
                J_inv = evaluate(fn, tau_batch)[i]
                # J^-1 undoes the measured J: its rounding scales with |J^-1|.
                err = np.abs(J_inv @ fd - dirs.T).max()
                assert err <= tol * (1 + np.abs(J_inv).max()), (label, kind, tau, err / tol)
                if angle < math.pi - 1e-3:
                    err = np.abs(
                        J_inv @ dirs.T - fd_log_derivative(G, tau, dirs, side)
                    ).max()
                    assert err <= tol * (1 + np.abs(J_inv).max()), (label, "log", kind, err)


@pytest.mark.parametrize("G", GROUPS, ids=repr)
def test_power(G, rng):
    """The test above tells the sides apart (for the non-abelian groups)."""
    impls = implementations_or_skip(G)
    if G.dof == 1:
        pytest.skip("a group of dimension 1 (SO(2)) is abelian: J_l = J_r = 1")
    tau = tangents(G, "random", rng)[0]
    dirs = directions(G, rng)
    fd_right = fd_jacobian(G, tau, dirs, "right")
    tol = FD_TOL * scale_of(G, tau)
    for _, fn in impls["left_jacobian"]:
        J_l = np.asarray(fn(tau), dtype=np.float64)
        assert np.abs(J_l @ dirs.T - fd_right).max() > 1e3 * tol
