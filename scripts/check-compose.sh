#!/usr/bin/env bash
# Checks deploy/compose.yaml for real (part of scripts/check-extended.sh): Debian's Docker
# engine and compose, a local debian:12-slim base made with debootstrap when none is there
# (Docker Hub does not answer on these machines), the grip image from the Dockerfile, then
# PostgreSQL + three replicas + HAProxy up; a job through HAProxy; one replica killed; the
# job still served and a new job solved; everything removed again.
#   bash scripts/check-compose.sh      (as root: starts and stops its own dockerd)
set -euo pipefail
# Debian's docker.io client first: another docker client earlier on PATH (e.g. in /usr/local/bin)
# may want a buildx plugin that Debian does not ship.
export PATH=/usr/bin:/usr/sbin:$PATH
cd "$(dirname "$0")/.."
scratch=${SCRATCH:-$(mktemp -d "${TMPDIR:-/tmp}/grip-compose-XXXXXX")}
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  docker.io docker-compose debootstrap iptables >/dev/null
dockerd_pid=
if ! docker info >/dev/null 2>&1; then
  nohup dockerd --data-root "$scratch/docker-data" >"$scratch/dockerd.log" 2>&1 &
  dockerd_pid=$!
  for _ in $(seq 1 60); do docker info >/dev/null 2>&1 && break; sleep 1; done
fi
compose=(docker-compose -f deploy/compose.yaml -p grip-check)
cleanup() {
  "${compose[@]}" down -v >/dev/null 2>&1 || true
  docker rm -f grip-stop-check >/dev/null 2>&1 || true
  docker volume rm grip-stop-check >/dev/null 2>&1 || true
  [ -n "$dockerd_pid" ] && kill "$dockerd_pid" && wait "$dockerd_pid" 2>/dev/null || true
}
trap cleanup EXIT

if ! docker image inspect debian:12-slim >/dev/null 2>&1; then
  mirror=$(sed -n 's/^URIs: *//p' /etc/apt/sources.list.d/*.sources | head -n 1)
  debootstrap --variant=minbase bookworm "$scratch/rootfs" "$mirror" >/dev/null
  rm -f "$scratch/rootfs/etc/apt/sources.list"
  cp /etc/apt/sources.list.d/*.sources "$scratch/rootfs/etc/apt/sources.list.d/"
  rm -rf "$scratch/rootfs/var/lib/apt/lists/"*
  tar -C "$scratch/rootfs" -c . | docker import \
    --change 'ENV PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'CMD ["bash"]' - debian:12-slim
fi
DOCKER_BUILDKIT=1 docker build -q -t grip .
"${compose[@]}" up -d --build

api=http://127.0.0.1:8080
for _ in $(seq 1 120); do curl -sf "$api/v1/ready" >/dev/null && break; sleep 1; done
curl -sf "$api/v1/ready"; echo
job=$(curl -sf -H 'Content-Type: application/json' --data @tests/load/small-job.json "$api/v1/jobs" |
      sed -n 's/.*"jobID":"\([^"]*\)".*/\1/p')
for _ in $(seq 1 60); do
  curl -sf "$api/v1/jobs/$job" | grep -q '"status":"successful"' && break; sleep 1
done
curl -sf "$api/v1/jobs/$job" | grep -q '"status":"successful"'
"${compose[@]}" kill -s KILL grip2
sleep 3
for _ in 1 2 3 4 5 6; do curl -sf "$api/v1/jobs/$job/result" >/dev/null; done  # every replica left answers
job2=$(curl -sf -H 'Content-Type: application/json' --data @tests/load/small-job.json "$api/v1/jobs" |
       sed -n 's/.*"jobID":"\([^"]*\)".*/\1/p')
for _ in $(seq 1 60); do
  curl -sf "$api/v1/jobs/$job2" | grep -q '"status":"successful"' && break; sleep 1
done
curl -sf "$api/v1/jobs/$job2" | grep -q '"status":"successful"'
echo "compose check: 3 replicas on PostgreSQL behind HAProxy; jobs solved and served with one replica killed"
"${compose[@]}" down -v >/dev/null 2>&1

# `docker stop` with a job running, five times: the image's grace (GRIP_GRACE=5) ends inside
# Docker's default 10 s, so the service exits by itself (status 0) and requeues the job, never
# SIGKILLed (137); a sixth start on the same volume runs the job to the end.
python3 - "$scratch/long-job.json" <<'PY'
import json, sys
s = json.load(open("tests/load/small-job.json"))
s["stages"][-1]["steps"] = 2000  # some 10 s of solving: longer than the grace
json.dump(s, open(sys.argv[1], "w"))
PY
one=http://127.0.0.1:18080
start() {
  docker run -d --name grip-stop-check -p 127.0.0.1:18080:8080 -v grip-stop-check:/var/lib/grip grip >/dev/null
  for _ in $(seq 1 60); do curl -sf "$one/v1/ready" >/dev/null && return; sleep 0.5; done
  echo "the container did not become ready"; exit 1
}
start
long=$(curl -sf -H 'Content-Type: application/json' --data @"$scratch/long-job.json" "$one/v1/jobs" |
       sed -n 's/.*"jobID":"\([^"]*\)".*/\1/p')
for try in 1 2 3 4 5; do
  [ "$try" = 1 ] || start
  for _ in $(seq 1 60); do curl -sf "$one/v1/jobs/$long" | grep -q '"status":"running"' && break; sleep 0.5; done
  sleep 1
  docker stop grip-stop-check >/dev/null
  code=$(docker inspect -f '{{.State.ExitCode}}' grip-stop-check)
  docker rm grip-stop-check >/dev/null
  [ "$code" = 0 ] || { echo "docker stop, try $try: exit status $code (SIGKILL: 137)"; exit 1; }
done
start
for _ in $(seq 1 120); do curl -sf "$one/v1/jobs/$long" | grep -q '"status":"successful"' && break; sleep 1; done
curl -sf "$one/v1/jobs/$long" | grep -q '"status":"successful"'
echo "docker stop during a job: 5 of 5 stops exited by themselves (status 0); the job finished after the restarts"
