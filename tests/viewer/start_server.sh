# Sourced by the viewer's Xvfb tests: start_server LOG ARGS... starts
# fishtank-server ($server) on a free loopback port with ARGS, its stderr in
# LOG, stops it when the test exits, and sets $port (exit 1 when it does not listen).
# wait_settled LOG waits until every ball is poured and has had 4 s to fall.
# need_tools TOOL... skips the test (exit 77) where one is not installed.
# wait_for_log FILE PATTERN SECONDS WHAT waits until a line of FILE matches
# PATTERN (grep's), or says it waited in vain for WHAT and exits 1.
# scripts/fishtank_tools.py reads the port, as it does for every script.
tools="$(dirname "${BASH_SOURCE[0]}")/../../scripts/fishtank_tools.py"
# The shells under xvfb-run source this file again by this path: functions
# exported with export -f do not pass through xvfb-run's /bin/sh.
helpers=$(realpath "${BASH_SOURCE[0]}")
need_tools() {
  local tool
  for tool in "$@"; do
    if ! command -v "$tool" >/dev/null; then
      echo "$tool is not installed (scripts/install-deps viewer installs it): skipped"
      exit 77
    fi
  done
}
start_server() {
  local log=$1 found
  shift
  "$server" --port 0 --no-web "$@" 2>"$log" &
  server_pid=$!
  trap 'kill "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true' EXIT
  if found=$(python3 "$tools" listening "$log" --pid "$server_pid" --timeout 10); then
    port=$(sed -n '1s/.*://p' <<<"$found")
    return 0
  fi
  echo "the server did not report its port:"
  cat "$log"
  exit 1
}

# The server's status lines give both the time the last ball was poured and the
# latest time, so the pile has formed when the one is 4 s past the other.
wait_settled() {
  local log=$1 poured latest
  for _ in $(seq 1200); do
    poured=$(sed -n 's/^t = *\([0-9.]*\) s *balls *[0-9]* (+0 queued).*/\1/p' "$log" | head -n 1)
    latest=$(sed -n 's/^t = *\([0-9.]*\) s.*/\1/p' "$log" | tail -n 1)
    if [ -n "$poured" ] && awk -v p="$poured" -v t="$latest" 'BEGIN { exit !(t >= p + 4) }'; then
      return 0
    fi
    kill -0 "$server_pid" 2>/dev/null || break
    sleep 0.1
  done
  echo "the server did not finish pouring its balls within 120 s:"
  cat "$log"
  exit 1
}

# A wait that fails where it waited, naming what for, rather than letting a later step
# fail with a message that misleads.
wait_for_log() {
  local file=$1 pattern=$2 seconds=$3 what=$4
  for _ in $(seq $((seconds * 10))); do
    grep -q -- "$pattern" "$file" 2>/dev/null && return 0
    sleep 0.1
  done
  echo "FAILED: waited $seconds s for $what: no line matching \"$pattern\" in $file; its last lines:"
  tail -n 20 "$file" 2>/dev/null || true
  exit 1
}
