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

expect_exit2 "tool.corner_radius" forces "$J" --set "tool.corner_radius=9 mm"
expect_exit2 "tool.corner_radius" forces "$J" --set "tool.type=flat"
finish
