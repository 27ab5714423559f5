#!/usr/bin/env bash
# Times the real viewer window while the mouse orbits the camera: the release binary
# in an Xvfb server (the X server shares the machine's cores), WHITTED_STATS=1, a drag
# of STEPS steps of 10 pixels each held for PAUSE seconds, then medians of what the
# window reported:
#
#   scripts/window.sh                  # hw3 at 1280x720
#   SCENE=my.toml STEPS=20 scripts/window.sh
#
# Prints one RESULT line: full passes (render_ms of the full-resolution frames),
# previews, submission to full frame (since_view_ms), the blit a frame, and how many
# views showed a preview. Needs Xvfb, xauth and xdotool (see .ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${STEPS:-31}
PAUSE=${PAUSE:-0.4}
SCENE=${SCENE:-}
BLIT=${BLIT:-softbuffer}
cargo build --release --quiet
work=$(mktemp -d)
app="" xvfb=""
trap 'kill $app $xvfb 2>/dev/null || true; rm -rf "$work"' EXIT
display=:$((50 + $$ % 200))
Xvfb "$display" -screen 0 1600x900x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
export DISPLAY=$display XDG_RUNTIME_DIR=$work
for _ in $(seq 50); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done
WHITTED_STATS=1 WHITTED_BLIT=$BLIT ./target/release/whitted view $SCENE 2>"$work/stats" &
app=$!
wid=$(xdotool search --sync --onlyvisible --name '^whitted')
sleep 1
xdotool windowfocus --sync "$wid"
xdotool mousemove --window "$wid" 640 360 mousedown 1
for _ in $(seq "$STEPS"); do
    sleep "$PAUSE"
    xdotool mousemove_relative -- 10 0
done
sleep "$PAUSE"
xdotool mouseup 1
sleep 0.5
kill "$app"
wait "$app" 2>/dev/null || true
# The first view is the window's opening render, not a drag step.
awk -v steps="$STEPS" '
    function median(a, n,   i, j, t) {
        for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j-1] > a[j]; j--) { t = a[j]; a[j] = a[j-1]; a[j-1] = t }
        return n == 0 ? "nan" : (n % 2 ? a[(n+1)/2] : (a[n/2] + a[n/2+1]) / 2)
    }
    /^stats: view / {
        for (i = 1; i <= NF; i++) v[$i] = $(i+1)
        view = $3; kind = $4
        if (first == "") first = view
        if (view == first) next
        blit[++nb] = v["blit_ms"]
        if (kind == "preview") { prev[++np] = v["render_ms"]; had[view] = 1 }
        else if (!(view in full)) { full[view] = 1; pass[++nf] = v["render_ms"]; since[nf] = v["since_view_ms"] }
    }
    /^stats: blitter/ { blitter = $3 }
    END {
        n = 0; for (k in had) n++
        printf "RESULT peer=whitted-window blitter=%s steps=%d views=%d full_pass_ms=%.2f preview_ms=%.2f view_ms=%.2f blit_ms=%.2f previews=%d\n",
            blitter, steps, nf, median(pass, nf), median(prev, np), median(since, nf), median(blit, nb), n
    }' "$work/stats"
