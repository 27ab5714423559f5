#!/usr/bin/env bash
# Builds whitted with profile-guided optimisation: an instrumented build runs the
# training below, and a second build lays out and inlines the hot loops by how often
# their branches ran (`-Cprofile-use`). The images are the same bytes; the time of a
# render is 3-8% lower (docs/speed.md). The profile is made from the source as it is,
# so it is never stale; the default build (`cargo build --release`) does not use one,
# which keeps it portable and free of a binary file to maintain.
#
#   rustup component add llvm-tools      # llvm-profdata, matching rustc's LLVM
#   scripts/pgo.sh                       # then: target/pgo-use/release/whitted
#   WHITTED=target/pgo-use/release/whitted scripts/speed.sh
#
# The training covers what users run: renders of the built-in hw3 scene and of the
# peers' many_N scenes (1,000 to a million balls, ../shared/peers/make_hw3.py), the
# stress scenes of scripts/scale_scene.py (clumps, many lights), several samples a
# pixel, the f64 reference, an animation, every output format, and the viewer's
# frames (`whitted time --orbit`, with and without the preview). A path no run takes
# is compiled as rarely run. (The window's own code, under Xvfb, is not trained.)
#
# Environment: KEEP=1 keeps the training's scenes and images (target/pgo-generate/work).
set -euo pipefail
cd "$(dirname "$0")/.."

sysroot=$(rustc --print sysroot)
host=$(rustc -vV | sed -n 's/^host: //p')
profdata="$sysroot/lib/rustlib/$host/bin/llvm-profdata"
if [ ! -x "$profdata" ]; then
    echo "no llvm-profdata in $sysroot: run rustup component add llvm-tools" >&2
    exit 1
fi

target=target/pgo-generate
work=$target/work
rm -rf "$work"
mkdir -p "$work/build-raw" "$work/raw"
work=$(cd "$work" && pwd)

# RUSTFLAGS reaches the build scripts too, which leave their counts in build-raw; the
# training runs write theirs to raw (LLVM_PROFILE_FILE, one file merged in place).
echo "== instrumented build ($target)"
RUSTFLAGS="-Cprofile-generate=$work/build-raw" CARGO_TARGET_DIR=$target \
    cargo build --release --quiet --bin whitted
bin=$target/release/whitted
export LLVM_PROFILE_FILE="$work/raw/whitted-%m.profraw"

echo "== training scenes"
scenes=$work/scenes
python3 ../shared/peers/make_hw3.py --many 1000 10000 100000 1000000 \
    --outdir "$scenes" --toml >/dev/null
python3 scripts/scale_scene.py clump 2000 --outdir "$scenes" >/dev/null
python3 scripts/scale_scene.py lights 10000 64 --outdir "$scenes" >/dev/null

echo "== training runs"
out=$work/out
mkdir -p "$out"
run() {
    echo "whitted $*"
    "$bin" "$@" --threads 2 --quiet
}
run render -o "$out/hw3.ppm" -o "$out/hw3.png"
run render --ppm-binary --encoding srgb -o "$out/hw3-p6.ppm" -o "$out/hw3.jpg"
for n in 1000 10000 100000; do
    run render "$scenes/many_$n.toml" -o "$out/many_$n.bmp"
done
run render "$scenes/many_1000000.toml" -o "$out/many_1000000.png"
run render "$scenes/clump_2000.toml" -o "$out/clump.bmp"
run render "$scenes/many_10000_L64.toml" --width 640 --height 360 -o "$out/lights.bmp"
run render --spp 4 --width 640 --height 360 -o "$out/hw3-spp4.exr"
run render --quality high --width 640 --height 360 -o "$out/hw3-high.png"
run render --reference --width 320 --height 180 -o "$out/hw3-reference.png"
run render --frames 6 --orbit 60 --width 320 --height 180 -o "$out/orbit.gif"
echo "whitted time --orbit 20 [--no-preview]"
"$bin" time --orbit 20 --no-preview --threads 2 >/dev/null
"$bin" time --orbit 20 --threads 2 >/dev/null

echo "== merging into $target/whitted.profdata"
"$profdata" merge --sparse -o "$target/whitted.profdata" "$work"/raw/*.profraw
[ -n "${KEEP:-}" ] || rm -rf "$work"

echo "== optimised build (target/pgo-use)"
profile=$(cd "$target" && pwd)/whitted.profdata
RUSTFLAGS="-Cprofile-use=$profile" CARGO_TARGET_DIR=target/pgo-use \
    cargo build --release --quiet --bin whitted
echo "built target/pgo-use/release/whitted"
