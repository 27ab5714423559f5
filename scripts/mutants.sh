#!/usr/bin/env bash
# Mutation testing (cargo-mutants) of the modules that compute pixels: the shading
# model, the camera, the sample positions, both tracers, the acceleration structures,
# the film mapping, the resolve step, adaptive anti-aliasing and the byte conversion.
# Each mutant is built with the `mutants` profile (optimised, the library built
# incrementally in 16 units) and the core alone (no window, no command line), and
# tested by the fast tests that check pixels: the unit tests and the integration
# tests named below. Results go to target/mutants-report/mutants.out/ (outcomes.json,
# caught.txt, missed.txt, timeout.txt, unviable.txt); docs/testing.md keeps the
# figures and why each remaining missed mutant is equivalent.
#
#   scripts/mutants.sh                      every mutant of those modules
#   scripts/mutants.sh --iterate            only the mutants not caught last time
#   scripts/mutants.sh --in-diff x.diff     only the mutants in lines a diff touches
#   scripts/mutants.sh -f src/model.rs      one module (cargo-mutants' own options)
#   scripts/mutants.sh --shard 1/4          a quarter, e.g. one per machine
#
# Runs under `nice`, so it can run in the background while you work.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo-mutants >/dev/null; then
    echo "cargo-mutants is not installed: cargo install --locked cargo-mutants" >&2
    exit 1
fi

# The modules, unless the caller names files.
files=()
if ! printf '%s\n' "$@" | grep -qx -- '-f\|--file'; then
    for f in src/model.rs src/camera.rs src/sampling.rs src/intersect.rs 'src/trace/*.rs' \
        'src/accel/*.rs' 'src/accel/bvh/*.rs' src/render/film.rs src/render/resolve.rs \
        src/render/adaptive.rs src/image_io/srgb.rs src/image_io/mod.rs; do
        files+=(--file "$f")
    done
fi

# Left out: image_io's encoders and file handling (tested by tests/files.rs through
# the binary, not pixels), the size guard of the files `compare` and `stitch` read
# (tests/parts.rs and compare_cli.rs, through the binary), and the viewer's ray-tree
# recorder (no pixel depends on it).
exclude='image_io/mod.rs:.*(replace|in) (save|save_rgb8|encode|encode_rgb8|exr_bytes|write_atomically|temp_file_for|target_of|folder_of|check_writable|Format::from_path|to_rgb32f|check_header_fits|check_holds|bytes_left)\b'
exclude+='|TreeRecorder|RayKind::name'

# The tests each mutant runs (cargo's target options); override with MUTANTS_TESTS,
# best with the targets that exercise the module run (docs/testing.md has a table),
# e.g. MUTANTS_TESTS=--lib for src/sampling.rs: fewer targets, a cheaper build.
tests=${MUTANTS_TESTS:---lib --test=hand_computed --test=accuracy --test=refraction --test=stress_scenes --test=quality}
targets=()
for t in $tests; do
    targets+=("--cargo-arg=$t")
done

# One build folder for every run, outside the copies cargo-mutants makes of the
# source: the dependencies are built once, and each mutant rebuilds only the library
# and the test crates named above, incrementally.
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$PWD/target/mutants-build}
out=${MUTANTS_OUT:-target/mutants-report}
mkdir -p "$out"
exec nice -n 10 cargo mutants \
    --no-default-features --profile mutants \
    --output "$out" \
    --exclude 'src/accel/tests/*' \
    --exclude-re "$exclude" \
    --minimum-test-timeout 60 \
    "${targets[@]}" \
    "${files[@]}" "$@"
