#!/usr/bin/env bash
# Issue 38's side-by-side: the default aircraft and runway with each GNSS service, the same seeds (common random
# numbers), closed loop. Usage: studies/gnss-services/run.sh RUNS OUTDIR
set -euo pipefail
runs=${1:-200}; out=${2:-gnss-services}
for s in py-pps l1ca sbas-l1 dfmc dfmc-sbas; do
  python -m approachsim evaluate "$(dirname "$0")/$s.toml" --runs "$runs" --seed 1 --workers 1 --no-report \
    --overwrite --out "$out/$s"
done
