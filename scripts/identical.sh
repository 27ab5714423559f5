#!/usr/bin/env bash
# Renders a fixed set of scenes with a whitted binary into a folder, so that two
# binaries (say, before and after a change that must not move a pixel) can be
# compared file by file:
#
#   scripts/identical.sh OLD_BIN /tmp/before
#   scripts/identical.sh target/release/whitted /tmp/after
#   diff -r /tmp/before /tmp/after && echo identical
#
# The set: hw3 at 1 and 4 spp and at --quality default, many_1000/10000/100000
# (../shared/peers/make_hw3.py) and many_100000 at 160×90 and 16×9, four close
# views of hw3 at depth 8, and the stress scenes of assets/scenes/stress; each as
# PPM, PNG and EXR.
set -euo pipefail
BIN=$(realpath "$1")
OUT=$2
cd "$(dirname "$0")/.."
mkdir -p "$OUT"
SCN=$(mktemp -d)
trap 'rm -rf "$SCN"' EXIT
python3 ../shared/peers/make_hw3.py --many 1000 10000 100000 --outdir "$SCN" --toml >/dev/null

# Close views: the hw3 scene seen from four places, the light's rays crossing glass.
"$BIN" scene hw3 | sed -n '/^\[image\]/,$p' >"$SCN/hw3-body.toml"
view() { # name look_from look_at
    {
        printf '[camera]\nlook_from = %s\nlook_at = %s\nup = [0, 1, 0]\nvfov = 40\n\n' "$2" "$3"
        sed 's/^max_depth = .*/max_depth = 8/' "$SCN/hw3-body.toml"
    } >"$SCN/$1.toml"
}
view close-glass '[0.2, 0.1, -0.6]' '[0, 0, -1]'
view close-mirror '[-1.2, 0.3, -0.8]' '[-1, 0, -1]'
view close-ground '[0, -0.3, -1.2]' '[0, -0.4, -2.5]'
view close-above '[0, 2, -1]' '[0, 0, -1.5]'

render() { # name scene-or-empty options...
    local name=$1 scene=$2
    shift 2
    for ext in ppm png exr; do
        "$BIN" render $scene -o "$OUT/$name.$ext" --quiet "$@"
    done
}
render hw3 ""
render hw3-spp4 "" --spp 4
render hw3-quality-default "" --quality default --width 640 --height 360
for n in 1000 10000 100000; do render "many_$n" "$SCN/many_$n.toml"; done
# Small images of many spheres: runs of rays parting too far to walk as bundles.
for size in 160x90 16x9; do
    render "many_100000-$size" "$SCN/many_100000.toml" --width "${size%x*}" --height "${size#*x}"
done
for v in close-glass close-mirror close-ground close-above; do
    render "$v" "$SCN/$v.toml" --width 640 --height 360
done
for f in assets/scenes/stress/*.toml; do render "stress-$(basename "$f" .toml)" "$f"; done
ls "$OUT" | wc -l
