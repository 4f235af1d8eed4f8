"""Sensor fault modes of the bank (campaign/integrity_bank.py): a sub-filter's copy of the records without the baro, the
radar altimeter or one pseudolite unit (invalid and nan throughout, as an outage), the GNSS channels as before."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from approachsim.campaign.bank_modes import BARO_MODE, PSEUDOLITE_MODE, RADALT_MODE, mode_name
from approachsim.campaign.integrity_bank import bank_records, sensor_modes


@dataclass(frozen=True)
class _Gnss:
    valid: np.ndarray


@dataclass(frozen=True)
class _Baro:
    valid: np.ndarray
    h_baro_m: np.ndarray


@dataclass(frozen=True)
class _Radalt:
    valid: np.ndarray
    h_agl_m: np.ndarray


@dataclass(frozen=True)
class _Pl:
    valid: np.ndarray
    pseudorange_m: np.ndarray


def _records(copies: int, m: int = 5) -> dict:
    return {"gnss": _Gnss(np.ones((copies, m, 6), bool)), "baro": _Baro(np.ones((copies, m), bool),
                                                                         np.full((copies, m), 100.0)),
            "radalt": _Radalt(np.ones((copies, m), bool), np.full((copies, m), 50.0)),
            "pseudolite": _Pl(np.ones((copies, m, 2), bool), np.full((copies, m, 2), 1e3))}


def test_sensor_mode_codes() -> None:
    rec = _records(1)
    assert sensor_modes(rec) == [BARO_MODE, RADALT_MODE, PSEUDOLITE_MODE, PSEUDOLITE_MODE - 1]
    assert [mode_name(c) for c in (3, BARO_MODE, RADALT_MODE, PSEUDOLITE_MODE - 1)] == [
        "gnss 3", "baro", "radalt", "pseudolite 1"]
    assert -1 not in sensor_modes(rec)  # -1 means "nothing excluded" in the bank's scores


def test_each_copy_loses_exactly_its_source() -> None:
    modes = [2, BARO_MODE, RADALT_MODE, PSEUDOLITE_MODE - 1]
    out = bank_records(_records(len(modes) + 1), np.array(modes))
    g, b, r, p = out["gnss"], out["baro"], out["radalt"], out["pseudolite"]
    assert g.valid[0].all() and b.valid[0].all() and r.valid[0].all() and p.valid[0].all()  # copy 0: everything
    assert not g.valid[1, :, 2].any() and g.valid[1, :, [0, 1, 3, 4, 5]].all() and b.valid[1].all()
    assert not b.valid[2].any() and np.isnan(b.h_baro_m[2]).all() and g.valid[2].all() and r.valid[2].all()
    assert not r.valid[3].any() and np.isnan(r.h_agl_m[3]).all() and b.valid[3].all()
    assert not p.valid[4, :, 1].any() and p.valid[4, :, 0].all() and np.isnan(p.pseudorange_m[4, :, 1]).all()
    assert np.all(p.pseudorange_m[4, :, 0] == 1e3)


def test_a_mode_without_its_record_is_an_error() -> None:
    rec = _records(2)
    del rec["radalt"]
    with pytest.raises(ValueError, match="no radalt record"):
        bank_records(rec, np.array([RADALT_MODE]))
