#!/usr/bin/env bash
# Load run: builds grip and grip_load, starts `grip serve` on a free loopback port with a fresh
# data folder, submits --jobs small jobs from --clients concurrent clients while --streams
# event streams follow jobs, checks every accepted job is successful with a complete result,
# and writes the figures with the machine, date and commit to --report (default
# bench/results/load.md).
#
#   bash scripts/load.sh [--jobs 1000] [--clients 50] [--streams 100] [--build-dir build-load]
#                        [--no-build] [--report FILE] [--append] [-- extra `grip serve` options]
#
# --append adds the run to the report instead of replacing it; `-- --streams 32` gives the
# server back its default stream cap (later options win).
#
# The server gets its default limits except --streams (32 by default, too few for the
# streams asked for): it is given the streams asked for + 28 (so that the HTTP pool, streams
# + 32, also serves the clients). A full queue answers 503 + Retry-After; the client waits
# that long, retries and counts the 503s.
set -euo pipefail

cd "$(dirname "$0")/.."
jobs=1000 clients=50 streams=100 build_dir=build-load build=1 report=bench/results/load.md append=0
serve_extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --jobs) jobs=$2; shift 2 ;;
    --clients) clients=$2; shift 2 ;;
    --streams) streams=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --report) report=$2; shift 2 ;;
    --append) append=1; shift ;;
    --) shift; serve_extra=("$@"); break ;;
    *) echo "load.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

if [ "$build" = 1 ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build_dir" --target grip grip_load -j 2
fi
grip="$build_dir/apps/grip"
load="$build_dir/tests/load/grip_load"
scene=tests/load/small-job.json

tmp=$(mktemp -d "${TMPDIR:-/tmp}/grip-load-XXXXXX")
server_pid=
cleanup() {
  if [ -n "$server_pid" ] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
  fi
  rm -rf "$tmp"
}
trap cleanup EXIT

server_streams=$((streams + 28))
# Every load client connects from 127.0.0.1: the limit per client address is raised to let
# them all in (it stands for clients on many hosts).
"$grip" serve --host 127.0.0.1 --port 0 --db "$tmp/grip.sqlite" --streams "$server_streams" \
  --per-client 1000 "${serve_extra[@]}" >"$tmp/server.log" 2>&1 &
server_pid=$!
port=
for _ in $(seq 1 600); do
  port=$(sed -n 's|.*listening on http://127\.0\.0\.1:\([0-9]*\).*|\1|p' "$tmp/server.log" | head -n 1)
  [ -n "$port" ] && break
  kill -0 "$server_pid" 2>/dev/null || { cat "$tmp/server.log" >&2; exit 1; }
  sleep 0.1
done
[ -n "$port" ] || { echo "load.sh: grip serve did not start" >&2; cat "$tmp/server.log" >&2; exit 1; }

commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)
mem=$(awk '/^MemTotal/ { printf "%.1f GiB", $2 / 1048576 }' /proc/meminfo)
os=$(. /etc/os-release && echo "$PRETTY_NAME")
mkdir -p "$(dirname "$report")"
[ "$append" = 1 ] || : >"$report"
limits=$(sed -n 's/.*grip serve: .*\(workers [0-9]* queue [0-9]* streams [0-9]* http-threads [0-9]*\).*/\1/p' \
           "$tmp/server.log")
{
  if [ "$append" = 0 ]; then echo "# Load runs (scripts/load.sh)"; fi
  echo
  echo "## $jobs jobs, $clients clients, $streams event streams; server: $limits"
  echo
  echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $commit; $os, $(nproc) cores ($cpu), $mem;"
  echo "load average $(cut -d ' ' -f 1-3 /proc/loadavg) at the start (other work on the machine shows here)."
  echo "\`bash scripts/load.sh --jobs $jobs --clients $clients --streams $streams${serve_extra[*]:+ -- ${serve_extra[*]}}\`:"
  echo "\`grip serve --streams $server_streams${serve_extra[*]:+ ${serve_extra[*]}}\` (the last option wins; other limits"
  echo "at their defaults) on a fresh SQLite data folder, \`grip_load\` on the same machine, each job"
  echo "\`$scene\`."
  echo
} >>"$report"

set +e
"$load" --port "$port" --scene "$scene" --jobs "$jobs" --clients "$clients" --streams "$streams" \
  --server-pid "$server_pid" --report "$report"
status=$?
set -e
if ! kill -0 "$server_pid" 2>/dev/null; then
  echo "load.sh: the server died during the run" >&2
  echo "- the server died during the run" >>"$report"
  status=1
fi
grep -E ' (error|critical) ' "$tmp/server.log" | head -n 20 >&2 || true
[ "$append" = 1 ] || cat >>"$report" <<'NOTE'

Submit latency: from sending the POST to its 201, for the attempt that was accepted (503
answers are counted, not timed). Iteration -> event delay: events carry no wall-clock time,
only `elapsed_ms` since their step began, so the server time of an iteration is estimated as
the job's `started` + the `seconds` of the earlier steps + `elapsed_ms`. That is never later
than the true time (`started` is stamped before the scene is read and the job row updated),
so the figure is an upper bound of the delay from the iteration to the event reaching the
client (SQLite commit, wake-up and write included). Only live events count: replayed ones
(produced before the stream was opened) are left out.
NOTE
echo "report: $report"
exit $status
