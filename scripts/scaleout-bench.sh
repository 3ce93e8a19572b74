#!/usr/bin/env bash
# Scale-out benchmark: jobs per second and submit-to-finish latency (p50 / p99) of the same
# load with 1, 2 and 3 `grip serve` replicas on one throwaway PostgreSQL cluster behind
# HAProxy, then one replica on SQLite for comparison; and what the database costs per job
# (queries and bytes counted by the replicas, commits and rows counted by PostgreSQL).
# Writes bench/results/scaleout.md (or --report FILE).
#
#   bash scripts/scaleout-bench.sh [--jobs 400] [--clients 20] [--workers 1] [--build-dir build]
#                                  [--no-build] [--report FILE] [--study N]
#
# --study N: instead, one study of N jobs (the paper's beam swept over its end load) posted
# through HAProxy to 1 and to 3 replicas: the study's wall time against its jobs' summed solve
# times, and how many jobs each replica ran (default report bench/results/study-scaleout.md).
#
# Latency is the job document's `finished` - `created` (both stamped by the service; one
# clock). Throughput: jobs / (last finished - first created).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=400 clients=20 workers=1 build_dir=build build=1 report=bench/results/scaleout.md study=0
while [ $# -gt 0 ]; do
  case "$1" in
    --jobs) jobs=$2; shift 2 ;;
    --clients) clients=$2; shift 2 ;;
    --workers) workers=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --report) report=$2; shift 2 ;;
    --study) study=$2; shift 2
      [ "$report" = bench/results/scaleout.md ] && report=bench/results/study-scaleout.md ;;
    *) echo "scaleout-bench.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
