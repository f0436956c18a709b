#!/usr/bin/env bash
# `robomill toolpath`: the example programs in G-code, KRL and APT CL run to
# the documented files, columns and summary keys; bad programs and jobs exit 2
# naming the program line and word (or the job field), writing nothing.
source "$(dirname "$0")/lib.bash"
G="$SOURCE/examples/toolpath_pocket_gcode.yaml"
K="$SOURCE/examples/toolpath_pocket_krl.yaml"
A="$SOURCE/examples/toolpath_ball_5axis_apt.yaml"
P="$SOURCE/tests/cli/programs"
KRL_TOOLPATH='{format: krl, bases: {1: [0, 0, 0, 0, 0, 0]}, tool_direction: x, spindle: 8000 rpm, spacing: 0.5 mm, tools: {T1: {type: flat, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}}}'

"$ROBOMILL" toolpath "$G" --out "$WORK/g" --quiet || fail "gcode example exit code"
for f in summary.json samples.csv samples_preview.csv moves.csv stock.csv inputs.json; do
  [ -s "$WORK/g/$f" ] || fail "toolpath did not write $f"
done
header=$(head -1 "$WORK/g/samples.csv")
for column in line t_s x_mm y_mm z_mm axis_i axis_j axis_k feed_mm_min spindle_rpm ap_mm ae_mm \
  engagement_deg entry_deg exit_deg chip_area_mm2 force_mean_N force_peak_N torque_Nm power_W; do
  case ",$header," in *",$column,"*) ;; *) fail "samples.csv lacks $column" ;; esac
done
for key in cutting_time_s air_time_s volume_removed_mm3 max_force_N max_force_line max_torque_Nm \
  max_torque_line max_power_W max_power_line warnings; do
  grep -q "\"$key\"" "$WORK/g/summary.json" || fail "summary.json lacks $key"
done
grep -qi 'nan\|inf' "$WORK/g/samples.csv" "$WORK/g/summary.json" && fail "non-finite number written"
ls -a "$WORK/g" | grep -q '^\.' && ls -a "$WORK/g" | grep -q 'stream-\|tmp-' && fail "temporary left"
# The drill T2 is not described: listed in moves.csv, reported, not analysed.
grep -q 'T2 is not described' "$WORK/g/summary.json" || fail "undescribed T2 not reported"
# The pocket removes the ramp, the slot, the side cut and the finishing loop:
# (40 x 24 mm with R 5 corners) x 3 mm minus the ramp's wedge, and the four
# holes are not cut (T2 undescribed). The pocket's area: 40 * 24 - (4 - pi) * 25.
v=$(awk -F': ' '/"volume_removed_mm3"/ { gsub(/,/, "", $2); print $2 }' "$WORK/g/summary.json")
awk -v v="$v" 'BEGIN { a = 40 * 24 - (4 - 3.14159265) * 25; exit !(v > 0.97 * a * 3 && v < 1.01 * a * 3) }' \
  || fail "removed volume $v mm^3"

# The stock an earlier run left (stock.height_map): the same pocket 1 mm lower
# removes one more millimetre of the pocket's area, 938.5 mm^3.
"$ROBOMILL" toolpath "$G" --set "stock.height_map=$WORK/g/stock.csv" --set "toolpath.origin=[0, 0, -1]" \
  --out "$WORK/again" --quiet || fail "height-map stock exit code"
v=$(awk -F': ' '/"volume_removed_mm3"/ { gsub(/,/, "", $2); print $2 }' "$WORK/again/summary.json")
awk -v v="$v" 'BEGIN { a = 40 * 24 - (4 - 3.14159265) * 25; exit !(v > 0.97 * a && v < 1.03 * a) }' \
  || fail "removed volume from the height map $v mm^3"

"$ROBOMILL" toolpath "$K" --out "$WORK/k" --quiet || fail "krl example exit code"
[ -s "$WORK/k/samples.csv" ] || fail "krl: no samples.csv"
"$ROBOMILL" toolpath "$A" --out "$WORK/a" --quiet || fail "apt example exit code"
grep -q '"dialect": "apt"' "$WORK/a/summary.json" || fail "apt: dialect"

