#!/usr/bin/env bash
# `--set` into lists (docs/job-reference.md): a sweep of one mode's damping
# through a dotted index changes the diagram, the dotted and bracket forms
# agree, the list's length appends an entry, and bad indices exit 2 naming
# the list's length and write nothing.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/demo.yaml"
FAST=(--set stability.speeds.count=20)

stability() {  # stability OUT ARGS...: the diagram of the demo with ARGS
  local out=$1; shift
  "$ROBOMILL" stability "$JOB" "${FAST[@]}" "$@" --out "$WORK/$out" --quiet \
    || fail "stability $*: exit code"
}
stability base
# The sweep of mode 0's damping: the file's own 0.81 % gives the file's
# diagram, 3 % another one; the bracket form is the same override.
for zeta in 0.81 3; do
  stability "zeta-$zeta" --set "dynamics.modes.0.zeta=$zeta %"
done
cmp -s "$WORK/base/sld.csv" "$WORK/zeta-0.81/sld.csv" || fail "zeta 0.81 % changed the diagram"
cmp -s "$WORK/base/sld.csv" "$WORK/zeta-3/sld.csv" && fail "zeta 3 % left the diagram unchanged"
stability bracket --set "dynamics.modes[0].zeta=3 %"
cmp -s "$WORK/zeta-3/sld.csv" "$WORK/bracket/sld.csv" || fail "dynamics.modes[0] and .0 differ"
# A fifth mode appended, and the whole list in flow form.
stability appended --set 'dynamics.modes.4={direction: x, fn: 30 Hz, zeta: 1 %, k: 2e6}'
cmp -s "$WORK/base/sld.csv" "$WORK/appended/sld.csv" && fail "the appended mode changed nothing"
stability flow --set 'dynamics.modes=[{direction: y, fn: 19.88 Hz, zeta: 0.81 %, k: 3.65e6 N/m},
  {direction: y, fn: 77.17 Hz, zeta: 5.15 %, k: 5.00e6 N/m},
  {direction: x, fn: 17.8 Hz, zeta: 1.76 %, k: 2.31e6 N/m},
  {direction: x, fn: 47.3 Hz, zeta: 0.74 %, k: 33.60e6 N/m}]'
cmp -s "$WORK/base/sld.csv" "$WORK/flow/sld.csv" || fail "the demo's modes in flow form differ"

# Bad indices: exit 2, the message, no output.
expect_exit2 \
  '`--set dynamics.modes.5.zeta=2%`: index 5 is out of range; dynamics.modes has 4 entries (from --set)' \
  stability "$JOB" --set dynamics.modes.5.zeta=2%
expect_exit2 "index 7 is out of range; dynamics.modes has 4 entries" \
  stability "$JOB" --set 'dynamics.modes[7]={direction: x, fn: 30 Hz, zeta: 1 %, k: 2e6}'
expect_exit2 "index 4 adds an entry only as a whole" stability "$JOB" --set dynamics.modes.4.zeta=2%
expect_exit2 "list indices count from 0, got -1" stability "$JOB" --set dynamics.modes.-1.zeta=2%
expect_exit2 "dynamics.modes[0].zeta: expected a number, got 'abc' (from --set)" \
  stability "$JOB" --set dynamics.modes.0.zeta=abc
expect_exit2 "needs tool.teeth to be a list or a section, but it is the value '2'" \
  stability "$JOB" --set tool.teeth.0=3
expect_exit2 "the job has no robot.posture list to index" stability "$JOB" --set robot.posture.0=30
finish
