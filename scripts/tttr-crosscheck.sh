#!/usr/bin/env bash
# Cross-checks tofprobe's time-tagged record decoder (crates/scene/src/tttr) against
# independent readers on real files: ptufile (PyPI) on every PTU file, and a transcription
# of phconvert's SPC-1xx reader on the SPC file. Compares photon, overflow and marker
# counts, the first photons (sync/time, delay, channel), the last time and the
# resolutions; exits non-zero on any difference. Also proves the comparison can fail (a
# perturbed copy of our result must be rejected).
#
# Usage: scripts/tttr-crosscheck.sh [FILE...]   (default: third_party/picoquant-tttr/*.ptu and
# crates/scene/tests/data/*); the real files' licences are beside them.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
venv="$(scripts/py-venv.sh)"

files=("$@")
if [ ${#files[@]} -eq 0 ]; then
  shopt -s nullglob
  files=(third_party/picoquant-tttr/*.ptu crates/scene/tests/data/*.ptu crates/scene/tests/data/*.spc)
fi
if [ ${#files[@]} -eq 0 ]; then
  echo "tttr-crosscheck: no files found" >&2
  exit 1
fi
# $TTTR_DUMP: an already built tttr_dump (the Rust test that runs this script passes the
# one `cargo test` built, so no cargo runs inside cargo).
dump="${TTTR_DUMP:-}"
if [ -z "$dump" ]; then
  cargo build --release --quiet -p tofprobe-scene --example tttr_dump
  dump="${CARGO_TARGET_DIR:-$root/target}/release/examples/tttr_dump"
fi
exec "$venv/bin/python" scripts/tttr_crosscheck.py "$dump" "${files[@]}"