# Programs refused by line and word; nothing written.
expect_exit2 "compensated.nc (line 8)" toolpath "$G" --set "toolpath.file=$P/compensated.nc"
expect_exit2 "G41" toolpath "$G" --set "toolpath.file=$P/compensated.nc"
expect_exit2 "bad_arc.nc (line 7)" toolpath "$G" --set "toolpath.file=$P/bad_arc.nc"
expect_exit2 "no_feed.nc (line 5)" toolpath "$G" --set "toolpath.file=$P/no_feed.nc"
expect_exit2 "12 mm in diameter" toolpath "$A" --set "toolpath.file=$P/wrong_cutter.cl" \
  --set 'toolpath.tools={T1: {type: flat, diameter: 10, teeth: 3}}'
# A program that never touches the stock (its zero 1 m away).
expect_exit2 "toolpath.origin" toolpath "$G" --set "toolpath.origin=[1000, 0, 0]"
# A missing program, a program over max_size, an unknown dialect.
expect_exit2 "toolpath.file" toolpath "$G" --set "toolpath.file=missing.nc"
expect_exit2 "max_size" toolpath "$G" --set "toolpath.max_size=0.0001"
truncate -s 100M "$WORK/huge.nc"  # a 100 MB program (sparse): refused before it is read
expect_exit2 "100.0 MiB, more than toolpath.max_size" toolpath "$G" --set "toolpath.file=$WORK/huge.nc"
printf 'G90 G21\nT1 M6\nS8000 M3\nG0 X10 Y20 Z25\nG1 Z17 F600\nG1 X20 E5\n' > "$WORK/unknown.nc"
expect_exit2 "unknown.nc (line 6)" toolpath "$G" --set "toolpath.file=$WORK/unknown.nc"
expect_exit2 "format: gcode, apt or krl" toolpath "$G" --set "toolpath.file=pocket.txt"
# The job: a stock box inside out, KRL keys on G-code.
expect_exit2 "stock.box.max" toolpath "$G" --set "stock.box.max=[60, 40, -5]"
expect_exit2 "only for KRL" toolpath "$G" --set "toolpath.tool_direction=z"

# The robot along the program (issue 19): the pocket on the KR 270.
R="$SOURCE/examples/toolpath_robot_pocket.yaml"
"$ROBOMILL" toolpath "$R" --out "$WORK/r" --quiet || fail "robot example exit code"
header=$(head -1 "$WORK/r/samples.csv")
for column in psi_deg q1_deg q6_deg reachable joint_margin_deg singularity ap_limit_mm margin \
  chatter at_risk chatter_freq_hz dev_x_um dev_y_um dev_z_um deflection_um form_error_um \
  floor_error_um dynamics_recomputed; do
  case ",$header," in *",$column,"*) ;; *) fail "robot samples.csv lacks $column" ;; esac
done
for key in robot_along_path fraction_at_risk min_margin min_margin_line max_form_error_um \
  worst_lines worst_posture joint_origins_mm shortcut_max_error dynamics_recomputations; do
  grep -q "\"$key\"" "$WORK/r/summary.json" || fail "robot summary.json lacks $key"
done
grep -qi 'nan\|inf' "$WORK/r/samples.csv" "$WORK/r/summary.json" && fail "non-finite number written"
# 000's contact boundary at the down-milling walls (robot_path.deflection).
"$ROBOMILL" toolpath "$R" --out "$WORK/rc" --quiet --set robot_path.deflection=contact \
  || fail "robot example with the contact deflection"
grep -q '"deflection_model": "contact"' "$WORK/rc/summary.json" || fail "no deflection_model contact"
contact=$(json_number "$WORK/rc/summary.json" robot_along_path contact_samples)
[ "${contact:-0}" -gt 0 ] || fail "no sample by the contact boundary"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "contact") c = i; if (!c) exit 1 }' \
  "$WORK/rc/samples.csv" || fail "samples.csv lacks contact"
