#!/usr/bin/env bash
# The README's first command: install the EDA tools if missing (scripts/install-tools.sh),
# build the release binary and run the main flow on the embedded default configuration:
# scene -> bit-true model -> RTL -> golden vectors -> Verilator co-simulation -> report.
# It runs the configuration's whole frame (--full-frame: the default's 1 s, 10^7 pulses,
# 500 periods of its 20,000-entry ΣΔ ROM, ~26 s of co-simulation) so the spectrum reads
# the scene's 100 µm tone (≈ 97 µm, noise ≈ 5 µm) far above the noise; extra
# arguments are passed to `tofprobe flow` (e.g. a configuration file, --no-size).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
scripts/install-tools.sh
cargo build --release -q -p tofprobe-cli
bin="${CARGO_TARGET_DIR:-$root/target}/release/tofprobe"
"$bin" flow --out flow-out --full-frame "$@"
