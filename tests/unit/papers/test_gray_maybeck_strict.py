"""Issue 43's strict reproduction rule for Tables 3-6 (papers/gray_maybeck.strict_row) on hand-made cells, and its
counts beside the direction rule (cell_counts)."""

from __future__ import annotations

import pytest

from approachsim.papers import gray_maybeck as gm


@pytest.mark.parametrize(("paper", "ours", "want"), [
    # Table 3 latitude, paper 8.9 -> 4.6 ft (48.3 %)
    ((8.9, 4.6), (12.0, 6.0), {"a": True, "b": True, "pct": True}),      # x1.35, x1.30, 50.0 % (x1.04)
    ((8.9, 4.6), (14.0, 6.0), {"a": False, "b": True, "pct": True}),     # x1.57: level a out; 57.1 % (x1.18)
    ((8.9, 4.6), (10.0, 9.0), {"a": True, "b": False, "pct": False}),    # 10 % is 4.8x below 48.3 %
    # levels on the bounds (inclusive), but the % change 1 - 3.07 / 13.35 = 77.0 % is x1.59 of 48.3 %
    ((8.9, 4.6), (8.9 * 1.5, 4.6 / 1.5), {"a": True, "b": True, "pct": False}),
    ((8.9, 4.6), (8.9, 0.1), {"a": True, "b": False, "pct": False}),     # 98.9 % > 1.5 x 48.3
    # Table 4 altitude, paper 2.6 -> 2.4 ft (7.7 %: |%| < 10, 5 points)
    ((2.6, 2.4), (2.6, 2.3), {"a": True, "b": True, "pct": True}),       # 11.5 %: 3.8 points
    ((2.6, 2.4), (2.6, 2.55), {"a": True, "b": True, "pct": False}),     # 1.9 %: 5.8 points
    ((2.6, 2.4), (2.5, 2.6), {"a": True, "b": True, "pct": False}),      # -4 %: the opposite sign
    # Table 6 altitude, paper 2.3 -> 3.6 ft (-56.5 %: an increase)
    ((2.3, 3.6), (2.0, 3.2), {"a": True, "b": True, "pct": True}),       # -60 %
    ((2.3, 3.6), (2.0, 2.0), {"a": True, "b": False, "pct": False}),     # 0 %: no sign; 2.0 < 3.6 / 1.5
])
def test_strict_row(paper, ours, want):
    got = gm.strict_row(paper[0], paper[1], ours[0], ours[1])
    assert {k: got[k] for k in ("a", "b", "pct")} == want
    assert got["reproduces"] == all(want.values())


def test_cell_counts_carry_both_rules():
    paper = gm.PAPER_TABLES["3"]
    # our levels 1.3x the paper's in both groups: the same % change, every strict cell within x1.5
    ours = {"a_ft": [1.3 * x for x in paper["a_ft"]], "b_ft": [1.3 * x for x in paper["b_ft"]],
            "pct": list(paper["pct"]), "pct_ci": [[p - 1.0, p + 1.0] for p in paper["pct"]]}
    claims = gm.table_claims(ours, paper)
    assert all(c["direction_reproduces"] for c in claims)
    assert all(c["strict"]["reproduces"] for c in claims)
    # 1.6x: the direction holds, the strict rule fails on both levels of every row
    ours16 = {**ours, "a_ft": [1.6 * x for x in paper["a_ft"]], "b_ft": [1.6 * x for x in paper["b_ft"]]}
    claims16 = gm.table_claims(ours16, paper)
    counts = gm.cell_counts({"3": {"claims": claims}, "3b": {"claims": claims16}})
    assert counts["direction_rows"] == 8 and counts["rows"] == 8
    assert counts["strict_rows"] == 4
    assert counts["strict_cells"] == 12 + 4  # all 12 of the 1.3x table; only the 4 % changes of the 1.6x one
