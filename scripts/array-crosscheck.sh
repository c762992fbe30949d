#!/usr/bin/env bash
# Reads an array output set with numpy and pyuff (scripts/array_check.py, in the cached
# venv of scripts/py-venv.sh) and checks it against its own summary and maps.
# Usage: scripts/array-crosscheck.sh DIR [--break]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$("$root/scripts/py-venv.sh")"
exec "$venv/bin/python" "$root/scripts/array_check.py" "$@"
