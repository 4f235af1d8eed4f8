"""core/layouts.py: every packed vector's offsets follow from its (name, width) fields, and each layout matches the
record it packs (Truth's fields, the autopilot's gains, the INS state, the JSBSim reads and writes)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from approachsim.core import layouts
from approachsim.core.layouts import Layout
from approachsim.flight.design import AutopilotGains
from approachsim.nav import ins
from approachsim.records import Truth


def test_offsets_follow_the_fields():
    lay = Layout([("a", 1), ("b", 3), ("c", 2)])
    assert lay.starts() == (0, 1, 4) and lay.size == 6
    assert lay.slice("b") == slice(1, 4) and lay.width("c") == 2 and lay.names == ("a", "b", "c")
    with pytest.raises(ValueError, match="twice"):
        Layout([("a", 1), ("a", 2)])
    with pytest.raises(ValueError, match="width 0"):
        Layout([("a", 0)])


def test_truth_row_has_every_truth_field_once():
    fields = [f.name for f in dataclasses.fields(Truth) if f.name != "runway"]
    assert sorted(layouts.TRUTH_ROW.names) == sorted(fields)
    assert layouts.TRUTH_ROW.width("controls") == 4 and layouts.CONTROLS_COL == layouts.ROW_CONTROLS
    assert layouts.N_ROW == sum(w for _, w in layouts.TRUTH_ROW.fields)


def test_autopilot_parameters_start_with_the_gains_in_their_order():
    assert layouts.AP_GAINS == tuple(f.name for f in dataclasses.fields(AutopilotGains))
    assert layouts.AP_PAR.names[:len(layouts.AP_GAINS)] == layouts.AP_GAINS
    assert layouts.AP_K_THETA == 0 and layouts.AP_DT == layouts.N_AP_PAR - 1


def test_ins_layout_packs_the_state_round_trip():
    rng = np.random.default_rng(1)
    n = 3
    s = ins.InsState(rng.normal(size=n), rng.normal(size=n), rng.normal(size=n), rng.normal(size=(n, 3)),
                     rng.normal(size=(n, 3, 3)), rng.normal(size=n))
    x = ins.pack(s)
    assert x.shape == (n, layouts.NX)
    np.testing.assert_array_equal(x[:, layouts.X_H], s.h_m)
    np.testing.assert_array_equal(x[:, layouts.INS.slice("c_bn")], s.c_bn.reshape(n, 9))
    back = ins.unpack(x)
    for f in dataclasses.fields(ins.InsState):
        np.testing.assert_array_equal(getattr(back, f.name), getattr(s, f.name))


def test_reads_and_writes_layouts_cover_the_properties():
    assert layouts.N_READ == len(layouts.RAW_FIELDS) + len(layouts.GEAR_FIELDS) == layouts.READS.size
    assert layouts.READS.names[layouts.R_VT] == "velocities/vtrue-fps"
    assert layouts.READS.names[layouts.R_WOW_NOSE] == "gear/unit[0]/WOW"
    assert len(layouts.GEAR_AIRBORNE) == len(layouts.GEAR_FIELDS)
    assert layouts.WRITES.size == len(layouts.WRITTEN) and layouts.WRITTEN[layouts.WRITE_TERRAIN].startswith(
        "position/terrain")
    assert layouts.D_READ + layouts.N_READ == layouts.N_D


def test_flight_vectors_concatenate_the_components():
    assert layouts.P_AP == layouts.N_CONST + layouts.N_F_PAR
    assert layouts.P_TERRAIN == layouts.N_CONST + layouts.N_F_PAR + layouts.N_AP_PAR + layouts.N_TB_PAR + \
        layouts.N_MN_PAR
    assert layouts.S_RING == layouts.N_F_STATE + layouts.N_AP_STATE + layouts.N_TB_STATE + layouts.N_MN_STATE
