#!/usr/bin/env bash
# Checks that maturin's build of the Python package (crates/python alone) resolves every
# dependency with the same features as `cargo test --workspace --release` does: cargo
# unifies features over the packages of one build, so a feature only some other member asks
# for (libc's extra_traits, from the CLI's ctrlc) gives the package's build other
# fingerprints, and maturin then recompiles the whole library tree instead of reusing it
# (minutes of CI). Exits 1 naming each package whose features differ, and the two sets.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
tree() {
  cargo tree --offline --locked "$@" --prefix none -f '{p} [{f}]' 2>/dev/null ||
    cargo tree "$@" --prefix none -f '{p} [{f}]'
}
workspace=$(tree --workspace -e features,normal,build,dev)
package=$(tree -p tofprobe-python -e features,normal,build)
python3 - "$workspace" "$package" <<'PY'
import sys

def features(text):
    out = {}
    for line in text.splitlines():
        line = line.replace(" (*)", "").strip()
        if " [" not in line:
            continue
        name, feats = line.rsplit(" [", 1)
        out[" ".join(name.split()[:2])] = feats.rstrip("]")
    return out

workspace, package = features(sys.argv[1]), features(sys.argv[2])
bad = [(k, workspace.get(k), v) for k, v in sorted(package.items()) if workspace.get(k) != v]
for name, ws, py in bad:
    print(f"python-features: {name}: the workspace build has [{ws}], the package's [{py}]",
          file=sys.stderr)
if bad:
    print("python-features: FAILED: maturin would recompile the library crates; ask for the "
          "workspace's features in crates/python/Cargo.toml", file=sys.stderr)
    sys.exit(1)
print(f"python-features: ok ({len(package)} packages resolved alike)")
PY
