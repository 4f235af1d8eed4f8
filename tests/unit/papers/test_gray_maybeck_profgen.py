"""The profgen variant of the Gray & Maybeck study (issue 43): its profile values and the refused combinations."""

from __future__ import annotations

import pytest

from approachsim.config import ProfileError
from approachsim.papers import gray_maybeck as gm


def test_profgen_cases_fly_the_lead_in_with_the_filter_from_its_start_and_the_frozen_tuning():
    for case in gm.CASES:
        prof = gm.case_profile(case, "profgen")
        assert prof.runway.lead_in == "profgen"
        assert prof.run.mode == "open"
        assert prof.nav.initial_error.start == "converged"
        assert prof.nav.gps_sigma_scale == gm.PROFGEN_TUNING["nav.gps_sigma_scale"]
        assert prof.nav.clock_q_scale == gm.PROFGEN_TUNING["nav.clock_q_scale"]
        # the faithful variant's per-grade free-inertial prior is kept (papers/gray_maybeck_faithful.py)
        faithful = gm.case_profile(case, "faithful")
        assert prof.nav.initial_error.position_m == faithful.nav.initial_error.position_m
        assert prof.sensors.gnss == faithful.sensors.gnss
        windows = [(f.start_s, f.end_s) for f in prof.faults]
        assert windows == list(gm.PROFGEN_OUTAGE_WINDOWS_S[case.gps_outages])
        assert faithful.runway.lead_in == "none"


def test_profgen_is_open_loop_only():
    with pytest.raises(ProfileError, match="--trajectory"):
        gm.compute(seed=1, runs=2, cases=["I"], evaluate=object(), columns=object(), closed=True,
                   trajectory="profgen")
    with pytest.raises(ProfileError, match="--trajectory"):
        gm.compute(seed=1, runs=2, cases=["I"], evaluate=object(), columns=object(), trajectory="spiral")
