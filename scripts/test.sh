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
# module's tests on one worker, so a module's cached flights and campaigns are computed once
python -m pytest -q -n "${PYTEST_WORKERS:-auto}" --dist loadfile "$@"
status=$?
set -e
if [ "$status" -eq 5 ]; then
  echo "pytest collected no tests: failing" >&2
  exit 1
fi
if [ "$status" -ne 0 ]; then
  exit "$status"
fi
# Regression: the committed profile baselines (small N, fixed seeds) against their stored results.
approachsim regress
