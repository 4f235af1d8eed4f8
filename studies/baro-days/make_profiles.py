"""Write the baro-days acceptance profiles (issue 39) from the shipped ones, key by key, into a folder.

    python studies/baro-days/make_profiles.py OUT_DIR

Sea level: profiles/default.toml (SFO 28R, 13 ft). High field: the same profile on a Denver-like runway, KDEN 16R
(threshold position and true course approximate; elevation 5434 ft, the field of issue 39). ISA -30 / 0 / +30, the
baro uncorrected (the default); a 10 K surface inversion over 1000 ft on the sea-level ISA day; the CAT III candidate
(profiles/gbas-cat3-candidate.toml, the physical baro) at a 1 ns and a 3 ns pseudolite time-sync error.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
KDEN = {"threshold_lat_deg": "39.8956", "threshold_lon_deg": "-104.6960", "elevation_ft": "5434.0",
        "heading_true_deg": "180.0"}


def set_key(text: str, key: str, value: str) -> str:
    """The profile text with `key = ...` (first occurrence, comment dropped) set to value; the key must exist."""
    new, n = re.subn(rf"(?m)^{re.escape(key)}\s*=.*$", f"{key} = {value}", text, count=1)
    if n != 1:
        raise KeyError(key)
    return new


def add_to_section(text: str, section: str, line: str) -> str:
    """The profile text with `line` added right under the [section] header (which must exist)."""
    head = f"[{section}]"
    i = text.index(head)
    j = text.index("\n", i) + 1
    return text[:j] + line + "\n" + text[j:]


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    base = (ROOT / "profiles" / "default.toml").read_text()
    for field, changes in (("sea", {}), ("kden", KDEN)):
        for dt in (-30, 0, 30):
            t = base
            for k, v in changes.items():
                t = set_key(t, k, v)
            t = set_key(t, "isa_dev_C", f"{dt:.1f}")
            t = set_key(t, "name", f'"baro-{field}-isa{dt:+d}"')
            (out / f"{field}-isa{dt:+d}.toml").write_text(t)
    t = set_key(base, "name", '"baro-sea-inversion10"')
    t = add_to_section(t, "environment", "inversion_K = 10.0\ninversion_depth_ft = 1000.0")
    (out / "sea-inversion10.toml").write_text(t)
    cat3 = (ROOT / "profiles" / "gbas-cat3-candidate.toml").read_text()
    for ns in (1, 3):
        t = set_key(cat3, "name", f'"cat3-sync{ns}ns"')
        t = add_to_section(t, "sensors.pseudolite", f"sync_sigma_ns = {ns:.1f}")
        (out / f"cat3-sync{ns}ns.toml").write_text(t)


if __name__ == "__main__":
    main(Path(sys.argv[1]))
