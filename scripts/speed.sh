#!/usr/bin/env bash
# whitted against the Embree peer of ../shared/peers, measured as users run them: a
# fresh process per run on both sides, acceleration build plus render inside the
# timer (whitted: the closing line of `whitted render`; the peer: build_s + render_s),
# the two alternated run by run in one sitting, medians. whitted's warm in-process
# figures (`whitted time`: median of renders after a warm-up, build apart, the
# viewer's case) are printed beside them, never instead of them.
#
#   QUICK=1 ../shared/peers/run.sh      # builds the peers (needs libembree-dev)
#   scripts/speed.sh                    # the table below, for hw3 and many_N
#
# Columns: Embree and whitted cold (median s), whitted ÷ Embree; the builds in those
# same cold runs (whitted: the build the closing line gives; the peer: build_s; median
# s) and their ratio; whitted's warm render and build (median s, `whitted time`: its
# builds run after renders in one process, each into freshly mapped memory); and the
# peak resident memory of `whitted render` (MB, the largest of the runs).
#
# Then the viewer's line: a whole frame of hw3 at 1280×720 on two threads while the
# camera orbits (`whitted time --orbit $ORBIT --no-preview`, the median frame) against
# the Embree peer's hw3 render on two threads (median of RUNS), and their ratio; and
# like for like, the same frames against the peer's render of the same views (each
# view written by `whitted time --views-to`, rendered once by the peer; the median).
#
# Environment: OUT (run.sh's output folder, default /tmp/peers-out), MANY (default
# "1000 10000 100000 1000000"), RUNS (default 5), THREADS (default "1 2"), ORBIT
# (views of the viewer's orbit, default 40; 0 leaves the viewer's line out), WHITTED
# (the binary to time, default target/release/whitted, built first), EMBREE (the peer
# binary, default the newest under $OUT/bin).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-/tmp/peers-out}
MANY=${MANY:-"1000 10000 100000 1000000"}
RUNS=${RUNS:-5}
THREADS=${THREADS:-"1 2"}
PEERS=$(cd ../shared/peers && pwd)
SCN=$OUT/scenes
mkdir -p "$SCN"
[ -s "$SCN/hw3.toml" ] || python3 "$PEERS/make_hw3.py" --outdir "$SCN" --toml >/dev/null
for n in $MANY; do
    [ -s "$SCN/many_$n.toml" ] || python3 "$PEERS/make_hw3.py" --many "$n" --outdir "$SCN" --toml >/dev/null
done
if [ -z "${WHITTED:-}" ]; then
    cargo build --release --quiet
    WHITTED=./target/release/whitted
fi
EMBREE=${EMBREE:-$(ls "$OUT"/bin/embree_rays.* 2>/dev/null | tail -1 || true)}
if [ -z "$EMBREE" ]; then
    echo "no Embree peer under $OUT/bin: run QUICK=1 ../shared/peers/run.sh first" >&2
    exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) cores; $(date -u '+%Y-%m-%d %H:%M UTC'); runs $RUNS"
printf '| %-12s | %-7s | %-11s | %-12s | %-9s | %-13s | %-12s | %-7s | %-11s | %-10s | %-10s |\n' \
    scene threads "Embree cold" "whitted cold" "whitted ÷" "whitted build" "Embree build" "build ÷" \
    "whitted warm" "warm build" "peak MB"
printf '|%s|\n' "--------------|---------|-------------|--------------|-----------|---------------|--------------|---------|-------------|------------|------------"
for scene in hw3 $(for n in $MANY; do echo "many_$n"; done); do
    for t in $THREADS; do
        : >"$tmp/embree" ; : >"$tmp/ebuild" ; : >"$tmp/whitted" ; : >"$tmp/wbuild" ; : >"$tmp/mem"
        for _ in $(seq "$RUNS"); do
            line=$(NO_BENCH=1 "$EMBREE" "$SCN/$scene.txt" "$tmp/e.ppm" "$t" | grep '^RESULT')
            b=$(field build_s <<<"$line")
            r=$(field render_s <<<"$line")
            awk -v b="$b" -v r="$r" 'BEGIN { print b + r }' >>"$tmp/embree"
            echo "$b" >>"$tmp/ebuild"
            /usr/bin/time -f '%M' -o "$tmp/rss" "$WHITTED" render "$SCN/$scene.toml" -o "$tmp/w.ppm" \
                --threads "$t" 2>"$tmp/err" >/dev/null
            sed -n 's/^rendered .* in \([0-9.]*\) s (build.*/\1/p' "$tmp/err" >>"$tmp/whitted"
            sed -n 's/^rendered .* (build \([0-9.]*\) s):.*/\1/p' "$tmp/err" >>"$tmp/wbuild"
            echo $(( $(cat "$tmp/rss") / 1024 )) >>"$tmp/mem"
        done
        warm=$("$WHITTED" time "$SCN/$scene.toml" --runs "$RUNS" --threads "$t")
        e=$(median <"$tmp/embree")
        w=$(median <"$tmp/whitted")
        eb=$(median <"$tmp/ebuild")
        wb=$(median <"$tmp/wbuild")
        printf '| %-12s | %-7s | %-11.4f | %-12.4f | %-9.2f | %-13.4f | %-12.4f | %-7.2f | %-11s | %-10s | %-10s |\n' \
            "$scene" "$t" "$e" "$w" "$(awk -v w="$w" -v e="$e" 'BEGIN { print w / e }')" \
            "$wb" "$eb" "$(awk -v w="$wb" -v e="$eb" 'BEGIN { print w / e }')" \
            "$(field render_s <<<"$warm")" "$(field build_s <<<"$warm")" \
            "$(sort -g "$tmp/mem" | tail -1)"
    done
done
ORBIT=${ORBIT:-40}
if [ "$ORBIT" -gt 0 ]; then
    mkdir -p "$tmp/views"
    frame=$("$WHITTED" time --orbit "$ORBIT" --no-preview --threads 2 --views-to "$tmp/views" |
        field frame_ms)
    : >"$tmp/erender"
    for _ in $(seq "$RUNS"); do
        NO_BENCH=1 "$EMBREE" "$SCN/hw3.txt" "$tmp/e.ppm" 2 | grep '^RESULT' | field render_s >>"$tmp/erender"
    done
    e=$(median <"$tmp/erender")
    echo "viewer: hw3 orbit ($ORBIT views, 2 threads) $frame ms a frame; Embree's hw3 render $e s; ÷ $(awk -v f="$frame" -v e="$e" 'BEGIN { printf "%.2f", f / 1000 / e }')"
    : >"$tmp/eviews"
    for view in "$tmp"/views/view_*.txt; do
        NO_BENCH=1 "$EMBREE" "$view" "$tmp/e.ppm" 2 | grep '^RESULT' | field render_s >>"$tmp/eviews"
    done
    ev=$(median <"$tmp/eviews")
    echo "viewer, like for like: Embree's render of the same $ORBIT views $ev s (median); ÷ $(awk -v f="$frame" -v e="$ev" 'BEGIN { printf "%.2f", f / 1000 / e }')"
fi
