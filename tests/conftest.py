"""Shared test settings: hypothesis profiles and small helpers used by several files.

Hypothesis runs with ``deadline=None`` (a first call may wait for a numba compile)
and a modest number of examples; ``HYPOTHESIS_PROFILE=thorough`` runs more.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "default",
    max_examples=100,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("thorough", max_examples=2000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


@pytest.fixture
def rng():
    """A seeded generator, fresh for every test (tests stay independent of order)."""
    return np.random.default_rng(20240607)


def quat_angle(q1, q2):
    """Angle (radians) of the rotation between unit quaternions, in float64 NumPy.

    An independent reference for "the same orientation": ``2 atan2(|v|, |w|)`` of
    ``q1* q2`` written out here, so ``q`` and ``-q`` compare equal.
    """
    q1 = np.asarray(q1, dtype=np.float64)
    q2 = np.asarray(q2, dtype=np.float64)
    w1, v1 = q1[..., 0], q1[..., 1:]
    w2, v2 = q2[..., 0], q2[..., 1:]
    w = w1 * w2 + np.sum(v1 * v2, axis=-1)
    v = w1[..., None] * v2 - w2[..., None] * v1 - np.cross(v1, v2)
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))
