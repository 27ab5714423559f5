#!/usr/bin/env bash
# Every test of the project, as README's set-up and CI run them:
#   1. the whole crate with its default features (the command line and the window);
#   2. the core library alone (`--no-default-features`): its unit tests, the
#      integration tests that need no binary, and the doc examples;
#   3. the core's documentation builds with no rustdoc warning (broken links);
#   4. the core's dependency tree holds none of the shells' crates;
#   5. the Python package (python/), built by maturin into a virtual environment
#      made here (target/python-env), with its tests: the module against the command
#      line, and `whitted.distributed` on a Dask cluster started on 127.0.0.1.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== cargo test --release"
cargo test --release

echo "== cargo test --release --no-default-features (the core library)"
cargo test --release --no-default-features

echo "== the core library's documentation (rustdoc, warnings are errors)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --no-default-features --quiet

echo "== the core's dependencies"
shells="clap indicatif plotters nv-flip ctrlc winit pixels softbuffer anyhow"
tree=$(cargo tree -e normal --no-default-features --prefix none --format '{p}' | cut -d' ' -f1 | sort -u)
found=""
for crate in $shells; do
    if grep -qx "$crate" <<<"$tree"; then found+=" $crate"; fi
done
if [ -n "$found" ]; then
    echo "FAILED: the core library depends on:$found" >&2
    exit 1
fi
echo "ok: none of $shells"

echo "== the Python package"
venv=target/python-env
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --upgrade pip
"$venv/bin/pip" install --quiet "maturin>=1.16,<2" numpy pytest dask distributed tqdm
PATH="$PWD/$venv/bin:$PATH" "$venv/bin/pip" install --quiet --no-build-isolation --force-reinstall --no-deps ./python
WHITTED_BIN="$PWD/target/release/whitted" "$venv/bin/python" -m pytest -q python/tests
