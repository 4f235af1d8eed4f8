"""The tuning procedure's choice (tools/gray_maybeck_tuning.pick, issue 43) on hand-made sweep rows: the smallest
true error among the settings whose filter claims no less than the true error in every state."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
_spec = importlib.util.spec_from_file_location("gray_maybeck_tuning", ROOT / "tools" / "gray_maybeck_tuning.py")
tuning = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tuning)


def _row(true, sigma):
    keys = ("latitude", "longitude", "altitude", "clock_bias")
    return {"true_rms_ft": dict(zip(keys, true, strict=True)), "sigma_ft": dict(zip(keys, sigma, strict=True))}


def test_pick_is_the_best_consistent_setting():
    optimistic = _row((10, 10, 10, 10), (2, 2, 2, 2))           # the smallest true error, but the filter claims 5x less
    one_short = _row((12, 12, 12, 12), (20, 20, 11.9, 20))      # under-claims the altitude by 0.1 ft
    good = _row((13, 13, 13, 13), (14, 14, 14, 14))
    worse = _row((15, 15, 15, 12), (30, 30, 30, 30))            # sqrt(15^2 x 3 + 12^2) = 28.7 > 26.0
    assert tuning.pick([optimistic, one_short, worse, good]) is good
    assert tuning.pick([optimistic, one_short]) is None
    # equality is not optimism: sigma == true passes
    edge = _row((12, 12, 12, 12), (12, 12, 12, 12))
    assert tuning.pick([good, edge]) is edge
