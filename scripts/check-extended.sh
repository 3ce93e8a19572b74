#!/usr/bin/env bash
# Extended checks, slower than scripts/test.sh and each in a build directory of its own:
#   1. build-asan: everything built with AddressSanitizer + UndefinedBehaviorSanitizer
#      (GRIP_SANITIZE=ON, gcc); the unit and integration tests run under it (the integration
#      tests start the sanitized `grip`).
#   2. build-fuzz: clang + libFuzzer (GRIP_FUZZ=ON); the `fuzz` label fuzzes the scene reader
#      for GRIP_FUZZ_SECONDS (default 60) and replays tests/fuzz/regressions.
#   3. the `hard_slow` label (slow hard-case tests), in build-asan.
#   4. deploy/compose.yaml in Docker (scripts/check-compose.sh).
# Usage: bash scripts/check-extended.sh [GRIP_FUZZ_SECONDS]. Exit status non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(( $(nproc) < 2 ? $(nproc) : 2 ))
fuzz_seconds=${1:-60}
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

echo "== ASan + UBSan: unit and integration tests (build-asan)"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGRIP_SANITIZE=ON
cmake --build build-asan -j "$jobs" --target grip grip_unit_tests grip_integration_tests
ctest --test-dir build-asan -L 'unit|integration' --output-on-failure -j "$jobs" --timeout 900

echo "== libFuzzer: scene reader (build-fuzz, ${fuzz_seconds} s)"
# -O1 with assertions on (no NDEBUG): Eigen's index checks count as findings too.
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
  -DGRIP_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ -DGRIP_FUZZ_SECONDS="$fuzz_seconds"
cmake --build build-fuzz -j "$jobs" --target grip_fuzz_scene
ctest --test-dir build-fuzz -L fuzz --output-on-failure

# ---- hard_slow: slow hard-case tests (tests/hard, registered for configuration "slow" only),
# under the sanitizers too.
# Builds the remaining targets of build-asan; a label that matches no test runs nothing.
echo "== hard_slow tests (build-asan)"
cmake --build build-asan -j "$jobs"
ctest --test-dir build-asan -C slow -L hard_slow --output-on-failure --timeout 3600

# ---- deploy/compose.yaml: PostgreSQL, three replicas and HAProxy in Docker (images built
# FROM a local debian:12-slim made with debootstrap when Docker Hub does not answer).
echo "== compose (deploy/compose.yaml)"
bash scripts/check-compose.sh
