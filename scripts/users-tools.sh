#!/usr/bin/env bash
# The users'-tools checks (issue 21): the FuseSoC core (lint, sim) and the cocotb
# testbench on the committed default, and an array set's verification kit (issue 42: its
# core's sim and sim_verilator, the cocotb array test; scripts/array-kit-check.sh), in one
# cached Python venv (scripts/py-venv.sh).
# Prints one result line; skips (exit 0, saying so) only when python3 is missing outside CI.
# (The PTU/SPC decoder's cross-check with ptufile runs as a cargo test:
# crates/scene/tests/it/tttr_crosscheck.rs.)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if ! command -v python3 >/dev/null 2>&1; then
  if [ "${TOFPROBE_REQUIRE_TOOLS:-0}" = 1 ] || { [ -n "${CI:-}" ] && [ "${CI}" != false ]; }; then
    echo "users-tools: FAILED: python3 not found, and CI requires the fusesoc and cocotb checks" >&2
    exit 1
  fi
  echo "users-tools: SKIPPED (python3 not found): fusesoc and cocotb checks did not run"
  exit 0
fi
start=$(date +%s)
"$root/scripts/fusesoc-check.sh"
"$root/scripts/cocotb-check.sh"
"$root/scripts/array-kit-check.sh"
echo "users-tools: ok (fusesoc lint+sim, cocotb, the array set's kit) in $(( $(date +%s) - start )) s"
