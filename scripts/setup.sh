#!/usr/bin/env bash
# Installs every Debian package grip needs to build, test and run. Idempotent: safe to re-run.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libspdlog-dev libgtest-dev
  libcpp-httplib-dev libvalijson-dev libsqlite3-dev
  python3 python3-matplotlib
  curl
  clang libclang-rt-14-dev  # libFuzzer build of scripts/check-extended.sh
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