expect_exit2 "static, contact" toolpath "$R" --set robot_path.deflection=nodes
unreachable=$(json_number "$WORK/r/summary.json" robot_along_path unreachable_samples)
[ "$unreachable" = "0" ] || fail "the example's part is out of reach: $unreachable samples"
# --optimize runs the analysis six times and more (the first pass, the speed
# search, the feed runs, the re-run): a 0.5 mm sample spacing and 41
# candidate speeds keep it to seconds here and to minutes under ASan.
FAST=(--set "toolpath.spacing=0.5 mm" --set "stability.speeds={from: 4000 rpm, to: 12000 rpm, count: 41}")
# --optimize: the spindle speeds written back, read back by the G-code reader,
# no sample newly at risk, the chosen speed inside stability.speeds.
"$ROBOMILL" toolpath "$R" --out "$WORK/o" --quiet --optimize "${FAST[@]}" || fail "--optimize exit code"
[ -s "$WORK/o/program_optimized.nc" ] || fail "--optimize wrote no program_optimized.nc"
grep -q '(robomill: S8000 -> S' "$WORK/o/program_optimized.nc" || fail "no commented S change"
newly=$(awk -F': ' '/"samples_newly_at_risk"/ { gsub(/,/, "", $2); print $2 }' "$WORK/o/summary.json")
[ "$newly" = "0" ] || fail "--optimize put $newly samples newly at risk"
awk -F': ' '/"chosen_rpm"/ { gsub(/,/, "", $2); v = $2 + 0; if (v < 4000 || v > 12000.001) bad = 1 } END { exit bad }' \
  "$WORK/o/summary.json" || fail "a chosen speed outside stability.speeds"
"$ROBOMILL" toolpath "$G" --set "toolpath.file=$WORK/o/program_optimized.nc" --out "$WORK/o2" --quiet \
  || fail "the optimized program does not read back"
# The feeds under robot_path.feed_limits: measured again on the written
# program, every cap holds and every feed lies in [feed_min, feed_max]; the
# lines changed carry their comment.
/usr/bin/python3 - "$WORK/o/summary.json" "$WORK/o/program_optimized.nc" <<'PYEOF' || fail "--optimize feeds"
import json, re, sys
o = json.load(open(sys.argv[1]))["optimization"]
feeds, after = o["feeds"], o["after"]
limits = feeds["limits"]
assert feeds["lines_changed"] > 0 and feeds["lines_slowed"] > 0, feeds
assert after["max_force_N"] <= limits["force_max_N"] * (1 + 1e-6), after
assert after["max_deflection_um"] <= limits["deflection_max_um"] * (1 + 1e-6), after
assert feeds["max_after"]["joint_speed_deg_s"] <= limits["joint_speed_max_deg_s"] * (1 + 1e-9)
for change in feeds["changes"]:
    assert limits["feed_min_mm_min"] - 1e-6 <= change["chosen_mm_min"] <= limits["feed_max_mm_min"] + 1e-6
text = open(sys.argv[2]).read()
assert len(re.findall(r"\(robomill: feed \d+ -> \d+ mm/min", text)) == feeds["lines_changed"], text
assert o["samples_compared"] == o["samples_before"], o
# The compensation (robot_path.compensation in the example): the written
# program analysed again, the walls' error against the programmed path. The
# median and the 90th percentile fall at least fivefold; the largest stays at
# the corners, where one point finishes two walls (docs/toolpath.md).
c = o["compensation"]
assert c["lines_compensated"] > 0 and c["points_added"] > 0, c
before, residual = c["form_error_before_um"], c["residual_um"]
assert residual["median"] <= before["median"] / 5 and residual["p90"] <= before["p90"] / 5, c
assert c["compensated"]["at_risk_samples"] <= after["at_risk_samples"], c
assert c["compensated"]["max_force_N"] <= limits["force_max_N"] * 1.01, c
assert len(re.findall(r"\(robomill: compensated", text)) >= c["lines_compensated"], text
PYEOF
# ψ(s) on a 60° angle head (ψ moves the arm): one angle per line, turning
# within 20 deg/s; the re-run's joints stay within it, no sample newly at risk.
"$ROBOMILL" toolpath "$R" --out "$WORK/psi" --quiet --optimize "${FAST[@]}" \
  --set 'robot.tool={xyz: [0, 0, 350], rpy: [180, 60, 0]}' \
  --set 'robot_path.redundancy_search={from: -90 deg, to: 90 deg, count: 13, per_line: true, joint_speed_max: 20 deg/s}' \
  || fail "--optimize with a redundancy schedule exit code"
