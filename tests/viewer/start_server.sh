# Sourced by the viewer's Xvfb tests: start_server LOG ARGS... starts
# fishtank-server ($server) on a free loopback port with ARGS, its stderr in
# LOG, stops it when the test exits, and sets $port (exit 1 when it does not listen).
start_server() {
  local log=$1
  shift
  "$server" --port 0 --no-web "$@" 2>"$log" &
  server_pid=$!
  trap 'kill "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true' EXIT
  port=""
  for _ in $(seq 200); do
    port=$(sed -n 's/^listening on .*:\([0-9][0-9]*\)$/\1/p' "$log")
    [ -n "$port" ] && return 0
    kill -0 "$server_pid" 2>/dev/null || break
    sleep 0.05
  done
  echo "the server did not report its port:"
  cat "$log"
  exit 1
}
