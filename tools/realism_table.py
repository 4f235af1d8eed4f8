"""Markdown table of the realism-defaults study (studies/realism-defaults.toml): per variant and category the FAA
1-sigma with its one-sided upper bound and the verdict, from each variant's summary.json.

    python tools/realism_table.py OUT_DIR [VARIANT ...]     # OUT_DIR/<variant>/summary.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def _f(x: float | None) -> str:
    return "--" if x is None else f"{x:.2f}"


def table(out: Path, names: list[str]) -> str:
    """The markdown table of the named variants found under out."""
    rows = ["| variant | runs (failed) | CAT I lat / vert ft | CAT II lat / vert ft | CAT III lat / vert ft | best |",
            "|---|---|---|---|---|---|"]
    for name in names:
        p = out / name / "summary.json"
        if not p.is_file():
            continue
        s = json.loads(p.read_text())
        cells = []
        for cat in ("CAT I", "CAT II", "CAT III"):
            e = s["decision_heights"][cat]
            cells.append(f"{_f(e['lateral_1sigma_ft'])} ({_f(e['lateral_1sigma_upper_ft'])}) / "
                         f"{_f(e['vertical_1sigma_ft'])} ({_f(e['vertical_1sigma_upper_ft'])}): {e['verdict']}")
        rows.append(f"| {name} | {s['runs']} ({s['failed_runs']}) | " + " | ".join(cells)
                    + f" | {s['best_category'] or 'none'} |")
    return "\n".join(rows)


def main(argv: list[str]) -> int:
    """Print the table."""
    out = Path(argv[0])
    names = argv[1:] or sorted(p.name for p in out.iterdir() if (p / "summary.json").is_file())
    print(table(out, names))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
