#!/usr/bin/env bash
# Runs one coverage-guided fuzz target (fuzz/fuzz_targets/TARGET.rs) for SECONDS:
#
#   scripts/fuzz.sh TARGET SECONDS [libFuzzer options...]
#   scripts/fuzz.sh scene 600 -jobs=2
#
# Targets: scene, image, part, placement, cli_values (docs/testing.md says what each
# checks). cargo-fuzz drives libFuzzer on the stable toolchain with `-s none` (no
# address sanitizer, which needs nightly; safe Rust's panics, overflows, hangs and
# huge allocations are what it finds). The seeds are fuzz/corpus/TARGET (committed);
# what the run adds goes to fuzz/work/TARGET (not committed), crashes to
# fuzz/artifacts/TARGET. libFuzzer's last lines give the executions (#N), the coverage
# (cov: edges, ft: features) and any crash.
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: scripts/fuzz.sh TARGET SECONDS [libFuzzer options...]" >&2
    exit 2
fi
target=$1 seconds=$2
shift 2
cd "$(dirname "$0")/../fuzz"
if [ ! -f "fuzz_targets/$target.rs" ]; then
    echo "no fuzz target $target: $(ls fuzz_targets | sed 's/\.rs$//' | tr '\n' ' ')" >&2
    exit 2
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "cargo-fuzz is missing: installing it with 'cargo install cargo-fuzz' (about 2 minutes)" >&2
    cargo install cargo-fuzz
fi
mkdir -p "work/$target"
# Keys and values of the target's input language, when it has a dictionary.
dict=()
[ -f "dict/$target.dict" ] && dict=("-dict=dict/$target.dict")
# -timeout: an input taking longer is a hang (30 s: the machine may be shared);
# -rss_limit_mb: more memory is a crash.
exec cargo +stable fuzz run -s none "$target" "work/$target" "corpus/$target" -- \
    -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 "${dict[@]}" "$@"
