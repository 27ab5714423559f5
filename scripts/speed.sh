#!/usr/bin/env bash
# Times whitted on the peers' scenes, in the form of ../shared/peers/run.sh's RESULT
# lines, next to the peers built by run.sh, in one sitting:
#
#   QUICK=1 ../shared/peers/run.sh      # builds the peers, writes the scenes, times them
#   scripts/speed.sh                    # hw3 and many_N with whitted and the Embree peer
#
# Both print the median of RUNS runs as render_s and the best as best_s.
#
# Environment: OUT (run.sh's output folder, default /tmp/peers-out), MANY (default
# "1000 10000 100000"), RUNS (default 7), THREADS (default "1 2"), WHITTED (the binary
# to time, default: target/release/whitted, built first; another binary, such as the
# one before a change, is timed as it is).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-/tmp/peers-out}
MANY=${MANY:-"1000 10000 100000"}
RUNS=${RUNS:-7}
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
EMBREE=$(ls "$OUT"/bin/embree_rays.* 2>/dev/null | tail -1 || true)
for scene in hw3 $(for n in $MANY; do echo "many_$n"; done); do
    for t in $THREADS; do
        if [ -n "$EMBREE" ]; then
            # As many runs as whitted's: the RESULT line of the median run (the speed
            # targets compare medians), with the best of them added as best_s.
            lines=""
            for _ in $(seq "$RUNS"); do
                line=$(NO_BENCH=1 "$EMBREE" "$SCN/$scene.txt" "$OUT/$scene.embree.ppm" "$t" | grep '^RESULT')
                s=$(sed -n 's/.* render_s=\([^ ]*\).*/\1/p' <<<"$line")
                lines+="$s $line"$'\n'
            done
            sorted=$(sort -g <<<"${lines%$'\n'}")
            best=$(head -n 1 <<<"$sorted" | cut -d' ' -f1)
            median=$(sed -n "$(( (RUNS + 1) / 2 ))p" <<<"$sorted" | cut -d' ' -f2-)
            echo "$median best_s=$best runs=$RUNS"
        fi
        "$WHITTED" time "$SCN/$scene.toml" --runs "$RUNS" --threads "$t"
    done
done
