#!/usr/bin/env bash
# The compose drill (issue 34): PostgreSQL + three replicas + HAProxy from deploy/compose.yaml;
# 2 clients x 50 small jobs through HAProxy while one replica is killed and PostgreSQL is
# stopped for 8 s; then `compose down`, timed. Passes when every job finished exactly once,
# no 5xx came without Retry-After, and the stack stopped on SIGTERM (no 137, HAProxy < 1 s).
# Needs Docker and the grip image (scripts/check-compose.sh shows how to get both; building
# the image takes some 10 minutes of two cores).
#   bash scripts/compose-drill.sh
set -euo pipefail
export PATH=/usr/bin:/usr/sbin:$PATH
cd "$(dirname "$0")/.."
compose=(docker-compose -f deploy/compose.yaml -p grip-drill)
trap '"${compose[@]}" down -v >/dev/null 2>&1 || true' EXIT
"${compose[@]}" up -d --build
api=http://127.0.0.1:8080
for _ in $(seq 1 120); do curl -sf "$api/v1/ready" >/dev/null && break; sleep 1; done

python3 scripts/compose_drill.py "$api" tests/load/small-job.json 2 50 &
client=$!
sleep 3
"${compose[@]}" kill -s KILL grip2
sleep 2
"${compose[@]}" stop -t 0 postgres
sleep 8
"${compose[@]}" start postgres
"${compose[@]}" start grip2
status=0
wait "$client" || status=$?

# Stopping: HAProxy on SIGTERM at once; the replicas within their grace.
for service in haproxy grip1 grip3; do
  start=$(date +%s.%N)
  "${compose[@]}" stop "$service" >/dev/null 2>&1
  code=$(docker inspect -f '{{.State.ExitCode}}' "$("${compose[@]}" ps -q "$service")")
  echo "$service stopped in $(echo "$(date +%s.%N) - $start" | bc) s, exit status $code"
  [ "$code" != 137 ] || status=1
done
"${compose[@]}" logs haproxy | grep -c '"POST /v1/jobs' | sed 's/^/haproxy logged POSTs: /'
exit "$status"
