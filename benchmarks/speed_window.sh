#!/usr/bin/env bash
# Issue 26's speed table in one window: two checkouts of approachsim (e.g. `git worktree add /tmp/before fa0a581`)
# measured alternately by the same commands, each warmed first, BLAS one thread. Prints the closed-loop / raw-JSBSim
# ratios, two passes of 1000 open-loop runs with the integrity bank, and one without, for each.
#
#     bash benchmarks/speed_window.sh BEFORE_DIR AFTER_DIR [RUNS]
#
# Run it with nothing else on the machine; it prints the load average at the start and the end.
set -u
before=${1:?usage: speed_window.sh BEFORE_DIR AFTER_DIR [RUNS]}
after=${2:?usage: speed_window.sh BEFORE_DIR AFTER_DIR [RUNS]}
runs=${3:-1000}
export OPENBLAS_NUM_THREADS=1
run() { local dir=$1; shift; (cd "$dir" && PYTHONPATH="$dir" python benchmarks/bench_compiled.py "$@"); }
for d in "$before" "$after"; do
  echo "== $d: $(git -C "$d" log --oneline -1 | cut -c1-60)"
done
echo "== warm $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"
for d in "$before" "$after"; do run "$d" scaling --ns 25 > /dev/null 2>&1; done
echo "== ratios $(date -u +%H:%M:%S)"
for d in "$before" "$after"; do echo "-- $d"; run "$d" ratios --repeat 5 2>&1 | tail -10; done
echo "== $runs open-loop runs with the integrity bank $(date -u +%H:%M:%S)"
for pass in 1 2; do
  for d in "$before" "$after"; do echo "-- $d (pass $pass)"; run "$d" scaling --ns "$runs" 2>&1 | tail -1; done
done
echo "== accuracy only"
for d in "$after" "$before"; do echo "-- $d"; run "$d" scaling --ns "$runs" --accuracy-only 2>&1 | tail -1; done
echo "== end $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"
