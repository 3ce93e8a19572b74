#!/usr/bin/env bash
# Time from POST to 201 for a large generated mesh (the sliding block as a 200 x 200 q4
# rectangle, 40401 nodes): what the HTTP thread spends reading and checking a submission.
#   bash bench/submit_latency.sh [GRIP_BINARY] [REPEATS]    (default build/apps/grip, 9)
# Prints each time and the median; one worker solves the accepted jobs meanwhile, as in use.
set -euo pipefail
cd "$(dirname "$0")/.."
grip=${1:-build/apps/grip}
repeats=${2:-9}
scratch=$(mktemp -d)
trap 'kill "$server" 2>/dev/null; wait "$server" 2>/dev/null; rm -rf "$scratch"' EXIT
python3 - "$scratch/scene.json" <<'PY'
import json, sys
s = json.load(open("schemas/examples/sliding-block.json"))
s["body"]["mesh"]["rectangle"]["divisions"] = [200, 200]
json.dump(s, open(sys.argv[1], "w"))
PY
"$grip" serve --port 0 --db "$scratch/db.sqlite" --workers 1 >"$scratch/log" 2>&1 &
server=$!
for _ in $(seq 1 100); do grep -q "listening" "$scratch/log" 2>/dev/null && break; sleep 0.1; done
port=$(sed -n 's/.*listening on http:\/\/[^:]*:\([0-9]*\).*/\1/p' "$scratch/log" | head -n 1)
for _ in $(seq 1 "$repeats"); do
  curl -sS -o /dev/null -w '%{http_code} %{time_total}\n' -H 'Content-Type: application/json' \
    --data @"$scratch/scene.json" "http://127.0.0.1:$port/v1/jobs"
done | tee "$scratch/times"
sort -k2 -n "$scratch/times" | awk '{t[NR] = $2} END {printf "median %.3f s over %d submissions\n", t[int((NR + 1) / 2)], NR}'
