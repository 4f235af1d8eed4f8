"""Shared synthetic truths for the sensor tests (synthetic test truth, not JSBSim)."""

from __future__ import annotations

import math

import pytest

from approachsim import geo, synthetic

SFO = geo.RunwayFrame(math.radians(37.6117), math.radians(-122.3581), 13.0 * 0.3048, math.radians(298.0))


@pytest.fixture(scope="session")
def runway() -> geo.RunwayFrame:
    return SFO


@pytest.fixture(scope="session")
def descent():
    """10 nmi constant-velocity descent to the SFO 28R threshold at 20 Hz (~265 s)."""
    return synthetic.glidepath_descent(SFO, rate_hz=20.0, ground_speed_mps=70.0)
