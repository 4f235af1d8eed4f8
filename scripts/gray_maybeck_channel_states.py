# Side measurement for docs/gray-maybeck/README.md: cases II and X with nav.channel_states = true (8 runs, seed 1).
import tomllib
from pathlib import Path

from approachsim.campaign.evaluation import evaluate_profile
from approachsim.papers import gray_maybeck as gm
from approachsim.profile import parse_profile

for roman in ("II", "X"):
    case = next(c for c in gm.CASES if c.roman == roman)
    path = gm.base_profile_path()
    data = tomllib.loads(path.read_text())
    for k, v in gm.case_settings(case):
        gm._set(data, k, v)
    gm._set(data, "nav.channel_states", True)
    data["name"] = f"gm-{roman}-chstates"
    prof = parse_profile(data, source=path)
    ev = evaluate_profile(prof, runs=8, seed=1, mode="closed", out_dir=Path(f"/tmp/gm_cs/{roman}"), progress=False)
    print(roman, "filter states", gm.filter_states(prof)["total"], ev.details["time_averaged_rms_ft"],
          {k: (round(v["lateral_1sigma_ft"], 2), round(v["vertical_1sigma_ft"], 2), v["verdict"])
           for k, v in ev.summary["decision_heights"].items()},
          "failed", ev.summary["failed_runs"], flush=True)
