"""nav.clock_q_scale (issue 43's Q tuning): the filter's receiver-clock process noise scales, the truth's clock and
everything else of the filter do not; a bad value is one line naming the field."""

from __future__ import annotations

import dataclasses

import pytest

from approachsim.config import ProfileError
from approachsim.nav.system import NavSystem
from approachsim.papers import gray_maybeck as gm


def test_clock_q_scale_multiplies_the_filters_clock_noise_only():
    case = gm.select_cases(["III"])[0]
    base = gm.case_profile(case, "faithful")
    tuned = gm.case_profile(case, "faithful", extra=[("nav.clock_q_scale", 250.0)])
    nz0 = NavSystem.from_profile(base).noise_model.noise()
    nz1 = NavSystem.from_profile(tuned).noise_model.noise()
    assert nz1.clock_sf == pytest.approx(250.0 * nz0.clock_sf, rel=1e-12)
    assert nz1.clock_sg == pytest.approx(250.0 * nz0.clock_sg, rel=1e-12)
    for f in dataclasses.fields(nz0):
        if f.name not in ("clock_sf", "clock_sg"):
            assert repr(getattr(nz1, f.name)) == repr(getattr(nz0, f.name)), f.name
    assert tuned.sensors == base.sensors  # the truth's clock: the sensor's oscillator, unchanged
    with pytest.raises(ProfileError, match="nav.clock_q_scale"):
        gm.case_profile(case, "faithful", extra=[("nav.clock_q_scale", 0.0)])
