#!/usr/bin/env bash
# Installs the EDA tools tofprobe drives (Verilator, Icarus Verilog, yosys, OpenSTA and the
# OSU 0.18 um liberty; for `tofprobe layout`: qflow with graywolf and qrouter, magic,
# netgen-lvs and klayout) and rsvg-convert (the figures' rendering check) from Debian's
# packages, only where one is missing. Idempotent: a
# machine that already has them is left untouched, so CI and the main flow can call it on
# every run.
set -euo pipefail

need=()
command -v verilator >/dev/null 2>&1 || need+=(verilator)
command -v iverilog  >/dev/null 2>&1 || need+=(iverilog)
command -v yosys     >/dev/null 2>&1 || need+=(yosys)
command -v sta       >/dev/null 2>&1 || need+=(opensta)
[ -d /usr/share/qflow/tech/osu018 ] || need+=(qflow-tech-osu018)
# Place and route (tofprobe layout, docs/layout.md).
command -v qflow     >/dev/null 2>&1 || need+=(qflow)
command -v graywolf  >/dev/null 2>&1 || need+=(graywolf)
command -v qrouter   >/dev/null 2>&1 || need+=(qrouter)
command -v magic     >/dev/null 2>&1 || need+=(magic)
command -v netgen-lvs >/dev/null 2>&1 || need+=(netgen-lvs)
command -v klayout   >/dev/null 2>&1 || need+=(klayout)
# The figures' rendering check (cli reproduce test) renders every SVG as a viewer would.
command -v rsvg-convert >/dev/null 2>&1 || need+=(librsvg2-bin)

if [ ${#need[@]} -eq 0 ]; then
  exit 0
fi

echo "install-tools: installing ${need[*]} from Debian's packages" >&2
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq >&2
$sudo apt-get install -y -qq --no-install-recommends "${need[@]}" >&2
