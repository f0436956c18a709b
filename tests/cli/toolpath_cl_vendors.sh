#!/usr/bin/env bash
# `robomill toolpath` on CL files as CAM systems write them (issue 31): two
# Siemens NX CLSF files in inches with no UNITS and no SPINDL record — a
# 5-axis variable-axis ball finish and a profile with a bull-nose end mill —
# read as inches from FEDRAT/IPM, their vendor records (SELECT/TOOL, PAINT)
# skipped and noted, analysed end to end over a stock box around the part.
# Then the unit's errors: a program read in the wrong unit names the key
# that fixes it; a UNITS record that disagrees with toolpath.units names both;
# a bull nose that differs from the job's cutter is refused naming both.
source "$(dirname "$0")/lib.bash"
P="$SOURCE/tests/cli/programs"
V="$P/nx_variable_contour_in.yaml"
B="$P/nx_profile_bull_in.yaml"

"$ROBOMILL" toolpath "$V" --out "$WORK/v" --quiet || fail "NX variable contour exit code"
"$ROBOMILL" toolpath "$B" --out "$WORK/b" --quiet || fail "NX bull-nose profile exit code"
/usr/bin/python3 - "$WORK/v" "$WORK/b" <<'PYEOF' || fail "NX inch CLSF analysed"
import csv, json, math, sys
v = json.load(open(sys.argv[1] + "/summary.json"))
b = json.load(open(sys.argv[2] + "/summary.json"))
for s in (v, b):
    assert s["dialect"] == "apt", s["dialect"]
    notes = [n["text"] for n in s["notes"]]
    assert any("gives feeds in inches" in n for n in notes), notes
    assert any(n.startswith("SELECT (1 record from line 8)") for n in notes), notes
    assert any(n.startswith("PAINT (") for n in notes), notes
    assert not any("not described" in w["text"] for w in s["warnings"]), s["warnings"]

def rows(folder):
    return list(csv.DictReader(open(folder + "/samples.csv")))

# The ball finish: every feed sample at 12000 rpm (toolpath.spindle: the file
# has no SPINDL) and 40 in/min on the cut; positions in mm (inches read).
rv = rows(sys.argv[1])
cut = [r for r in rv if float(r["ap_mm"]) > 0]
assert len(cut) > 1000, len(cut)
assert all(abs(float(r["spindle_rpm"]) - 12000) < 1e-6 for r in cut)
feeds = {round(float(r["feed_mm_min"]), 6) for r in cut}
assert feeds <= {round(20 * 25.4, 6), round(40 * 25.4, 6)} and round(40 * 25.4, 6) in feeds, feeds
xs = [float(r["x_mm"]) for r in rv]
assert abs(min(xs) + 1.35 * 25.4) < 0.01 and abs(max(xs) - 0.9 * 25.4) < 0.01, (min(xs), max(xs))
# The axis leans up to 26.7 deg from z (x = ±0.9 in on a 2 in radius).
lean = max(math.degrees(math.acos(min(1.0, float(r["axis_k"])))) for r in rv)
assert abs(lean - math.degrees(math.asin(0.45))) < 0.1, lean
# The ball finish removes material (with a tilted axis the stock once cut
# offset by its box's min and removed nothing here; issue 31), and the same
# wherever the setup sits: see the run moved 20 mm up below.
assert v["volume_removed_mm3"] > 1000, v["volume_removed_mm3"]

