#!/usr/bin/env bash
# Issue 39 acceptance campaigns: the physical baro on cold, standard and hot days at a sea-level and a 5434 ft field,
# a 10 K surface inversion, and the CAT III candidate at a 1 ns and a 3 ns pseudolite time-sync error.
#
#   PYTHONPATH=. studies/baro-days/run.sh OUT_DIR [days|cat3] [CAT3_RUNS_PER_SEED] [CAT3_SEEDS]
#
# days: the six ISA -30 / 0 / +30 x {SFO 28R, KDEN 16R-like 5434 ft} cases and the inversion, 200 closed-loop runs
# each (seed 1). cat3: the candidate at 1 ns and 3 ns in blocks of CAT3_RUNS_PER_SEED runs on seeds 1..CAT3_SEEDS
# (default 250 x 4 = 1000 runs; blocks of the two clocks interleaved, so a stopped campaign leaves both at the same
# N, paired on the same draws). studies/baro-days/table.py OUT_DIR pools the blocks and writes the table.
set -euo pipefail
out=${1:?OUT_DIR}
what=${2:-all}
per=${3:-250}
seeds=${4:-4}
here=$(cd "$(dirname "$0")" && pwd)
py=${PYTHON:-python}
$py "$here/make_profiles.py" "$out/profiles"
ev() { $py -m approachsim evaluate "$out/profiles/$1.toml" --runs "$2" --seed "$3" --workers 1 --no-report \
        --out "$out/$1-s$3" --overwrite > "$out/$1-s$3.log" 2>&1; }
if [[ $what == all || $what == days ]]; then
  for c in sea-isa+0 sea-isa-30 sea-isa+30 kden-isa+0 kden-isa-30 kden-isa+30 sea-inversion10; do
    ev "$c" 200 1
  done
fi
if [[ $what == all || $what == cat3 ]]; then
  for s in $(seq 1 "$seeds"); do
    for c in cat3-sync1ns cat3-sync3ns; do
      ev "$c" "$per" "$s"
    done
  done
fi
