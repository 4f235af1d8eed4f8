"""approachsim/memo.py: the cache of a truth's shared work is owned by its composer, keyed explicitly, bounded per
kind, and never serves one truth's entry for another; and no module of the package keeps a memo of its own."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from approachsim.memo import TruthMemo, memoized

PACKAGE = Path(__file__).resolve().parents[2] / "approachsim"


class _Truth:
    pass


def test_an_entry_is_made_once_per_key_and_kind():
    t = _Truth()
    memo = TruthMemo(t)
    made = []

    def make(v):
        def f():
            made.append(v)
            return v
        return f

    assert memo.get(t, "a", 1, make("x")) == "x"
    assert memo.get(t, "a", 1, make("y")) == "x"  # kept
    assert memo.get(t, "b", 1, make("z")) == "z"  # another kind, its own entry
    assert made == ["x", "z"]
    assert len(memo) == 2


def test_each_kind_keeps_at_most_keep_entries_oldest_dropped_first():
    t = _Truth()
    memo = TruthMemo(t)
    for k in range(5):
        memo.get(t, "a", k, lambda k=k: k, keep=3)
    assert len(memo) == 3
    assert memo.get(t, "a", 0, lambda: "again", keep=3) == "again"  # 0 was dropped
    assert memo.get(t, "a", 4, lambda: "new", keep=3) == 4  # 4 kept


def test_another_truth_is_refused_and_no_memo_computes_afresh():
    a, b = _Truth(), _Truth()
    memo = TruthMemo(a)
    with pytest.raises(ValueError, match="another truth"):
        memo.get(b, "a", 1, lambda: 1)
    calls = []
    assert memoized(None, a, "a", 1, lambda: calls.append(1) or 7) == 7
    assert memoized(None, a, "a", 1, lambda: calls.append(1) or 7) == 7
    assert len(calls) == 2


def test_an_unhashable_key_is_made_each_time_and_not_kept():
    t = _Truth()
    memo = TruthMemo(t)
    assert memo.get(t, "a", (np.zeros(2),), lambda: 1) == 1
    assert len(memo) == 0


def _module_level_mutable_caches(path: Path) -> list[str]:
    """Module-level assignments of an empty dict / list / set, or a `global` statement, in a module: the shape of a
    hidden memo (conventions item 20)."""
    tree = ast.parse(path.read_text())
    out = []
    for node in tree.body:
        value = getattr(node, "value", None)
        targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
        literal = (isinstance(value, (ast.Dict, ast.List, ast.Set)) and not getattr(value, "keys", None)
                   and not getattr(value, "elts", None))
        call = (isinstance(value, ast.Call) and isinstance(value.func, ast.Name)
                and value.func.id in ("dict", "list", "set") and not value.args and not value.keywords)
        empty = literal or call
        if empty:
            out.extend(f"{path.name}: {ast.unparse(t)}" for t in targets if t is not None)
    for node in ast.walk(tree):
        if isinstance(node, ast.Global):
            out.append(f"{path.name}: global {', '.join(node.names)}")
    return out


NOT_A_MEMO = {
    "closed_loop.py: _NO_RECS": "an empty mapping used as a read-only default, never filled",
    "evaluate.py: _PENDING": "report/evaluate.py hands one call's figures to its forked render workers (they read "
                             "the parent's memory) and clears it when the call ends: nothing outlives the call",
}
"""Module-level empty containers that are not memos, each with why."""


def test_no_module_keeps_a_memo_of_its_own():
    """Caches belong to the object that composes a campaign or study (approachsim/memo.py TruthMemo, an object's
    own attribute) or are functools.lru_cache with an explicit key: no module-level empty dict / list / set filled at
    run time, no `global` rebinding (the nine memos keyed by "the last truth" that issue 37 removed)."""
    found = [c for p in sorted(PACKAGE.rglob("*.py")) for c in _module_level_mutable_caches(p)]
    assert sorted(set(found) - set(NOT_A_MEMO)) == []