# The bull-nose profile: the stock outside the 2 x 1.5 in part (0.25 in
# corners) within the 2.2 x 1.7 in box, 0.25 in deep — read in millimetres
# the program would cut 1/25.4 of it in each direction. A flat end removes
# all of it; the 0.06 in corner leaves a fillet r^2 (1 - pi/4) along the
# wall's foot (its centroid 0.2234 r off the wall: 5 in of straight wall and
# 2 pi (0.25 + 0.2234 r) round the corners). The stock's dexels resolve the
# ring to about 1 % at 0.5 mm (measured 3128.1 mm^3 against 3167.1: -1.2 %);
# the fillet must be left: below halfway to the flat end's volume.
inch = 25.4
ring = 2.2 * 1.7 - (2.0 * 1.5 - (4 - math.pi) * 0.25 ** 2)
flat = ring * 0.25 * inch ** 3
r = 0.06
fillet = r ** 2 * (1 - math.pi / 4) * (5.0 + 2 * math.pi * (0.25 + r * (10 - 3 * math.pi) / (12 - 3 * math.pi)))
bull = flat - fillet * inch ** 3
removed = b["volume_removed_mm3"]
print(f"NX profile, bull nose: removed {removed:.1f} mm^3; analytic {bull:.1f} (bull nose), "
      f"{flat:.1f} (flat end); ball finish: {len(cut)} cutting samples of {len(rv)}, "
      f"lean up to {lean:.2f} deg")
assert 0.97 * bull < removed < 0.5 * (bull + flat), (removed, bull, flat)
rb = rows(sys.argv[2])
assert all(abs(float(r["spindle_rpm"]) - 6000) < 1e-6 for r in rb if float(r["ap_mm"]) > 0)
PYEOF

# The ball finish with the setup 20 mm higher (program origin and stock box
# moved together) removes the same volume.
"$ROBOMILL" toolpath "$V" --out "$WORK/v_up" --quiet --set "toolpath.origin=[0, 0, 20]" \
  --set "stock.box={min: [-17.78, -5.08, 4.76], max: [17.78, 43.18, 20]}" || fail "moved exit code"
/usr/bin/python3 - "$WORK/v/summary.json" "$WORK/v_up/summary.json" <<'PYEOF' || fail "same volume moved"
import json, sys
a, b = (json.load(open(p))["volume_removed_mm3"] for p in sys.argv[1:3])
assert abs(a - b) <= 1e-6 * a, (a, b)
PYEOF

# The same program read in millimetres (toolpath.units: mm): its cutter is
# 0.25 mm, which is the job's 6.35 mm only in inches; the error says so.
expect_exit2 "toolpath.units: inch" toolpath "$V" --set toolpath.units=mm
expect_exit2 "nx_variable_contour_ball_in.cls (line 2)" toolpath "$V" --set toolpath.units=mm
# A UNITS record that disagrees with toolpath.units: refused naming both.
{ printf 'UNITS/MM\r\n'; cat "$SOURCE/tests/toolpath/apt/nx_profile_bull_in.cls"; } > "$WORK/units_mm.cls"
expect_exit2 "UNITS/MM says the program is in millimetres, but toolpath.units says inch" \
  toolpath "$B" --set "toolpath.file=$WORK/units_mm.cls" --set toolpath.units=inch
# Without toolpath.units the record rules: the cutter is then 0.5 mm, and the
# error points at the program's unit word, not at a key that cannot help.
expect_exit2 "if the program is in inches, check the program's unit word" \
  toolpath "$B" --set "toolpath.file=$WORK/units_mm.cls"
# toolpath.units is for CL files only.
expect_exit2 "only for APT / CL programs" toolpath "$SOURCE/examples/toolpath_pocket_gcode.yaml" \
  --set toolpath.units=inch
# The bull nose against a job cutter with another corner, and against a flat.
expect_exit2 "bull-nose end mill" toolpath "$B" \
  --set 'toolpath.tools={T1: {type: bull, diameter: 12.7 mm, corner_radius: 2 mm, teeth: 4, overhang: 40 mm}}'
expect_exit2 "corner radius of 1.524 mm (a bull-nose end mill), toolpath.tools.T1 is a flat end mill" \
  toolpath "$B" --set 'toolpath.tools={T1: {type: flat, diameter: 12.7 mm, teeth: 4, overhang: 40 mm}}'
finish
