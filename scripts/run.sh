#!/usr/bin/env bash
# Builds grip and runs its main job: solve the paper's beam example and print its step table.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target grip
mkdir -p out
./build/apps/grip solve schemas/examples/beam-on-cylinder.json \
  --out out/beam-on-cylinder.result.json --events out/beam-on-cylinder.events.ndjson
