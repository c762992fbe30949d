#!/usr/bin/env bash
# Every test of the workspace in release mode, as `cargo test --workspace --release` runs
# them (each test binary in its package's directory with its CARGO_MANIFEST_DIR, then the
# doc tests), but with the CLI's integration binary in the background beside the others.
# Why: cargo runs the binaries one after another, and libtest starts a binary's tests in
# name order, so the CLI binary's long tests (a routed layout, synthesis of the default on
# three corners, the options study, sign-off: 30–75 s each, ≈ 300 s of the binary's two
# threads) end it with one core idle, as do the sign-off proofs of eda's binary. Cargo
# holds the target directory's lock while its tests run, so two `cargo test` cannot
# overlap: the binaries are run directly (their paths from cargo's own build report).
# Every binary's output is printed (the background one's when it ends); the exit status
# is 1 if any binary failed, naming them. Used by scripts/test.sh.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$(pwd)

if ! command -v python3 >/dev/null 2>&1; then
  exec cargo test --workspace --release
fi

# "executable<TAB>package directory<TAB>label" of every test binary (already built by the
# build-tests phase: this only reads cargo's report).
list=$(cargo test --workspace --release --no-run --message-format=json | python3 -c '
import json, os, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"]["test"]:
        pkg = os.path.dirname(m["manifest_path"])
        kind = m["target"]["kind"][0]
        print("\t".join([m["executable"], pkg, os.path.basename(pkg) + " " + kind + " " + m["target"]["name"]]))
' | sort -t $'\t' -k3)

tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
run() { # executable, package directory
  (cd "$2" && CARGO_MANIFEST_DIR="$2" "$1")
}

failed=()
background=""
while IFS=$'\t' read -r exe pkg label; do
  if [ "$label" = "cli test it" ]; then
    background=$label
    (
      rc=0
      run "$exe" "$pkg" >"$tmp/background.out" 2>&1 || rc=$?
      echo "$rc" >"$tmp/background.rc"
    ) &
  fi
done <<<"$list"

while IFS=$'\t' read -r exe pkg label; do
  [ "$label" = "$background" ] && continue
  echo "     Running ${exe#"$root"/} ($label)" >&2
  run "$exe" "$pkg" || failed+=("$label")
done <<<"$list"

if [ -n "$background" ]; then
  wait
  echo "     Running the background binary ($background):" >&2
  cat "$tmp/background.out"
  [ "$(cat "$tmp/background.rc")" = 0 ] || failed+=("$background")
fi

cargo test --workspace --release --doc || failed+=("doc tests")

if [ "${#failed[@]}" -ne 0 ]; then
  printf 'run-tests: FAILED: %s\n' "${failed[@]}" >&2
  exit 1
fi
echo "run-tests: every test binary passed" >&2
