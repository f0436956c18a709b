#!/usr/bin/env bash
# Every malformed job in bad/ must exit 2, name the field (and line) given in
# its "# expect:" comment, and leave no output behind — for `validate` and
# for `forces`.
source "$(dirname "$0")/lib.bash"
for job in "$SOURCE"/tests/cli/bad/*.yaml; do
  expected=$(head -1 "$job" | sed 's/^# expect: //')
  for command in validate forces; do
    out="$WORK/out-$(basename "$job" .yaml)-$command"
    if [ "$command" = forces ]; then
      message=$("$ROBOMILL" forces "$job" --out "$out" 2>&1 >/dev/null); code=$?
    else
      message=$("$ROBOMILL" validate "$job" 2>&1 >/dev/null); code=$?
    fi
    [ "$code" -eq 2 ] || fail "$(basename "$job") $command: exit $code, expected 2 ($message)"
    case "$message" in
      *"$expected"*) ;;
      *) fail "$(basename "$job") $command: message lacks '$expected': $message" ;;
    esac
    case "$message" in
      *nan*|*NaN*|*inf\ *) [ "$(basename "$job")" = nan_value.yaml ] || [ "$(basename "$job")" = inf_value.yaml ] \
        || fail "$(basename "$job"): message prints a non-finite value: $message" ;;
    esac
    [ ! -e "$out" ] || fail "$(basename "$job") $command: output folder was created"
  done
done
# A job file that does not exist, and unknown commands or options.
"$ROBOMILL" validate "$WORK/none.yaml" 2>/dev/null; [ $? -eq 2 ] || fail "missing job file: exit code"
"$ROBOMILL" frobnicate x.yaml 2>/dev/null; [ $? -eq 2 ] || fail "unknown command: exit code"
"$ROBOMILL" forces "$SOURCE/examples/demo.yaml" --threads -3 2>/dev/null
[ $? -eq 2 ] || fail "negative --threads: exit code"
"$ROBOMILL" forces "$SOURCE/examples/demo.yaml" --set process.ae 2>/dev/null
[ $? -eq 2 ] || fail "--set without '=': exit code"
finish
