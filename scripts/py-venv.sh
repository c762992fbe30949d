#!/usr/bin/env bash
# Prints the path of tofprobe's Python venv (the users'-tools checks, the Python package),
# creating it and installing scripts/py-requirements.txt only when the requirements changed
# (a stamp file holds their hash), so reruns cost a few milliseconds. The venv lives in
# $TOFPROBE_PY_VENV, default target/py-venv (cache that directory in CI).
# Exit status 3 with a message when python3 (with venv) is missing.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${TOFPROBE_PY_VENV:-$root/target/py-venv}"
req="$root/scripts/py-requirements.txt"

if ! command -v python3 >/dev/null 2>&1; then
  echo "py-venv: python3 not found" >&2
  exit 3
fi
want="$(python3 --version 2>&1) $(sha256sum "$req" | cut -d' ' -f1)"
if [ -x "$venv/bin/python" ] && [ "$(cat "$venv/.tofprobe-stamp" 2>/dev/null)" = "$want" ]; then
  echo "$venv"
  exit 0
fi
echo "py-venv: creating $venv and installing $(grep -cv '^#' "$req") packages" >&2
rm -rf "$venv"
if ! python3 -m venv "$venv" >&2; then
  echo "py-venv: python3 -m venv failed (Debian: apt-get install python3-venv)" >&2
  exit 3
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$req" >&2
echo "$want" >"$venv/.tofprobe-stamp"
echo "$venv"
