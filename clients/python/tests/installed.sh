#!/usr/bin/env bash
# The client tests once against the installed package: a throwaway venv, `pip install` of a
# copy of clients/python with no index and no build isolation (setuptools, wheel and
# matplotlib are Debian's python3-setuptools, python3-wheel and python3-matplotlib, seen
# through --system-site-packages), then the client, command-line and plot tests with that
# venv's python: `grip_client` imported from its site-packages, the command line run as the
# installed `grip-client` script.
set -euo pipefail
tests="$(cd "$(dirname "$0")" && pwd)"
package="$(dirname "$tests")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 -m venv --system-site-packages "$tmp/venv"
mkdir "$tmp/src"
cp -r "$package/pyproject.toml" "$package/README.md" "$package/grip_client" "$tmp/src/"
"$tmp/venv/bin/pip" install --no-build-isolation --no-index --no-deps --quiet "$tmp/src"
"$tmp/venv/bin/grip-client" --help | grep -q "^usage: grip-client"
cd "$tests"  # the package's parent folder is not on the path: only the installed copy is
GRIP_CLIENT_INSTALLED=1 PYTHONDONTWRITEBYTECODE=1 \
  "$tmp/venv/bin/python" -m unittest -v test_client test_cli test_plots
