#!/usr/bin/env bash
# Fails when a tracked C++ file is not laid out as .clang-format says (ctest format_clean).
# Fix with: git ls-files '*.cpp' '*.hpp' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
git ls-files -z 'solver/*.cpp' 'solver/*.hpp' 'server/*.cpp' 'server/*.hpp' 'apps/*.cpp' 'apps/*.hpp' \
  'tests/*.cpp' 'tests/*.hpp' | xargs -0 clang-format --dry-run --Werror
