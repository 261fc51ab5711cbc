#!/usr/bin/env bash
# The viewer for real (DESIGN "Tests"): a server on an ephemeral loopback
# port, the viewer under Xvfb with Mesa's software OpenGL rendering frames and
# saving a PNG once the poured balls have settled, then the pixel check.
# Exit 77 (skipped) only without xvfb-run.
#
# Usage: screenshot_test.sh SERVER VIEWER CHECKER OUT_DIR
set -euo pipefail
server=$1 viewer=$2 checker=$3 out=$4
source "$(dirname "$0")/start_server.sh"

need_tools xvfb-run
mkdir -p "$out"
png=$out/viewer_screenshot.png
log=$out/server.log
rm -f "$png"

start_server "$log" --balls 1000

# The pile lies below the player sphere at the tank's centre and no falling ball hides it.
wait_settled "$log"

timeout 150 xvfb-run -a -s "-screen 0 1280x1024x24" \
  "$viewer" --connect "127.0.0.1:$port" --no-hud --screenshot "$png" --frames 60
"$checker" "$png"
