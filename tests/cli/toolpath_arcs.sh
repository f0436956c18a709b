#!/usr/bin/env bash
# `robomill toolpath --optimize` compensating arcs: the robot pocket with R8
# wall corners (examples/programs/rounded_pocket.nc, G3 with I J and with R)
# on the KR 270 example. Every arc is written with its centre and radius
# moved, the line before ends on the moved circle, the written program reads
# back (the command checks every end point and arc centre) and, analysed
# again, leaves the walls far closer to the programmed path than before.
source "$(dirname "$0")/lib.bash"
R="$SOURCE/examples/toolpath_robot_pocket.yaml"
FAST=(--set "toolpath.spacing=0.5 mm" --set "stability.speeds={from: 4000 rpm, to: 12000 rpm, count: 41}")

"$ROBOMILL" toolpath "$R" --out "$WORK/arcs" --quiet --optimize "${FAST[@]}" \
  --set "toolpath.file=$SOURCE/examples/programs/rounded_pocket.nc" || fail "--optimize exit code"
[ -s "$WORK/arcs/program_optimized.nc" ] || fail "no program_optimized.nc"
/usr/bin/python3 - "$WORK/arcs/summary.json" "$WORK/arcs/program_optimized.nc" <<'PYEOF' || fail "arc compensation"
import json, re, sys
c = json.load(open(sys.argv[1]))["optimization"]["compensation"]
text = open(sys.argv[2]).read()
# The program's eight corner arcs (four with I J, two with R in the
# finishing loop, two more with I J) are all compensated, none skipped.
assert c["arcs_compensated"] == 8, c
assert not c["lines_skipped"], c
arcs = re.findall(r"^N\d+ G3 .*\(robomill: compensated arc, radius ([+-]\d+\.\d) um", text, re.M)
assert len(arcs) == 8, arcs
# The walls' error against the programmed path falls at least fivefold at
# the median and threefold at the 90th percentile (the corners, where one
# point finishes two walls, keep the largest; docs/toolpath.md).
before, residual = c["form_error_before_um"], c["residual_um"]
assert residual["median"] <= before["median"] / 5, c
assert residual["p90"] <= before["p90"] / 3, c
assert residual["max"] < before["max"], c
# The material left makes every arc's radius grow (the tool is pushed off
# the concave corner's wall, towards the pocket's middle).
assert all(float(r) > 0 for r in arcs), arcs
# An R arc keeps its R word, grown by its radius change.
for line in re.findall(r"^N1(?:25|45) G3 .*$", text, re.M):
    radius = float(re.search(r"R(\d+\.\d+)", line).group(1))
    change = float(re.search(r"radius ([+-]\d+\.\d) um", line).group(1))
    assert abs(radius - (3.0 + change * 1e-3)) < 1e-4, line
PYEOF
# The written program on its own: it reads and runs.
"$ROBOMILL" toolpath "$R" --out "$WORK/again" --quiet "${FAST[@]}" \
  --set "toolpath.file=$WORK/arcs/program_optimized.nc" || fail "the written program does not run"
finish
