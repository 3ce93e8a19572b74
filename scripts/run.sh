#!/usr/bin/env bash
# Builds grip and starts the service on http://127.0.0.1:8080 with its SQLite file in ./data.
# Flags after the script go to `grip serve` (bash scripts/run.sh --port 9000 --workers 4);
# GRIP_* variables work too (./build/apps/grip serve --help lists them). Ctrl-C stops it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target grip
mkdir -p data
exec ./build/apps/grip serve --db "${GRIP_DB:-data/grip.sqlite}" "$@"
