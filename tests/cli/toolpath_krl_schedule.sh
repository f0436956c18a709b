#!/usr/bin/env bash
# `robomill toolpath --optimize` with a redundancy schedule ψ(s) on a KRL
# program: the example pocket (examples/programs/pocket.src/.dat) on the KR
# 270 with a 60° angle head, per_line search. Each Cartesian point's frame is
# turned by the angle of the line that ends at it (the slot's partial frame
# completed with the orientation it inherits), the turns stay within the
# joint-speed bound, and the written pair analysed on its own gives the
# re-run's figures.
source "$(dirname "$0")/lib.bash"
R="$SOURCE/examples/toolpath_robot_pocket.yaml"
KRL_TOOLPATH='{format: krl, bases: {1: [0, 0, 0, 0, 0, 0]}, tool_direction: x, spindle: 8000 rpm, spacing: 0.5 mm, tools: {T1: {type: flat, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}}}'
sed -e '/^  compensation:/d' -e "s|file: programs/pocket.nc|file: $SOURCE/examples/programs/pocket.nc|" \
  "$R" > "$WORK/robot_krl.yaml"
KRL_HEAD=(--set "toolpath=$KRL_TOOLPATH" --set 'robot.tool={xyz: [0, 0, 350], rpy: [180, 60, 0]}'
  --set "stability.speeds={from: 4000 rpm, to: 12000 rpm, count: 41}")
"$ROBOMILL" toolpath "$WORK/robot_krl.yaml" --out "$WORK/psi" --quiet --optimize "${KRL_HEAD[@]}" \
  --set "toolpath.file=$SOURCE/examples/programs/pocket.src" \
  --set "toolpath.dat=$SOURCE/examples/programs/pocket.dat" \
  --set 'robot_path.redundancy_search={from: -90 deg, to: 90 deg, count: 13, per_line: true, joint_speed_max: 20 deg/s}' \
  || fail "--optimize with a KRL schedule exit code"
[ -s "$WORK/psi/redundancy_schedule.csv" ] || fail "no redundancy_schedule.csv"
"$ROBOMILL" toolpath "$WORK/robot_krl.yaml" --out "$WORK/again" --quiet "${KRL_HEAD[@]}" \
  --set "toolpath.file=$WORK/psi/program_optimized.src" || fail "the written KRL program"
/usr/bin/python3 - "$WORK/psi" "$WORK/again" <<'PYEOF' || fail "KRL frames turned per line"
import json, re, sys
o = json.load(open(sys.argv[1] + "/summary.json"))["optimization"]
r = o["redundancy"]
assert r["per_line"] and r["frames"] and r["changed"] and "per_line_refused" not in r, r
assert r["min_margin_after"] > r["min_margin_before"] and o["samples_newly_at_risk"] == 0, o
assert len({(l["from_deg"], l["to_deg"]) for l in r["lines"]}) > 1, r["lines"]  # not one angle
assert all(l["turn_joint_speed_deg_s"] <= 20.0 + 1e-9 for l in r["lines"]), r["lines"]
assert o["after"]["max_joint_speed_deg_s"] <= 20.0 * 1.001, o["after"]
# The written pair alone: the re-run's margin, form error and risk, and ψ over
# the cut within the schedule's angles.
again = json.load(open(sys.argv[2] + "/summary.json"))["robot_along_path"]
after = o["after"]
for key in ("min_margin", "max_form_error_um"):
    assert abs(again[key] - after[key]) <= 1e-9 * abs(after[key]), (key, again[key], after[key])
assert again["at_risk_samples"] == after["at_risk_samples"], (again, after)
angles = [a for l in r["lines"] for a in (l["from_deg"], l["to_deg"])]
lo, hi = again["redundancy_range_deg"]
assert min(angles) - 1e-9 <= lo and hi <= max(angles) + 1e-9, (again["redundancy_range_deg"], angles)
# A line that turns and had no orientation of its own now has a complete frame.
src = open(sys.argv[1] + "/program_optimized.src").read()
during = [l for l in r["lines"] if l["turn"] == "during"]
for line in during:
    print(f"line {line['line']} turns {line['from_deg']:.0f} -> {line['to_deg']:.0f} deg")
print(f"min margin {r['min_margin_before']:.3f} -> {again['min_margin']:.3f} on the written program")
PYEOF
finish
