#!/usr/bin/env bash
# The README's test command: install the package with its test extras, lint, check layering, check that
# docs/profiles.md is current, run pytest, then the profile regression baselines.
set -euo pipefail
cd "$(dirname "$0")/.."
python -m pip install --quiet -e ".[test]"
ruff check .
lint-imports
# docs/profiles.md is generated from the profile / study / aircraft parsers: fail when it is not current.
python tools/gen_profiles_doc.py --check
set +e
# pytest-xdist: one worker per core (the suite is CPU-bound, single-threaded per test); --dist loadfile keeps a
# module's tests on one worker, so a module's cached flights and campaigns are computed once; --no-loadscope-reorder
# hands the files out in collection order, which tests/conftest.py starts with the longest (xdist's own order, by
# number of tests, left the 3-minute wheel test, one test, to the end with the other worker idle)
run_pytest() {
  python -m pytest -q -n "${PYTEST_WORKERS:-auto}" --dist loadfile --no-loadscope-reorder "$@"
  status=$?
  if [ "$status" -eq 5 ]; then
    echo "pytest collected no tests: failing" >&2
    exit 1
  fi
  if [ "$status" -ne 0 ]; then
    exit "$status"
  fi
}
# the whole suite; the slowest 10 tests and their times at the end keep the CI budget visible
run_pytest --durations=10 "$@"
# CPU independence: the kernel/oracle, engine/generic and closed/open equality tests (marker "equality") once more,
# with the kernels compiled for numba's generic x86-64 target (SSE2, no FMA, another vector width) and numpy's
# runtime-dispatched SIMD loops (AVX2 / AVX-512 sin, exp, log, ...) switched off: a tolerance that holds only on this
# CPU's instruction selection fails here, not on a user's machine (docs/tolerances.md). The kernels get their own
# numba cache (the cache key includes the CPU target, approachsim/__init__.py). About 1 min of CPU on 2 cores.
npy_off=$(python -c "from numpy._core._multiarray_umath import __cpu_features__ as f, __cpu_dispatch__ as d
print(' '.join(k for k in d if f.get(k)))" 2>/dev/null || true)
echo "equality tests on the generic CPU target (NUMBA_CPU_NAME=generic, NPY_DISABLE_CPU_FEATURES='$npy_off'):"
NUMBA_CPU_NAME=generic NPY_DISABLE_CPU_FEATURES="$npy_off" run_pytest -m equality --durations=5
set -e
# Regression: the committed profile baselines (small N, fixed seeds) against their stored results.
approachsim regress
