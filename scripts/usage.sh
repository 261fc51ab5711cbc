# Sourced by each bash script before it installs or builds anything: with -h
# or --help first, prints the script's opening comment (what it does and how
# to call it) and exits.
case "${1:-}" in
  -h | --help)
    sed -n '2,/^[^#]/{/^#/{s/^# \{0,1\}//;p}}' "$0"
    exit 0
    ;;
esac

# For a script whose only arguments are positional (a build folder, say): refuses an option, or more than
# $1 arguments, pointing at --help, instead of reading "--bogus" as a folder's name.
positional_only() {
  local most=$1
  shift
  for arg in "$@"; do
    if [[ $arg == -* ]]; then
      echo "$(basename "$0"): unknown option '$arg'; see $0 --help" >&2
      exit 2
    fi
  done
  if (($# > most)); then
    echo "$(basename "$0"): at most $most argument(s), got $#: $*; see $0 --help" >&2
    exit 2
  fi
}
