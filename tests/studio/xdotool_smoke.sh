#!/usr/bin/env bash
# xdotool_smoke.sh SYLVA GRAMMAR [save|term] — run inside xvfb-run by window_test.cpp:
# opens GRAMMAR (a binary tree whose production is on line 6) in the studio, clicks at the
# end of line 6, types '[' (an unbalanced bracket: an error), Backspace and '[+A]' (a
# third branch: the plant regrows), then `save` (the default): saves with Ctrl+S and
# closes; `term`: sends SIGTERM with the edit unsaved. Prints the studio's trace lines
# (SYLVA_STUDIO_TRACE=1) and "studio exit STATUS" for the test to read.
set -u
sylva=$1
grammar=$2
mode=${3:-save}
log=$(mktemp)
trap 'rm -f "$log"' EXIT
SYLVA_STUDIO_TRACE=1 "$sylva" studio "$grammar" --size 1000x700 >"$log" 2>&1 &
pid=$!

# Waits until the log holds a line matching $1 (after the first $2 such lines), 60 s at most.
wait_for() {
  local pattern=$1 count=${2:-0}
  for _ in $(seq 600); do
    if [ "$(grep -c -- "$pattern" "$log")" -gt "$count" ]; then return 0; fi
    if ! kill -0 "$pid" 2>/dev/null; then echo "studio exited early"; cat "$log"; exit 1; fi
    sleep 0.1
  done
  echo "timed out waiting for '$pattern'"; cat "$log"; kill "$pid"; exit 1
}

# Dear ImGui 1.86 reads key state once a frame: a key must stay down across a frame to
# be seen (typed characters are queued and need no such care).
press() { xdotool keydown "$1"; sleep 0.15; xdotool keyup "$1"; sleep 0.1; }

wait_for '^studio: editor '
read -r _ _ x y lh < <(grep '^studio: editor ' "$log" | head -1)
line=6
cx=$(awk -v x="$x" 'BEGIN { printf "%d", x + 4 }')
cy=$(awk -v y="$y" -v lh="$lh" -v l="$line" 'BEGIN { printf "%d", y + (l - 0.5) * lh }')
xdotool mousemove "$cx" "$cy" click 1
sleep 0.3
press End
xdotool type --delay 50 '['
wait_for '^studio: error .*:6:'
plants=$(grep -c '^studio: plant ' "$log")
press BackSpace
xdotool type --delay 50 '[+A]'
wait_for '^studio: plant ' "$plants"
if [ "$mode" = save ]; then
  press ctrl+s
  sleep 1
fi
kill -TERM "$pid"
wait "$pid" 2>/dev/null
status=$?
cat "$log"
echo "studio exit $status"
exit 0
