"""The limit-case sweep's grid (campaign/limit_case.py): every grid point's standard-normal u maps, through the
integrity-risk study's own fault map, to the magnitude, onset and channel rank it names (no flight)."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim.campaign import limit_case as lc
from approachsim.campaign.integrity_risk import MODES, fault_spec


def test_grid_maps_back_to_the_named_faults() -> None:
    m = MODES["baro-step"].with_window(250.0)
    pts = lc.grid(m, per_decade=2, channels=1)
    mags = lc.magnitudes(m, 2)
    assert mags[0] == pytest.approx(1.0) and mags[-1] == pytest.approx(100.0) and len(mags) == 5
    onsets = lc.onset_points(m)
    assert [o[1] for o in onsets][:2] == ["3600 s before the window", "1800 s before the window"]
    assert len(pts) == len(onsets) * len(mags)
    window = (10.0, 260.0)
    for u, what in pts:
        spec, p = fault_spec(m, u, None, None, 1, 0, window)
        assert spec.magnitude == pytest.approx(what["magnitude"], rel=1e-9)
    # the onsets: 3600 s, 1800 s, 360 s, 36 s before the window start, then its start, middle and 90 %
    got = sorted({round(fault_spec(m, u, None, None, 1, 0, window)[1]["onset_s"], 6) for u, _ in pts})
    assert got == pytest.approx(sorted([10.0 - 3600.0, 10.0 - 1800.0, 10.0 - 360.0, 10.0 - 36.0, 10.0, 135.0, 235.0]))


def test_satellite_grid_covers_each_rank() -> None:
    m = MODES["sat-ramp"].with_window(250.0)
    pts = lc.grid(m, per_decade=1, channels=4)
    ranks = {w["rank"] for _, w in pts}
    assert ranks == {0, 1, 2, 3}
    # the channel input's Phi picks rank k among 4: (k + 0.5) / 4
    from scipy import stats as sps

    for u, w in pts[:8]:
        assert int(sps.norm.cdf(u[2]) * 4) == w["rank"]
    assert np.all(np.isfinite(np.array([u for u, _ in pts])))
