#!/usr/bin/env bash
# A bull-nose end mill along a program (issue 31, points 1 and 2): the
# example z-level roughing (examples/toolpath_bull_nose_gcode.yaml, a 16 mm
# cutter with a 2 mm corner, 1.37 mm steps and a 0.3 mm floor finish over a
# 0.5 mm dexel stock). ap is the program's on every steady row whatever the
# grid; `forces` and `stability` take the same job's bull nose; a corner
# radius the tool cannot have is an error naming the key.
source "$(dirname "$0")/lib.bash"
J="$SOURCE/examples/toolpath_bull_nose_gcode.yaml"

"$ROBOMILL" toolpath "$J" --out "$WORK/tp" --quiet || fail "toolpath exit code"
/usr/bin/python3 - "$WORK/tp/samples.csv" <<'PYEOF' || fail "bull-nose depths"
import csv, sys
from collections import Counter
rows = [r for r in csv.DictReader(open(sys.argv[1])) if float(r["ap_mm"]) > 0]
by_line = {}
for r in rows:
    by_line.setdefault(int(r["line"]), []).append(float(r["ap_mm"]))
def steady(line):
    return Counter(round(a, 4) for a in by_line[line]).most_common(1)[0]
# Rows 2-4 of each roughing layer cut 1.37 mm under the layer above; the
# finish 0.3 mm: the most common ap of each row, in at least 90 % of its
# engaged samples (the rest are its ends).
for line, depth in [(13, 1.37), (15, 1.37), (24, 1.37), (26, 1.37), (35, 1.37), (37, 1.37),
                    (47, 0.3), (49, 0.3)]:
    value, count = steady(line)
    assert abs(value - depth) < 1e-3, (line, value)
    assert count >= 0.9 * len(by_line[line]), (line, count, len(by_line[line]))
PYEOF

"$ROBOMILL" forces "$J" --out "$WORK/forces" --quiet || fail "forces exit code"
[ -s "$WORK/forces/forces.csv" ] || fail "no forces.csv"
"$ROBOMILL" stability "$J" --out "$WORK/sld" --quiet || fail "stability exit code"
[ -s "$WORK/sld/sld.csv" ] || fail "no sld.csv"

# The robot along the program with a bull nose (the KR 270 pocket, its T1 a
# 1.5 mm-corner bull nose): every engaged sample gets its posture, chatter
# margin and deflection, as with the flat end mill.
R="$SOURCE/examples/toolpath_robot_pocket.yaml"
FAST=(--set "toolpath.spacing=0.5 mm" --set "stability.speeds={from: 4000 rpm, to: 12000 rpm, count: 41}")
"$ROBOMILL" toolpath "$R" --out "$WORK/robot" --quiet "${FAST[@]}" \
  --set "toolpath.tools.T1={type: bull, corner_radius: 1.5 mm, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}" \
  || fail "robot with a bull nose exit code"
/usr/bin/python3 - "$WORK/robot/summary.json" <<'PYEOF' || fail "robot along the program with a bull nose"
import json, math, sys
r = json.load(open(sys.argv[1]))["robot_along_path"]
assert r["analysed_samples"] > 400 and r["stability_samples"] == r["analysed_samples"], r
assert math.isfinite(r["min_margin"]) and r["min_margin"] > 0, r
assert 0 < r["max_deflection_um"] < 1000, r
PYEOF

expect_exit2 "tool.corner_radius" forces "$J" --set "tool.corner_radius=9 mm"
expect_exit2 "tool.corner_radius" forces "$J" --set "tool.type=flat"
finish
