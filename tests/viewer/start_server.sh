# Sourced by the viewer's Xvfb tests: start_server LOG ARGS... starts
# fishtank-server ($server) on a free loopback port with ARGS, its stderr in
# LOG, stops it when the test exits, and sets $port (exit 1 when it does not listen).
# scripts/fishtank_tools.py reads the port, as it does for every script.
tools="$(dirname "${BASH_SOURCE[0]}")/../../scripts/fishtank_tools.py"
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
