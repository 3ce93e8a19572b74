#!/usr/bin/env bash
# Installs every Debian package grip needs to build, test and run. Idempotent: safe to re-run.
#   bash scripts/setup.sh             everything (build, tests, plots, fuzzing, scale-out tests)
#   bash scripts/setup.sh --service   only what building `grip` needs (the Dockerfile's build stage)
set -euo pipefail
service=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libspdlog-dev libgtest-dev
  libcpp-httplib-dev libvalijson-dev libsqlite3-dev
  libpq-dev  # the shared job store (grip serve --db postgresql://...)
  zlib1g-dev  # results stored gzip-compressed by earlier versions (read still)
  libzstd-dev  # results stored zstd-compressed
  libssl-dev  # SHA-256 (libcrypto): uploaded meshes' content-addressed ids
  libsuitesparse-dev  # CHOLMOD: sparse Cholesky of symmetric tangents; UMFPACK: LU of large contact zones' saddle-point systems
)
extras=(
  python3 python3-matplotlib
  python3-venv python3-setuptools python3-wheel  # pip install ./clients/python, no index
  curl
  chromium  # headless, for the browser test (tests/browser)
  clang libclang-rt-14-dev  # libFuzzer build of scripts/check-extended.sh
  clang-format              # the layout check (ctest format_clean, scripts/check-format.sh)
  postgresql                # store contract and scale-out tests start a throwaway cluster
  haproxy                   # the load balancer of deploy/ and of the scale-out test
)
packages=("${service[@]}")
if [ "${1:-}" != "--service" ]; then
  packages+=("${extras[@]}")
  # Node.js and npm run the browser test's driver; an installed Node.js with its own npm will do.
  command -v npm > /dev/null || packages+=(nodejs npm)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

[ "${1:-}" = "--service" ] && exit 0
# The browser test's driver, puppeteer-core, at the versions pinned in its package-lock.json;
# no browser is downloaded (the test uses Debian's chromium).
browser_tests="$(cd "$(dirname "$0")/.." && pwd)/tests/browser"
if [ -f "$browser_tests/package-lock.json" ] &&
   { [ ! -f "$browser_tests/node_modules/.package-lock.json" ] ||
     [ "$browser_tests/package-lock.json" -nt "$browser_tests/node_modules/.package-lock.json" ]; }; then
  (cd "$browser_tests" && npm ci --no-audit --no-fund --ignore-scripts --loglevel=error)
fi