[ -s "$WORK/psi/redundancy_schedule.csv" ] || fail "no redundancy_schedule.csv"
/usr/bin/python3 - "$WORK/psi/summary.json" <<'PYEOF' || fail "redundancy schedule"
import json, sys
o = json.load(open(sys.argv[1]))["optimization"]
r = o["redundancy"]
assert r["per_line"] and r["changed"] and r["min_margin_after"] > r["min_margin_before"], r
assert all(line["turn_joint_speed_deg_s"] <= 20.0 + 1e-9 for line in r["lines"]), r
assert o["after"]["max_joint_speed_deg_s"] <= 20.0 * 1.001, o["after"]
assert o["samples_newly_at_risk"] == 0, o
PYEOF
# ψ of a KRL program on the angle head: the search turns the program's frames
# about the tool axis, writes the turn into the A, B, C of every Cartesian
# point of program_optimized.src and .dat, and the written pair analysed on
# its own gives the re-run's figures (the compensation is left out here:
# cli.toolpath_krl runs the two together).
sed -e '/^  compensation:/d' -e "s|file: programs/pocket.nc|file: $SOURCE/examples/programs/pocket.nc|" \
  "$R" > "$WORK/robot_krl.yaml"
KRL_HEAD=(--set "toolpath=$KRL_TOOLPATH" --set 'robot.tool={xyz: [0, 0, 350], rpy: [180, 60, 0]}'
  --set "stability.speeds={from: 4000 rpm, to: 12000 rpm, count: 41}")
"$ROBOMILL" toolpath "$WORK/robot_krl.yaml" --out "$WORK/krl_psi" --quiet --optimize "${KRL_HEAD[@]}" \
  --set "toolpath.file=$SOURCE/examples/programs/pocket.src" \
  --set "toolpath.dat=$SOURCE/examples/programs/pocket.dat" \
  --set 'robot_path.redundancy_search={from: -90 deg, to: 90 deg, count: 13}' \
  || fail "--optimize of a KRL program's ψ exit code"
[ -s "$WORK/krl_psi/program_optimized.dat" ] || fail "KRL ψ: no program_optimized.dat"
"$ROBOMILL" toolpath "$WORK/robot_krl.yaml" --out "$WORK/krl_psi_again" --quiet "${KRL_HEAD[@]}" \
  --set "toolpath.file=$WORK/krl_psi/program_optimized.src" || fail "the turned KRL program"
/usr/bin/python3 - "$WORK/krl_psi" "$WORK/krl_psi_again" <<'PYEOF' || fail "KRL frames turned"
import json, sys
o = json.load(open(sys.argv[1] + "/summary.json"))["optimization"]
r = o["redundancy"]
assert r["frames"] and r["chosen_deg"] != r["programmed_deg"], r
assert r["frames_turned"] == 13, r  # 2 inline PTP frames, XHOME and 10 array points
assert r["min_margin_after"] > r["min_margin_before"] and o["samples_newly_at_risk"] == 0, o
again = json.load(open(sys.argv[2] + "/summary.json"))["robot_along_path"]
assert all(abs(v - r["chosen_deg"]) < 1e-9 for v in again["redundancy_range_deg"]), again
after = o["after"]
for key in ("min_margin", "max_form_error_um"):
    assert abs(again[key] - after[key]) <= 1e-9 * abs(after[key]), (key, again[key], after[key])
