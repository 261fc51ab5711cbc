#!/usr/bin/env bash
# The viewer's sandbox keys for real: a server on an ephemeral loopback port,
# the viewer under Xvfb, keys typed with xdotool. Each key must reach the
# server (its status line says so) or, for F12, leave a PNG in the viewer's
# working folder and say where. Exit 77 (skipped) only without xvfb-run or xdotool.
#
# Usage: controls_test.sh SERVER VIEWER OUT_DIR
set -euo pipefail
server=$1 viewer=$2 out=$3
source "$(dirname "$0")/start_server.sh"

need_tools xvfb-run xdotool
rm -rf "$out"
mkdir -p "$out/work"
log=$out/server.log

start_server "$log" --balls 300 --threads 1 --status-interval 0.25

# Inside the X session: start the viewer, wait for its window and its welcome,
# then type each key and wait (at most 20 s) for the server's status line to show it.
export SERVER_LOG=$log VIEWER=$viewer PORT=$port HELPERS=$helpers
cd "$out/work"
timeout 200 xvfb-run -a -s "-screen 0 1280x1024x24" bash -euo pipefail -c '
  source "$HELPERS"
  "$VIEWER" --connect "127.0.0.1:$PORT" --max-fps 10 2>viewer.log &
  viewer_pid=$!
  expect_status() {  # pattern, what it means
    for _ in $(seq 200); do
      tail -n 1 "$SERVER_LOG" | grep -q -- "$1" && return 0
      sleep 0.1
    done
    echo "FAILED: $2: no status line matching \"$1\""; tail -n 5 "$SERVER_LOG"; exit 1
  }
  window=$(xdotool search --sync --name Fishtank | head -n 1)
  wait_for_log "$SERVER_LOG" "welcomed with player sphere" 20 "the server to welcome the viewer with a player sphere"
  # The viewer ignores sandbox keys until it has a snapshot: deltas (frames sent, no keyframe) mean it
  # acknowledged one.
  wait_for_log "$SERVER_LOG" "[1-9][0-9]* B mean, 0 keyframes" 20 "the server to send the viewer deltas"
  xdotool windowfocus "$window"
  xdotool key bracketleft
  expect_status "time scale set to x0.50" "[ slows the clock to 0.5"
  xdotool key bracketright
  expect_status "scene tank$" "] brings it back to real time"
  xdotool key 3
  expect_status "scene dam-break$" "3 switches to the dam-break scene"
  xdotool key p
  expect_status "scene dam-break  paused" "P pauses"
  xdotool key F12
  wait_for_log viewer.log "screenshot saved: " 10 "the viewer to save its F12 screenshot"
  xdotool key Escape
  wait "$viewer_pid"
'
saved=$(sed -n 's/^fishtank-viewer: screenshot saved: //p' viewer.log)
if [ -z "$saved" ] || [ ! -s "$saved" ] || [ "$(dirname "$saved")" != "$(pwd -P)" ]; then
  echo "FAILED: F12 saved no PNG in the working folder and said so:"
  cat viewer.log
  exit 1
fi
echo "every key reached the server; F12 saved $saved"
