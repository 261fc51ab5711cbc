#!/usr/bin/env bash
# The viewer's own sphere found inside the pile: a server on an ephemeral
# loopback port, the viewer under Xvfb, Q held (xdotool) until the sphere is
# pressed down to the floor under the settled balls, then F12 and the pixel
# check: no white sphere in view, its amber through the balls instead.
# Exit 77 (skipped) only without xvfb-run or xdotool.
#
# Usage: hidden_player_test.sh SERVER VIEWER CHECKER OUT_DIR
set -euo pipefail
server=$1 viewer=$2 checker=$3 out=$4
source "$(dirname "$0")/start_server.sh"

need_tools xvfb-run xdotool
rm -rf "$out"
mkdir -p "$out/work"
log=$out/server.log

start_server "$log" --balls 1000
wait_settled "$log"

# The sphere moves at 8 m/s and stops at the floor: 2.5 s of Q take it there from the tank's
# centre, and 7 s do even with the physics in slow motion at x0.4 on a busy machine.
export SERVER_LOG=$log VIEWER=$viewer PORT=$port HELPERS=$helpers
cd "$out/work"
timeout 150 xvfb-run -a -s "-screen 0 1280x1024x24" bash -euo pipefail -c '
  source "$HELPERS"
  "$VIEWER" --connect "127.0.0.1:$PORT" --no-hud 2>viewer.log &
  viewer_pid=$!
  window=$(xdotool search --sync --name Fishtank | head -n 1)
  wait_for_log "$SERVER_LOG" "welcomed with player sphere" 20 "the server to welcome the viewer with a player sphere"
  xdotool windowfocus "$window"
  xdotool keydown q
  sleep 7
  xdotool keyup q
  sleep 1
  xdotool key F12
  wait_for_log viewer.log "screenshot saved: " 10 "the viewer to save its F12 screenshot"
  xdotool key Escape
  wait "$viewer_pid"
'
saved=$(sed -n 's/^fishtank-viewer: screenshot saved: //p' viewer.log)
if [ -z "$saved" ]; then
  echo "FAILED: F12 saved no screenshot:"
  cat viewer.log
  exit 1
fi
"$checker" --own-hidden "$saved"