assert again["at_risk_samples"] == after["at_risk_samples"], (again, after)
print(f"KRL frames turned by {r['chosen_deg']:.0f} deg: min margin {r['min_margin_before']:.3f} -> "
      f"{again['min_margin']:.3f} on the written program")
PYEOF
# A cap no feed can meet: an error naming the program line, nothing written.
expect_exit2 "no feed satisfies the limits" toolpath "$R" --optimize "${FAST[@]}" \
  --set 'robot_path.feed_limits={force_max: 20 N, feed_min: 200 mm/min}'
expect_exit2 "robot_path.feed_limits.feed_max" toolpath "$R" --optimize \
  --set 'robot_path.feed_limits={force_max: 100 N, feed_min: 200 mm/min, feed_max: 100 mm/min}'
expect_exit2 "stability.speeds" toolpath "$R" --optimize --set 'stability={method: zoa, depth_max: 10}' \
  --set 'robot_path.feed_limits=null'
expect_exit2 "needs the robot" toolpath "$G" --optimize
# The part out of the robot's reach, a robot_path without a pose.
expect_exit2 "reaches no sample" toolpath "$R" --set "workpiece.table=[9000, 0, 500]" \
  --set "toolpath.spacing=2 mm"
expect_exit2 "needs a robot" toolpath "$G" --set "robot_path.redundancy=10"
# Part of the program out of reach: reported by line; --optimize refuses.
"$ROBOMILL" toolpath "$R" --out "$WORK/far" --quiet --set "workpiece.table=[2820, -20, 560]" \
  --set "toolpath.spacing=1 mm" || fail "a partly unreachable program must still be analysed"
far=$(json_number "$WORK/far/summary.json" robot_along_path unreachable_samples)
[ "${far:-0}" -gt 0 ] || fail "the moved table should put samples out of reach"
expect_exit2 "cannot reach" toolpath "$R" --optimize --set "workpiece.table=[2820, -20, 560]" \
  --set "toolpath.spacing=1 mm"
# 004's groove as a program (examples/programs/004_groove.ngc) on 004's robot
# at Table 2's pose 6, with robot_path.offset: along the straight sides, where
# the stock leaves 004's band (up milling, ae = 4 mm less the dexel's 0.08 mm
# at 0.5 mm), each sample's offset against `robomill optimize`'s d_i at the
# same point (its path.csv). The band's 2 % smaller ae lowers the force and the
# offset by 1.6 %; the tolerance 2.5 % holds that and nothing more. The boss's
# corners, where the tool leaves the material, are 004's constant-engagement
# idealisation: the mean over the program is reported, not compared.
O4="$SOURCE/examples/004_kr300_pose_optimization.yaml"
"$ROBOMILL" toolpath "$O4" --out "$WORK/groove" --quiet \
  --set 'toolpath={file: programs/004_groove.ngc, spacing: 1 mm}' \
  --set 'stock={box: {min: [128, 8, -20], max: [272, 72, 2]}, resolution: 0.5 mm}' \
  --set 'workpiece.pose={x: 0 mm, y: -460 mm, theta: 0 deg}' --set 'robot_path={offset: {}}' \
  || fail "004 groove program exit code"
"$ROBOMILL" optimize "$O4" --out "$WORK/groove_opt" --quiet --set optimize.budget=5 \
  --set optimize.local_budget=0 --set 'optimize.landscape={x: 1, y: 1, theta: [0]}' \
  || fail "004 optimize exit code"
