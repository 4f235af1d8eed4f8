"""The CAT III candidate on a cold day (docs/cat3.md, docs/baro.md).

At ISA -30 the barometric altitude reads low by about dT / T of the height above the field (cold-is-low,
sensors/atmosphere.py): some 100 ft at 1000 ft above the field, 5 ft at 50 ft. The candidate carries the default
physical baro (issue 39, docs/baro.md): the filter's bias and scale-factor states take the day's temperature error,
so the CAT III vertical on a cold day stays within 1.6x of the ISA day's (issue 39's acceptance) and under 1.5 ft.
(Until issue 39 the candidate hid the error behind a 100 ft / 1 h baro bias in truth and filter, which this test
then pinned.) Finding: on the candidate the scale-factor state alone is not what keeps it: without it
(temperature_scale_sigma = 0) the 6 runs gave 0.98 ft against 1.05 ft with it: at 50 ft GBAS, the pseudolites and
the radar altimeter carry the vertical and the bias state absorbs the rest. Open loop, one flown truth per group,
integrity bank off (the accuracy is what is judged here). Measured, 6 runs, seed 1: 1.05 ft at ISA -30, 0.88 ft on
the ISA day (1.19x).
"""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import pytest

from approachsim.campaign.evaluation import evaluate_profile
from approachsim.profile import parse_profile

ROOT = Path(__file__).resolve().parents[2]
CANDIDATE = ROOT / "profiles" / "gbas-cat3-candidate.toml"

pytestmark = pytest.mark.slow


def _vertical_ft(tmp_path: Path, name: str, isa_dev_c: float) -> float:
    data = tomllib.loads(CANDIDATE.read_text(encoding="utf-8"))
    assert "bias_sigma_m" not in data.get("sensors", {}).get("baro", {})  # no 100 ft sponge
    data["environment"]["isa_dev_C"] = isa_dev_c
    prof = parse_profile(data, source=CANDIDATE)
    prof = replace(prof, evaluation=replace(prof.evaluation, integrity=()))
    ev = evaluate_profile(prof, runs=6, seed=1, mode="open", out_dir=tmp_path / name, workers=2, progress=False)
    assert ev.summary["failed_runs"] == 0
    return float(ev.summary["decision_heights"]["CAT III"]["vertical_1sigma_ft"])


def test_the_physical_baro_keeps_cat3_vertical_on_a_cold_day(tmp_path):
    cold = _vertical_ft(tmp_path, "cold", -30.0)
    isa = _vertical_ft(tmp_path, "isa", 0.0)
    print(f"CAT III vertical 1-sigma, 6 runs, same seeds: {cold:.2f} ft at ISA -30, {isa:.2f} ft on the ISA day")
    assert cold < 1.5, cold  # CAT III limit 1.0 ft; 6 runs' RMS of a ~0.9-1.0 ft population
    assert cold < 1.6 * isa, (cold, isa)  # issue 39's acceptance: within 1.6x of the ISA day
