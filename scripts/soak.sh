#!/usr/bin/env bash
# Soaks the viewer window in random X input for MINUTES on each scene (default 5):
#
#   scripts/soak.sh 10                       # hw3, the hw3 turntable, many_100000
#   SOAK_SCENES=many_100000 scripts/soak.sh 3
#   SOAK_SEED=1234 scripts/soak.sh 1         # the same storm again
#
# Runs the ignored test `soak_for_longer` of tests/viewer_soak.rs (see there for what
# it sends and checks), which fails on any check. Prints one SOAK line per scene:
# events sent, time, probes of the response time and their median and 99th
# percentile (event to title change, and to the first picture of the new view),
# resident memory after the first minute and at the end. Fails if the median answer
# is over 100 ms. Needs Xvfb, xdotool, xprop and ImageMagick's import (see .ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-5}
export SOAK_SECONDS=$(awk -v m="$minutes" 'BEGIN { print m * 60 }')
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
cargo test --release --test viewer_soak -- --ignored --exact soak_for_longer --nocapture \
    2>&1 | tee "$log" || status=$?
# The figures of every scene, also when a check failed on one.
grep '^SOAK ' "$log" | awk '
    {
        for (i = 2; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
        printf "%s: %s events in %s s; answer median %s ms, p99 %s ms; first picture median %s ms, p99 %s ms (%s probes); memory %s -> %s MiB\n",
            v["scene"], v["events"], v["seconds"], v["answer_median_ms"], v["answer_p99_ms"],
            v["picture_median_ms"], v["picture_p99_ms"], v["probes"], v["rss_first_mib"], v["rss_end_mib"]
        if (v["answer_median_ms"] + 0 > 100) { slow = slow " " v["scene"] }
    }
    END {
        if (NR == 0) { print "FAILED: no SOAK line (the soak did not run)"; exit 1 }
        if (slow != "") { print "FAILED: median answer over 100 ms on" slow; exit 1 }
    }' || status=1
if [ "$status" -ne 0 ]; then
    echo "FAILED: a check of the soak failed (see above)" >&2
    exit "$status"
fi
