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

# The client submits one job every 0.3 s per client (some 15 s of submissions), so that
# submissions and polls meet both faults: a replica killed at 3 s, PostgreSQL stopped from
# 5 s to 13 s.
t0=$(date +%s.%N)
since() { printf '%.1f' "$(echo "$(date +%s.%N) - $t0" | bc)"; }
python3 scripts/compose_drill.py "$api" tests/load/small-job.json 2 50 0.3 &
client=$!
sleep 3
echo "$(since) s: kill -9 grip2"
"${compose[@]}" kill -s KILL grip2 >/dev/null 2>&1
sleep 2
echo "$(since) s: PostgreSQL stopped"
"${compose[@]}" stop -t 0 postgres >/dev/null 2>&1
sleep 8
echo "$(since) s: PostgreSQL started, grip2 started"
"${compose[@]}" start postgres >/dev/null 2>&1
"${compose[@]}" start grip2 >/dev/null 2>&1
status=0
wait "$client" || status=$?
echo "$(since) s: the client ended (exit status $status)"

# Stopping: HAProxy on SIGTERM at once; the replicas within their grace. Timed from `docker
# stop` to the container's own end (its FinishedAt), without compose's own start-up.
for service in haproxy grip1 grip3; do
  id=$("${compose[@]}" ps -q "$service")
  start=$(date -u +%s.%N)
  docker stop "$id" >/dev/null
  finished=$(date -u -d "$(docker inspect -f '{{.State.FinishedAt}}' "$id")" +%s.%N)
  code=$(docker inspect -f '{{.State.ExitCode}}' "$id")
  echo "$service stopped $(printf '%.2f' "$(echo "$finished - $start" | bc)") s after SIGTERM, exit status $code"
  [ "$code" != 137 ] || status=1
  if [ "$service" = haproxy ] && [ "$(echo "$finished - $start > 1" | bc)" = 1 ]; then status=1; fi
done
"${compose[@]}" logs grip1 grip2 grip3 | grep -c 'lease lost' | sed 's/^/replicas logged "lease lost": /' || true
"${compose[@]}" logs haproxy | grep -c '"POST /v1/jobs' | sed 's/^/haproxy logged POSTs: /'
exit "$status"
