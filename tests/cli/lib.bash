# Shared helpers for the command-line tests: $ROBOMILL is the binary,
# $SOURCE the repository root, $WORK a scratch folder removed on exit.
set -u
ROBOMILL=$1
SOURCE=$2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
failures=0

fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# json_number FILE KEY SUBKEY: the number of "SUBKEY" inside object "KEY" of a
# pretty-printed summary.json (no jq on a bare Debian machine).
json_number() {
  awk -v key="\"$2\"" -v sub_key="\"$3\"" '
    index($0, key ":") { inside = 1; next }
    inside && index($0, sub_key ":") { gsub(/[ ,]/, "", $0); split($0, kv, ":"); print kv[2]; exit }
    inside && /}/ { inside = 0 }' "$1"
}

# expect_exit2 FRAGMENT ARGS...: `robomill ARGS --out $WORK/bad` must exit 2
# with FRAGMENT in its message and write nothing.
expect_exit2() {
  local fragment=$1; shift
  msg=$("$ROBOMILL" "$@" --out "$WORK/bad" 2>&1); code=$?
  [ "$code" -eq 2 ] || fail "$*: exit $code (expected 2): $msg"
  case "$msg" in *"$fragment"*) ;; *) fail "$*: message lacks '$fragment': $msg" ;; esac
  [ ! -e "$WORK/bad" ] || fail "$*: wrote output"
}

finish() {
  if [ "$failures" -ne 0 ]; then
    echo "$failures check(s) failed" >&2
    exit 1
  fi
  echo "all checks passed"
}
