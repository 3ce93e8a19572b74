#!/usr/bin/env bash
# Builds grip_bench, runs the contact strategy benchmark and draws its plots and table:
#   bench/results/strategies.csv, scenes.csv, machine.txt        (grip_bench)
#   bench/results/error_vs_time_<scene>.png, iterations_vs_tolerance.png, strategies.md
#                                                                 (scripts/bench_plots.py)
# The full matrix takes about half an hour on two quiet cores. Arguments go to grip_bench:
#   scripts/bench.sh --quick --out /tmp/bench    a smoke run in under a minute
#   scripts/bench.sh --scenes beam --levels 1    one scene, the middle mesh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target grip_bench
out=bench/results
args=("$@")
for ((i = 0; i + 1 < ${#args[@]}; ++i)); do
  [ "${args[$i]}" = "--out" ] && out=${args[$((i + 1))]}
done
label="commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
git diff --quiet HEAD -- solver 2>/dev/null || label+=" with uncommitted changes in solver/"
# Two workers, one run per core; --jobs 1 after these arguments overrides.
./build/tests/bench/grip_bench --jobs 2 --out "$out" --label "$label" "$@"
/usr/bin/python3 scripts/bench_plots.py "$out"
