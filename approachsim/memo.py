"""What the runs over one truth compute once, in a cache their composer owns and passes down.

The runs of an open-loop flight group share one flown truth (campaign/pipeline.py open_loop_group), and so do the
samples of the integrity-risk study on each of its truths (campaign/integrity_risk.py): the truth's trigonometry
and glidepath slope for scoring (evaluate/dh.py, evaluate/score.py), the reference trajectory and epoch models of
the integrity bank and of the reduced open-loop pass (campaign/bankpass.py, nav/reduced.py), and the converged
starts (nav/system.py NavSystem._prepared) are functions of that truth and of values the key names. The composer
that holds the truth makes one TruthMemo for it and hands it to every call that may reuse such work; a call given
no memo computes afresh (the same numbers: every entry is a pure function of the truth and its key). The memo
lives and dies with its composer (a task, a flown truth of a study), never in a module global, so two threads or
two campaigns never see each other's entries and a truth's identity is never mistaken for another's.

Keys are explicit and hashable: a kind (the function that makes the entry) and the values it depends on besides the
truth (a navigation system by value, array bytes, counts). Each kind keeps at most `keep` entries, oldest dropped
first (the converged starts: one per run's sky, a few hundred kB each).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any, TypeVar

T = TypeVar("T")


class TruthMemo:
    """The cache of the work shared by the runs over one truth (module docstring)."""

    __slots__ = ("truth", "_kinds")

    def __init__(self, truth: Any) -> None:
        self.truth = truth
        self._kinds: dict[str, dict[Hashable, Any]] = {}

    def get(self, truth: Any, kind: str, key: Hashable, make: Callable[[], T], keep: int = 8) -> T:
        """The entry (kind, key) of this memo's truth, made by make() the first time; `truth` must be the memo's
        own (ValueError otherwise: an entry of one truth is never served for another). An unhashable key is made
        each time (never kept)."""
        if truth is not self.truth:
            raise ValueError(f"TruthMemo.get({kind!r}): the memo belongs to another truth")
        entries = self._kinds.setdefault(kind, {})
        try:
            return entries[key]
        except KeyError:
            pass
        except TypeError:  # an unhashable key (a configuration object that is not a value): nothing to share
            return make()
        value = make()
        while len(entries) >= keep:
            entries.pop(next(iter(entries)))
        entries[key] = value
        return value

    def __len__(self) -> int:
        return sum(len(e) for e in self._kinds.values())


def memoized(memo: TruthMemo | None, truth: Any, kind: str, key: Hashable, make: Callable[[], T],
             keep: int = 8) -> T:
    """memo.get(truth, kind, key, make, keep), or make() when there is no memo."""
    if memo is None:
        return make()
    return memo.get(truth, kind, key, make, keep)
