"""`regress`'s paired test on the real pipeline: a degraded sensor is caught, a reshuffle of the draws is not.

Against the P(Y) default's baseline (tests/data/default-py-baseline.json: baselines/default.json as it was while the
default flew the P(Y) code preset, tests/data/default-py.toml; open loop, 20 runs, seed 7): the radio-altimetry
error budget -- the radar altimeter's white noise (percent_of_height, floor) and correlated error (bias, Markov) and
the filter's terrain-database error (bias, Area 4 and Area 2 sigmas), which together make the vertical error at the
decision heights -- scaled by 1.1 and by 2, and the unchanged profile on seed 8 (new, independent draws of the same
model). Measured figures are in approachsim/campaign/regress.py.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import pytest

from approachsim.campaign.evaluation import evaluate_profile
from approachsim.campaign.regress import compare_paired, per_run_errors, read_baseline
from approachsim.profile import load_profile

ROOT = Path(__file__).resolve().parents[2]
PY_DEFAULT = ROOT / "tests" / "data" / "default-py.toml"
"""The P(Y) default (tests/data/default-py.toml says why): on the SBAS L1 default the radio altimetry's share of
the vertical error is smaller and the 20-run paired test does not flag its x1.1 or x2 degradation (+3.5 % p 0.01,
+19 % p 0.04 at CAT II / III against alpha 1e-3; measured 2026-12-05), a finding about the test's power there."""

pytestmark = pytest.mark.slow


SECTIONS = {"[sensors.radalt]": ("percent_of_height", "floor_m", "bias_sigma_m", "markov_sigma_m"),
            "[nav.terrain_database]": ("bias_sigma_m", "sigma_m", "outer_sigma_m")}


def _variant(tmp_path: Path, name: str, scale: float) -> Path:
    text = PY_DEFAULT.read_text()
    for header, keys in SECTIONS.items():
        head, sep, rest = text.partition(header)
        section, nxt, tail = rest.partition("\n[")
        for key in keys:  # every sigma of the section, whatever its value
            section, k = re.subn(rf"^{key} = ([0-9.eE+-]+)",
                                 lambda m, key=key: f"{key} = {float(m.group(1)) * scale:.6g}", section, flags=re.M)
            assert k == 1, f"tests/data/default-py.toml no longer sets {header} {key} as this test expects"
        text = head + sep + section + nxt + tail
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return p


def _rerun(path: Path, doc: dict, tmp_path: Path, seed: int | None = None):
    # the test judges the per-run accuracy pairs; the integrity bank (a third of the open-loop cost) is left out
    prof = load_profile(path)
    prof = replace(prof, evaluation=replace(prof.evaluation, integrity=()))
    ev = evaluate_profile(prof, runs=doc["runs"], seed=doc["seed"] if seed is None else seed, mode=doc["mode"],
                          out_dir=tmp_path / f"o-{path.stem}-{seed}", workers=2, progress=False)
    return compare_paired(doc, ev.summary, per_run_errors(ev.results))


def _flagged(diffs) -> set[str]:
    return {d.field.split(" ")[0] + " " + d.field.split(" ")[1] for d in diffs if d.regression}


def test_degraded_radar_altimeter_is_caught_and_a_reshuffle_is_not(tmp_path):
    doc = read_baseline(ROOT / "tests" / "data" / "default-py-baseline.json")
    assert doc["runs"] >= 20 and doc["mode"] == "open" and "per_run" in doc
    vertical = {f"CAT {c}.vertical_1sigma_ft" for c in ("I", "II", "III")}
    # 10 %: the vertical 1-sigma moves at every decision height; flagged at CAT II and III (+5.4 %, p = 8.8e-5;
    # +5.2 %, p = 3.9e-6). CAT I: +5.4 %, p = 0.0007, flagged with the baseline regenerated for the baro loop's
    # held-sample fix (docs/baro-loop-hold-bias.md) but missed (+4.0 %, p = 0.0013) with the one before: too close to
    # alpha = 1e-3 to assert. A finding about the test's power at CAT I, not a tolerance
    assert vertical - {"CAT I.vertical_1sigma_ft"} <= _flagged(_rerun(_variant(tmp_path, "radalt-1.1", 1.1), doc,
                                                                      tmp_path))
    # 2x: caught, and the lateral figures (GPS) are untouched. Which figure catches it depends on the baseline's
    # realization: the filter re-weights the doubled altimetry against GPS and baro run by run, so the change is not
    # uniform. With the baseline of issue 39's filter changes the vertical 1-sigma moves +31.0 / +34.9 / +31.8 %
    # (CAT I / II / III) at p = 0.0041 / 0.0012 / 0.0013, all just missed at alpha = 1e-3, and CAT II's verdict
    # (fails -> indeterminate) flags it; with the baro loop's held-sample fix CAT III was flagged (+33.0 %,
    # p = 0.00075) and CAT I / II missed (p = 0.004 / 0.0016): findings about the paired test's power at 20 runs,
    # approachsim/campaign/regress.py
    d2 = _rerun(_variant(tmp_path, "radalt-2", 2.0), doc, tmp_path)
    assert _flagged(d2) and not any("lateral" in f for f in _flagged(d2))
    # the same model on other random numbers: its 1-sigma figures move by tens of per cent, nothing is flagged
    reshuffled = _rerun(PY_DEFAULT, doc, tmp_path, seed=doc["seed"] + 1)
    moved = [d for d in reshuffled if "paired" in d.field and d.old != d.new]
    assert moved and not any(d.regression for d in reshuffled if "paired" in d.field)
