"""Suite-wide pytest hooks: the longest test files are handed out first.

CI runs the suite on two pytest-xdist workers with `--dist loadfile --no-loadscope-reorder` (scripts/test.sh): a
file's tests go to one worker, files in collection order (xdist's default orders them by number of tests, which put
the one-test wheel install file, about 3 min, last with the other worker idle). Longest first is the classic greedy
schedule (within 4/3 of the best): the suite's wall on a warm numba cache went from 576 s to 479 s on 2 cores
(2026-12-03), the CPU the same. The order of the other files, and every test's outcome, is unchanged. The list is a
scheduling hint measured on a warm cache (`pytest -n 2 --durations=0`, summed per file): a stale entry costs minutes
of CI, never a result.
"""

from __future__ import annotations

import pytest

LONGEST_FIRST = (
    "tests/integration/test_wheel_install.py",  # ~170 s (a fresh install compiles its kernels)
    "tests/integration/test_nav_consistency_pooled.py",  # ~100 s (12 flights, 1440 navigation runs)
    "tests/integration/test_nav_adaptive_damping.py",  # ~90 s
    "tests/unit/nav/test_carrier_engine.py",  # ~40 s each below
    "tests/unit/nav/test_fde.py",
    "tests/unit/nav/test_carrier_nav.py",
    "tests/unit/nav/test_closed_loop_epoch.py",
    "tests/integration/test_flight_envelope.py",
    "tests/integration/test_evaluate_cli.py",
    "tests/unit/papers/test_chernodarov.py",
    "tests/unit/evaluate/test_touchdown.py",
    "tests/unit/papers/test_sokolovic.py",
    "tests/integration/test_nav_consistency_jsbsim.py",
    "tests/unit/nav/test_filter_contract.py",
    "tests/unit/nav/test_epoch_engine.py",  # the longest of the generic-CPU equality pass, with the ones above
    "tests/unit/campaign/test_bankpass_carrier.py",
    "tests/unit/nav/test_epoch_kernels.py",
)


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items: list[pytest.Item]) -> None:
    """Stable reorder: the files of LONGEST_FIRST in its order, then every other file as collected."""
    rank = {f: i for i, f in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda it: rank.get(it.nodeid.split("::", 1)[0], len(rank)))
