# Sourced by each bash script before it installs or builds anything: with -h
# or --help first, prints the script's opening comment (what it does and how
# to call it) and exits.
case "${1:-}" in
  -h | --help)
    sed -n '2,/^[^#]/{/^#/{s/^# \{0,1\}//;p}}' "$0"
    exit 0
    ;;
esac
