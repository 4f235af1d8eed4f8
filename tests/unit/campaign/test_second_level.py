"""Second-level identification (campaign/integrity_bank.py second_level, score_category(confirm=True)): constructed
statistic sequences, and the pinned bank epochs of the misidentified ramp of docs/integrity.md (closed loop with the
online FDE, default profile, seed 1, run 44: PRN 20 (channel 18) ramped at 2 m/s from 78.6 s; the first detection's
largest identification statistic named channel 21 and the output carried the fault: 152 misleading and 62 hazardously
misleading CAT I epochs). Data: tests/unit/campaign/data/run44_bank_epochs.npz, the BankEpochs of that run
(campaign.integrity_bank.run_bank on its flown truth), written by the session that added the second look (issue 26)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from approachsim.campaign.integrity_bank import BankEpochs, score_category, second_level
from approachsim.integrity.requirements import REQUIREMENTS
from approachsim.units import FT

DATA = Path(__file__).parent / "data" / "run44_bank_epochs.npz"


def test_clear_candidate_confirmed_after_three_epochs() -> None:
    n = 12
    det = np.r_[np.zeros(5, bool), np.ones(7, bool)]
    stat = np.ones((n, 4))
    stat[:, 2] = 50.0
    mode, ok = second_level(det, stat)
    assert np.all(mode[:7] == -1) and np.all(mode[7:] == 2)
    assert ok[:5].all() and not ok[5:7].any() and ok[7:].all()


def test_nothing_detected_nothing_excluded() -> None:
    mode, ok = second_level(np.zeros(6, bool), np.random.default_rng(0).random((6, 3)))
    assert np.all(mode == -1) and ok.all()


def test_ambiguous_epochs_neither_confirm_nor_contradict() -> None:
    det = np.ones(10, bool)
    stat = np.ones((10, 3))
    stat[:, 0] = 10.0
    stat[:, 1] = 8.0  # ratio 1.25 < 2: ambiguous
    mode, ok = second_level(det, stat)
    assert np.all(mode == -1) and not ok.any()  # never protected, never excluded: the alert stays on
    stat[:4, 1] = 1.0  # clear for 4 epochs: mode 0 confirmed at epoch 2, then ambiguous epochs keep it
    mode, ok = second_level(det, stat)
    assert np.all(mode[2:] == 0) and ok[2:].all() and not ok[:2].any()


def test_a_clear_contradiction_alerts_and_keeps_the_exclusion() -> None:
    det = np.ones(12, bool)
    stat = np.ones((12, 3))
    stat[:5, 0] = 10.0
    stat[5:, 1] = 10.0
    mode, ok = second_level(det, stat)
    assert np.all(mode[2:] == 0)  # confirmed once, kept
    assert ok[2:5].all() and not ok[5:].any()  # contradicted from epoch 5 on: the alert stays on


def test_at_once_excludes_a_clear_first_detection_and_waits_on_an_ambiguous_one() -> None:
    det = np.r_[np.zeros(3, bool), np.ones(6, bool)]
    stat = np.ones((9, 3))
    stat[:, 1] = 50.0  # clear from the first detection on
    mode, ok = second_level(det, stat, at_once=True)
    assert np.all(mode[:3] == -1) and np.all(mode[3:] == 1) and ok.all()  # protected throughout: no alert
    mode2, ok2 = second_level(det, stat)  # the plain second look alerts while it confirms
    assert not ok2[3:5].any() and np.all(mode2[5:] == 1)
    stat[3, 2] = 40.0  # the first detection ambiguous (50 / 40 < 2): confirmed as without at_once
    mode, ok = second_level(det, stat, at_once=True)
    mode2, ok2 = second_level(det, stat)
    assert np.array_equal(mode, mode2) and np.array_equal(ok, ok2) and not ok[3]
    stat[3, 2] = 1.0  # clear first detection again; a later clear contradiction alerts there, the exclusion kept
    stat[6, 0] = 500.0
    mode, ok = second_level(det, stat, at_once=True)
    assert not ok[6] and mode[6] == 1


@pytest.mark.parametrize("cat, dh_ft", [("CAT I", 200.0), ("CAT II", 100.0), ("CAT III", 50.0)])
def test_run44_misidentification_becomes_an_alert(cat: str, dh_ft: float) -> None:
    ep = BankEpochs(**dict(np.load(DATA)))
    win = (ep.t_s >= ep.t_s[0] + 10.0) & (ep.height_m >= dh_ft * FT)
    first = score_category(ep, REQUIREMENTS[cat], 1.0, win)
    second = score_category(ep, REQUIREMENTS[cat], 1.0, win, confirm=True)
    at_once = score_category(ep, REQUIREMENTS[cat], 1.0, win, confirm=True, at_once=True)
    # the first detection was ambiguous (764 against 427: a ratio under 2), so at_once waits the same way
    assert np.array_equal(at_once.alert, second.alert) and np.array_equal(at_once.misleading, second.misleading)
    assert first.excluded_channel == 21 and first.misleading.sum() > 100  # the pinned failure
    assert second.excluded_channel == 18  # PRN 20, the faulted satellite
    assert second.misleading.sum() == 0 and second.hazardous.sum() == 0
    assert second.t_detect_s == first.t_detect_s  # the alert is raised at the same detection
    if cat == "CAT I":
        assert first.hazardous.sum() == 62 and second.alert.sum() <= 15  # 12 epochs while confirming
