#!/usr/bin/env bash
# `robomill toolpath --optimize` writing a KRL program: the example pocket
# (examples/programs/pocket.src/.dat) on the KR 270 with a 60° angle head,
# a redundancy schedule ψ(s) per line and the deflection compensation of the
# example job. Each Cartesian point's frame is turned by the angle of the
# line that ends at it (the slot's partial frame completed with the
# orientation it inherits), within the joint-speed bound; the points move
# where they are written (inline in the .src, the FOR loops' points in the
# .dat) with points added inside the lines that run once; and the written
# pair analysed on its own gives the compensated program's figures.
source "$(dirname "$0")/lib.bash"
R="$SOURCE/examples/toolpath_robot_pocket.yaml"
KRL_TOOLPATH='{format: krl, bases: {1: [0, 0, 0, 0, 0, 0]}, tool_direction: x, spindle: 8000 rpm, spacing: 0.5 mm, tools: {T1: {type: flat, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}}}'
KRL_HEAD=(--set "toolpath=$KRL_TOOLPATH" --set 'robot.tool={xyz: [0, 0, 350], rpy: [180, 60, 0]}'
  --set "stability.speeds={from: 4000 rpm, to: 12000 rpm, count: 41}")
"$ROBOMILL" toolpath "$R" --out "$WORK/krl" --quiet --optimize "${KRL_HEAD[@]}" \
  --set "toolpath.file=$SOURCE/examples/programs/pocket.src" \
  --set "toolpath.dat=$SOURCE/examples/programs/pocket.dat" \
  --set 'robot_path.redundancy_search={from: -90 deg, to: 90 deg, count: 13, per_line: true, joint_speed_max: 20 deg/s}' \
  || fail "--optimize of a KRL program exit code"
for f in redundancy_schedule.csv program_optimized.src program_optimized.dat; do
  [ -s "$WORK/krl/$f" ] || fail "no $f"
done
"$ROBOMILL" toolpath "$R" --out "$WORK/again" --quiet "${KRL_HEAD[@]}" --set robot_path.compensation=null \
  --set "toolpath.file=$WORK/krl/program_optimized.src" || fail "the written KRL program"
/usr/bin/python3 - "$WORK/krl" "$WORK/again" <<'PYEOF' || fail "KRL program written"
import json, re, sys
o = json.load(open(sys.argv[1] + "/summary.json"))["optimization"]
src = open(sys.argv[1] + "/program_optimized.src").read()
dat = open(sys.argv[1] + "/program_optimized.dat").read()
# ψ(s): more than one angle, every turn within 20 deg/s, nothing newly at risk.
r = o["redundancy"]
assert r["per_line"] and r["frames"] and r["changed"] and "per_line_refused" not in r, r
assert r["min_margin_after"] > r["min_margin_before"] and o["samples_newly_at_risk"] == 0, o
assert len({(l["from_deg"], l["to_deg"]) for l in r["lines"]}) > 1, r["lines"]
assert all(l["turn_joint_speed_deg_s"] <= 20.0 + 1e-9 for l in r["lines"]), r["lines"]
assert o["after"]["max_joint_speed_deg_s"] <= 20.0 * 1.001, o["after"]
# The slot turns: its point, written without A, B, C, now has them.
assert re.search(r"^LIN \{X [0-9.]+,Y [0-9.]+,Z 17,A 90,B 90,C 0\}", src, re.M), src
# The compensation: inline points before the lines that run once, the FOR
# loops' points moved in the .dat; the walls' error at the median falls
# fourfold (the loops' lines move their ends only, so the 90th percentile
# falls less).
c = o["compensation"]
assert c["lines_compensated"] > 0 and c["points_added"] > 0 and not c["lines_skipped"], c
assert len(re.findall(r"^LIN \{X[^}]*\} C_DIS ; robomill: compensated", src, re.M)) == c["points_added"]
assert re.search(r"^SIDE\[1\]=\{X [0-9.]+,Y [0-9.]+,Z 17,A 90,B 90,C 0\} ; robomill: compensated", dat, re.M), dat
before, residual = c["form_error_before_um"], c["residual_um"]
assert residual["median"] <= before["median"] / 4 and residual["p90"] < before["p90"], c
# The written pair alone: the compensated program's figures.
again = json.load(open(sys.argv[2] + "/summary.json"))["robot_along_path"]
compensated = c["compensated"]
assert abs(again["min_margin"] - compensated["min_margin"]) <= 1e-9 * compensated["min_margin"], (again, compensated)
assert again["at_risk_samples"] == compensated["at_risk_samples"], (again, compensated)
angles = [a for l in r["lines"] for a in (l["from_deg"], l["to_deg"])]
lo, hi = again["redundancy_range_deg"]
assert min(angles) - 1e-9 <= lo and hi <= max(angles) + 1e-9, (again["redundancy_range_deg"], angles)
print(f"psi per line: min margin {r['min_margin_before']:.3f} -> {again['min_margin']:.3f}; "
      f"walls' error median {before['median']:.1f} -> {residual['median']:.1f} um, "
      f"p90 {before['p90']:.1f} -> {residual['p90']:.1f} um")
PYEOF
finish