if [ "$build" = 1 ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build_dir" --target grip grip_load -j 2
fi
grip="$(pwd)/$build_dir/apps/grip"
load="$(pwd)/$build_dir/tests/load/grip_load"
scene=tests/load/small-job.json
pgbin=$(ls -d /usr/lib/postgresql/*/bin | sort -V | tail -n 1)
py=/usr/bin/python3

tmp=$(mktemp -d "${TMPDIR:-/tmp}/grip-scaleout-XXXXXX")
as_user=()
if [ "$(id -u)" = 0 ]; then as_user=(runuser -u postgres --); chown postgres "$tmp"; fi
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  "${as_user[@]}" "$pgbin/pg_ctl" -D "$tmp/pg" -m fast -w stop >/dev/null 2>&1 || true
  rm -rf "$tmp"
}
trap cleanup EXIT

free_port() { $py -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
pgport=$(free_port)
"${as_user[@]}" "$pgbin/initdb" -D "$tmp/pg" -U grip -A trust -E UTF8 >/dev/null
"${as_user[@]}" "$pgbin/pg_ctl" -D "$tmp/pg" -l "$tmp/pg.log" -w \
  -o "-p $pgport -k $tmp -c listen_addresses=127.0.0.1 -c max_connections=200" start >/dev/null
psql() { "$pgbin/psql" -h 127.0.0.1 -p "$pgport" -U grip -At "$@"; }

metric() { # port name -> value
  curl -s "http://127.0.0.1:$1/v1/metrics" | sed -n "s/^$2 //p"
}
wait_listening() { # log -> port
  for _ in $(seq 1 600); do
    p=$(sed -n 's|.*listening on http://127\.0\.0\.1:\([0-9]*\).*|\1|p' "$1" | head -n 1)
    [ -n "$p" ] && { echo "$p"; return; }
    sleep 0.1
  done
  echo "scaleout-bench.sh: grip serve did not start" >&2; cat "$1" >&2; exit 1
}

rows=()
start_replicas() { # label replicas db -> ports, run_pids, lbport, lb
  local label=$1 n=$2 kind=$3 db
  ports=() run_pids=()
  if [ "$kind" = postgresql ]; then
    psql -d postgres -c "DROP DATABASE IF EXISTS bench" -c "CREATE DATABASE bench" >/dev/null
    db="postgresql://grip@127.0.0.1:$pgport/bench"
  else
    db="$tmp/sqlite-$n/grip.sqlite"
  fi
  for i in $(seq 1 "$n"); do
    "$grip" serve --port 0 --db "$db" --workers "$workers" --replica "r$i" --queue 100000 \
      >"$tmp/$label-r$i.log" 2>&1 &
    run_pids+=($!); pids+=($!)
    ports+=("$(wait_listening "$tmp/$label-r$i.log")")
  done
  lbport=$(free_port)
  {
    printf 'global\n  maxconn 4000\ndefaults\n  mode http\n  timeout connect 2s\n  timeout client 300s\n'
    printf '  timeout server 300s\nlisten grip\n  bind 127.0.0.1:%s\n  balance roundrobin\n' "$lbport"
    printf '  option httpchk GET /v1/ready\n'
    for i in "${!ports[@]}"; do printf '  server r%s 127.0.0.1:%s check inter 1s\n' "$i" "${ports[$i]}"; done
  } >"$tmp/$label.cfg"
  haproxy -db -f "$tmp/$label.cfg" >"$tmp/$label-haproxy.log" 2>&1 &
  lb=$!; pids+=($lb)
  sleep 1
}

stop_replicas() {
  kill -TERM "$lb" "${run_pids[@]}" 2>/dev/null || true
  wait "$lb" "${run_pids[@]}" 2>/dev/null || true
}

run() { # label replicas db
  local label=$1 n=$2 kind=$3
  start_replicas "$label" "$n" "$kind"
  local commits0=0 rows0=0
  if [ "$kind" = postgresql ]; then
    psql -d bench -c "SELECT pg_stat_reset()" >/dev/null
    sleep 0.6  # the statistics collector's reset takes effect
  fi
  "$load" --port "$lbport" --scene "$scene" --jobs "$jobs" --clients "$clients" --streams 0 \
    >"$tmp/$label-load.txt" 2>&1 || { cat "$tmp/$label-load.txt" >&2; exit 1; }
  local trips=0 bytes=0 t b
  for p in "${ports[@]}"; do
    t=$(metric "$p" grip_db_round_trips_total); b=$(metric "$p" grip_db_bytes_total)
    trips=$((trips + ${t:-0})); bytes=$((bytes + ${b:-0}))
  done
  local pgstats="- - -"
  if [ "$kind" = postgresql ]; then
    sleep 0.6
    pgstats=$(psql -d bench -F ' ' -c "SELECT xact_commit, tup_inserted + tup_updated + tup_deleted, \
      pg_database_size('bench') FROM pg_stat_database WHERE datname = 'bench'")
  fi
  local stats
  stats=$(curl -s "http://127.0.0.1:${ports[0]}/v1/jobs?limit=1000&status=successful" | $py -c '
import json, sys, datetime as d
jobs = json.load(sys.stdin)["jobs"]
t = lambda s: d.datetime.strptime(s, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()
lat = sorted(t(j["finished"]) - t(j["created"]) for j in jobs)
span = max(t(j["finished"]) for j in jobs) - min(t(j["created"]) for j in jobs)
q = lambda p: lat[min(len(lat) - 1, int(p * len(lat)))]
print(len(jobs), "%.1f" % (len(jobs) / span), "%.2f" % q(0.5), "%.2f" % q(0.99))')
  read -r done_jobs jps p50 p99 <<<"$stats"
  read -r commits changed dbsize <<<"$pgstats"
  local per_q="-" per_b="-" per_c="-" per_r="-"
  if [ "$kind" = postgresql ]; then
    per_q=$($py -c "print('%.1f' % ($trips / $done_jobs))")
    per_b=$($py -c "print('%.1f' % ($bytes / $done_jobs / 1024))")
    per_c=$($py -c "print('%.1f' % ($commits / $done_jobs))")
    per_r=$($py -c "print('%.1f' % ($changed / $done_jobs))")
  fi
  rows+=("| $label | $n | $done_jobs | $jps | $p50 | $p99 | $per_q | $per_b | $per_c | $per_r |")
  stop_replicas
}

# One study of $study variants of the paper's beam (its end load swept from 100 to 600 kgf) posted
# through HAProxy; the study's wall time (post to successful) against its jobs' summed solve
# times (each job's finished - started), and the jobs each replica ran.
run_study() { # label replicas
  local label=$1 n=$2
  start_replicas "$label" "$n" postgresql
  local row
  row=$($py - "$lbport" "$study" "$n" <<'PY'
import json, sys, time, urllib.request, datetime as d
port, count, replicas = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
base = "http://127.0.0.1:%s" % port
scene = json.load(open("schemas/examples/beam-on-cylinder.json"))
scene["outputs"] = [{"name": "tip_w", "kind": "displacement", "node": 40, "component": "y"}]
plan = {"scene": scene, "sweep": [{"pointer": "/body/loads/0/force/1",
                                   "range": {"from": -100, "to": -600, "count": count}}]}
def call(path, body=None):
    req = urllib.request.Request(base + path, data=body and json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json"})
    return json.load(urllib.request.urlopen(req, timeout=60))
t0 = time.monotonic()
study = call("/v1/studies", plan)
while study.get("status") not in ("successful", "failed"):
    time.sleep(0.2)
    study = call("/v1/studies/" + study["id"])
wall = time.monotonic() - t0
t = lambda s: d.datetime.strptime(s, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()
jobs = [call("/v1/jobs/" + level["job"]) for level in study["levels"]]
solve = sum(t(j["finished"]) - t(j["started"]) for j in jobs)
per = {}
for j in jobs:
    per[j["replica"]] = per.get(j["replica"], 0) + 1
print("| %d | %s | %d | %.2f | %.2f | %.2f | %s |" % (replicas, study["status"], len(jobs), wall, solve,
      wall / solve, ", ".join("%s %d" % kv for kv in sorted(per.items()))))
PY
)
  rows+=("$row")
  stop_replicas
}

load0=$(cut -d ' ' -f 1-3 /proc/loadavg)
if [ "$study" -gt 0 ]; then
  run_study "study-1" 1
  run_study "study-3" 3
  commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
  {
    echo "# A study through HAProxy: 1 and 3 replicas (scripts/scaleout-bench.sh --study $study)"
    echo
    echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $commit; $(nproc) cores; load average $load0 before,"
    echo "$(cut -d ' ' -f 1-3 /proc/loadavg) after. $study variants of the paper's beam (end load -100 to -600 kgf),"
    echo "one PostgreSQL database, each replica \`--workers $workers\`."
    echo
    echo "| replicas | status | jobs | study wall s | jobs' solve s (summed) | wall / summed | jobs per replica |"
    echo "|---|---|---|---|---|---|---|"
    printf '%s\n' "${rows[@]}"
  } >"$report"
  cat "$report"
  exit 0
fi
run "postgresql, 1 replica" 1 postgresql
run "postgresql, 2 replicas" 2 postgresql
run "postgresql, 3 replicas" 3 postgresql
run "sqlite, 1 process" 1 sqlite
load1=$(cut -d ' ' -f 1-3 /proc/loadavg)

commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)
mkdir -p "$(dirname "$report")"
{
  echo "# Scale-out (scripts/scaleout-bench.sh)"
  echo
  echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $commit; $(. /etc/os-release && echo "$PRETTY_NAME"), $(nproc) cores ($cpu);"
  echo "load average $load0 before, $load1 after (other sessions' builds and tests share the machine)."
  echo "Each run: $jobs jobs of \`$scene\` from $clients clients (\`grip_load\`, no streams) through"
  echo "HAProxy (round robin, health checks on /v1/ready); each replica \`--workers $workers\`; PostgreSQL"
  echo "$("$pgbin/postgres" --version | sed 's/.* //') on the same machine (default settings, fsync on); one fresh database per run."
  echo
  echo "| store | replicas | jobs | jobs/s | p50 s | p99 s | queries/job | KiB/job | commits/job | rows written/job |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
  echo
  echo "Latency: submit to finish (the job's \`finished\` - \`created\`), queueing included: all"
  echo "jobs are submitted within about a second, so the later ones wait for the earlier."
  echo "Queries and KiB per job: counted by the replicas' store (every round trip: claims that"
  echo "found nothing, lease renewals, event batches, stream and document reads included; bytes"
  echo "are SQL text, parameters and result values). Commits and rows per job: PostgreSQL's"
  echo "pg_stat_database for the run's database."
} >"$report"
cat "$report"
