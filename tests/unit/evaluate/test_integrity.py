"""Protection levels from a covariance and Stanford-diagram counts on constructed cases."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim.evaluate.integrity import availability, protection_levels, stanford_regions


def test_protection_levels_diagonal_and_rotated():
    p = np.diag([9.0, 16.0, 4.0])
    vpl, hpl = protection_levels(p, 5.33, 6.0)
    assert vpl == pytest.approx(5.33 * 2.0)
    assert hpl == pytest.approx(6.0 * 4.0)  # the major semi-axis
    # the same ellipse rotated by 30 deg: d_major is invariant
    a = np.radians(30.0)
    r = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    vpl2, hpl2 = protection_levels(r @ p @ r.T, 5.33, 6.0)
    assert hpl2 == pytest.approx(24.0) and vpl2 == pytest.approx(vpl)
    # batched over (runs, time)
    pb = np.broadcast_to(p, (2, 5, 3, 3))
    vb, hb = protection_levels(pb, 5.33, 6.0)
    assert vb.shape == (2, 5) and np.allclose(hb, 24.0)


def test_stanford_counts_on_constructed_points():
    al = 10.0
    pts = [  # (PE, PL, region)
        (1.0, 5.0, "normal"),
        (5.0, 5.0, "normal"),  # on the diagonal: bounded
        (7.0, 5.0, "mi"),
        (10.0, 5.0, "mi"),  # PE = AL: not yet hazardous
        (12.0, 5.0, "hmi"),
        (-12.0, 9.9, "hmi"),  # the sign of the error does not matter
        (3.0, 10.0, "unavailable"),  # PL = AL: unavailable
        (30.0, 20.0, "unavailable"),
    ]
    pe = np.array([p[0] for p in pts])
    pl = np.array([p[1] for p in pts])
    c = stanford_regions(pe, pl, al)
    for region in ("normal", "mi", "hmi", "unavailable"):
        assert c[region] == sum(p[2] == region for p in pts), region
    assert c["unavailable_mi"] == 1
    assert sum(c[r] for r in ("normal", "mi", "hmi", "unavailable")) == len(pts)
    c2 = stanford_regions(np.array([np.nan, 1.0]), np.array([1.0, np.nan]), al)
    assert sum(c2.values()) == 0


def test_availability_needs_both_levels():
    a = availability(np.array([1.0, 11.0, 1.0]), np.array([1.0, 1.0, 41.0]), 10.0, 40.0)
    assert a.tolist() == [True, False, False]
