#!/usr/bin/env bash
# The grip HTTP API with curl alone: submit, follow, fetch, dismiss.
#   GRIP_URL=http://127.0.0.1:8080 bash clients/curl/examples.sh [OUT_DIR]
# Run by clients/python/tests/test_curl.py against a live server, so it cannot rot.
set -euo pipefail
URL=${GRIP_URL:-http://127.0.0.1:8080}
EXAMPLES="$(cd "$(dirname "$0")/../../schemas/examples" && pwd)"
OUT=${1:-.}
mkdir -p "$OUT"

# Submit a scene: 201, the job's path in Location, the job document in the body.
LOCATION=$(curl -sS -f -D - -o "$OUT/job.json" -X POST "$URL/v1/jobs" \
  -H 'Content-Type: application/json' --data @"$EXAMPLES/beam-on-cylinder.json" \
  | tr -d '\r' | sed -n 's/^[Ll]ocation: //p')
echo "submitted $LOCATION"

# Follow its events (SSE: replayed, then live; the stream ends after job_finished or job_failed).
curl -sS -f -N "$URL$LOCATION/events" > "$OUT/events.txt"
echo "iterations: $(grep -c '^event: iteration' "$OUT/events.txt")"
tail -n 3 "$OUT/events.txt"

# Resume after event 10 (as a browser's EventSource does after a dropped connection).
curl -sS -f -N -H 'Last-Event-ID: 10' "$URL$LOCATION/events" > "$OUT/resumed.txt"
grep -m 1 '^id:' "$OUT/resumed.txt"   # id: 11

# The job document: status, progress, timings, links.
curl -sS -f "$URL$LOCATION"; echo

# The result: JSON, or one CSV table, or the VTK files (tar with a .pvd collection).
curl -sS -f -o "$OUT/result.json" "$URL$LOCATION/result"
curl -sS -f -o "$OUT/contact_points.csv" "$URL$LOCATION/result?format=csv&table=contact_points"
curl -sS -f -o "$OUT/vtk.tar" "$URL$LOCATION/result?format=vtk"
curl -sS -f -o "$OUT/convergence.csv" "$URL$LOCATION/convergence?format=csv"
head -n 3 "$OUT/convergence.csv"
head -n 2 "$OUT/contact_points.csv"

# Errors are problem+json with a pointer per error (-f is left out to see the body).
curl -sS -X POST "$URL/v1/jobs" -H 'Content-Type: application/json' \
  --data '{"body": {"model": "timoshenko_beam"}, "steps": 0}' > "$OUT/problem.json"
cat "$OUT/problem.json"; echo

# Jobs, newest first, two per page; the `next` link carries the cursor.
curl -sS -f "$URL/v1/jobs?limit=2&status=successful"; echo

# Dismiss: cancels a queued or running job, removes a finished one.
curl -sS -f -X DELETE "$URL$LOCATION"; echo