/usr/bin/python3 - "$WORK/groove/samples.csv" "$WORK/groove_opt/path.csv" "$WORK/groove/summary.json" <<'PYEOF' || fail "004 offset along the groove"
import csv, json, math, sys
samples = [r for r in csv.DictReader(open(sys.argv[1])) if r["offset_um"] != ""]
reference = [r for r in csv.DictReader(open(sys.argv[2])) if r["pose"] == "6"]  # optimize.poses[5]
assert len(reference) == 20, len(reference)
offset = json.load(open(sys.argv[3]))["robot_along_path"]["offset"]
assert offset["measure"] == "startup" and offset["samples"] == len(samples), offset
compared = 0
for point in reference:
    # optimize's points in the cell: the program's in the part are 004 Eq 7's
    # inverse at pose 6 (table [600, 0, 500] + [0, -460, 0], no tilt).
    x, y = float(point["x_mm"]) - 600.0, float(point["y_mm"]) + 460.0
    near = min(samples, key=lambda r: math.hypot(float(r["x_mm"]) - x, float(r["y_mm"]) - y))
    if math.hypot(float(near["x_mm"]) - x, float(near["y_mm"]) - y) > 1e-6:
        continue  # no sample in the cut there (a corner the tool only grazes)
    if abs(float(near["ae_mm"]) - 4.0) > 0.1 or float(near["entry_deg"]) > 1e-9:
        continue  # a corner of the boss: not 004's band
    d_ref, d = float(point["d_mm"]) * 1e3, float(near["offset_um"])
    assert abs(d - d_ref) <= 0.025 * d_ref, (x, y, d, d_ref)
    compared += 1
assert compared >= 12, compared
print(f"004 groove at pose 6: {compared} band points within 2.5 % of optimize's d_i; "
      f"program d_m {offset['dm_um']:.1f} um over {offset['samples']} samples")
PYEOF
# A KRL program's frames set ψ at every sample (the rotation about the tool
# axis): the example pocket in KRL on the KR 270, as written (A 0, B 90: ψ = 0)
# and with every frame turned by A 30. The spindle lies along joint 6, so the
# turn moves joint 6 by 30° and nothing else (q1-q5 within 1e-6°).
for case in a0:$SOURCE/examples/programs/pocket a30:$P/pocket_a30; do
  name=${case%%:*} program=${case#*:}
  "$ROBOMILL" toolpath "$R" --out "$WORK/krl_$name" --quiet --set "toolpath=$KRL_TOOLPATH" \
    --set "toolpath.file=$program.src" --set "toolpath.dat=$program.dat" \
    || fail "KRL pocket $name on the robot exit code"
done
/usr/bin/python3 - "$WORK/krl_a0" "$WORK/krl_a30" <<'PYEOF' || fail "KRL frames' ψ"
import csv, json, sys
runs = []
for folder in sys.argv[1:]:
    summary = json.load(open(folder + "/summary.json"))["robot_along_path"]
    assert summary["redundancy_source"] == "program", summary["redundancy_source"]
    assert summary["oriented_samples"] == summary["samples"], summary
    runs.append((summary, list(csv.DictReader(open(folder + "/samples.csv")))))
(s0, a0), (s30, a30) = runs
assert s0["redundancy_range_deg"] == [0.0, 0.0], s0["redundancy_range_deg"]
assert all(abs(v - 30.0) < 1e-9 for v in s30["redundancy_range_deg"]), s30["redundancy_range_deg"]
assert len(a0) == len(a30) > 500, (len(a0), len(a30))
for r0, r30 in zip(a0, a30):
    if r0["reachable"] != "1":
        continue
    assert abs(float(r30["psi_deg"]) - 30.0) < 1e-9, r30["psi_deg"]
    for j in range(1, 6):
        assert abs(float(r0[f"q{j}_deg"]) - float(r30[f"q{j}_deg"])) < 1e-6, (j, r0["line"])
    turn = (float(r30["q6_deg"]) - float(r0["q6_deg"]) + 180.0) % 360.0 - 180.0
    assert abs(abs(turn) - 30.0) < 1e-6, (turn, r0["line"])
print(f"KRL frames: psi 0 and 30 deg over {len(a0)} samples; joint 6 turns by 30 deg, q1-q5 kept")
PYEOF
finish
