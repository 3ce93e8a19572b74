#!/usr/bin/env bash
# Fails when a C++ source is not laid out as .clang-format says (ctest format_clean).
# Fix with: git ls-files '*.cpp' '*.hpp' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  git ls-files -z 'solver/*.cpp' 'solver/*.hpp' 'server/*.cpp' 'server/*.hpp' 'apps/*.cpp' 'apps/*.hpp' \
    'tests/*.cpp' 'tests/*.hpp'
else  # a copy without git (an unpacked archive)
  find solver server apps tests -path '*/node_modules' -prune -o \( -name '*.cpp' -o -name '*.hpp' \) -print0
fi | xargs -0 clang-format --dry-run --Werror
