#!/usr/bin/env bash
# Issue 39 acceptance campaigns: the physical baro on cold, standard and hot days at a sea-level and a 5434 ft field,
# a 10 K surface inversion, and the CAT III candidate at a 1 ns and a 3 ns pseudolite time-sync error.
#
#   PYTHONPATH=. studies/baro-days/run.sh OUT_DIR days|cat3 [RUNS_PER_BLOCK] [BLOCKS]
#
# Each case runs in blocks of RUNS_PER_BLOCK closed-loop runs on seeds 1..BLOCKS, the cases taken in turn block by
# block, so that a campaign stopped at a deadline leaves every case at about the same N (and the two clocks of the
# CAT III candidate paired on the same draws). days: the six ISA -30 / 0 / +30 x {SFO 28R, KDEN 16R-like 5434 ft}
# cases and the 10 K inversion (issue 39: 200 runs each, e.g. 50 x 4); cat3: the candidate at 1 ns and 3 ns
# (1000 runs each, e.g. 50 x 20). studies/baro-days/table.py OUT_DIR pools the blocks (a stopped block's finished
# runs included) and writes the table.
set -euo pipefail
out=${1:?OUT_DIR}
what=${2:?days|cat3}
per=${3:-50}
seeds=${4:-4}
here=$(cd "$(dirname "$0")" && pwd)
py=${PYTHON:-python}
$py "$here/make_profiles.py" "$out/profiles"
ev() { $py -m approachsim evaluate "$out/profiles/$1.toml" --runs "$2" --seed "$3" --workers 1 --no-report \
        --out "$out/$1-s$3" --overwrite > "$out/$1-s$3.log" 2>&1; }
case $what in
  days) cases="sea-isa+0 sea-isa-30 sea-isa+30 kden-isa+0 kden-isa-30 kden-isa+30 sea-inversion10" ;;
  cat3) cases="cat3-sync1ns cat3-sync3ns" ;;
  *) echo "days or cat3" >&2; exit 2 ;;
esac
for s in $(seq 1 "$seeds"); do
  for c in $cases; do
    ev "$c" "$per" "$s"
  done
done
