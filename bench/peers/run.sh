#!/usr/bin/env bash
# Peer comparison on the Hertz geometry: grip against GetFEM (bench/peers/compare.py), table
# in bench/results/peers.md. GetFEM comes from Debian's python3-getfem, installed here only
# (never by scripts/setup.sh: no test or build needs it).
#   bash bench/peers/run.sh [path/to/grip] [--sizes 10,20,40] [--table PATH]
set -euo pipefail
cd "$(dirname "$0")/../.."
if ! /usr/bin/python3 -c "import getfem" 2>/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends python3-getfem
fi
/usr/bin/python3 bench/peers/compare.py "${1:-build/apps/grip}" "${@:2}"
