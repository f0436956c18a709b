#!/usr/bin/env bash
# `robomill robot`: files, columns, summary keys, the workspace map, and bad
# robot input exiting 2 with the field named and nothing written.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/004_kr300_pose_optimization.yaml"

"$ROBOMILL" robot "$JOB" --set robot.map.counts=[4,3,1] --out "$WORK/r" --quiet || fail "robot exit code"
for f in summary.json frf.csv modes.csv map.csv; do
  [ -s "$WORK/r/$f" ] || fail "robot did not write $f"
done
for key in posture_deg tool_position_mm jacobian compliance natural_frequencies_hz \
  modal_table_tool_frame principal_stiffness reduced_model full_natural_frequencies_hz; do
  grep -q "\"$key\"" "$WORK/r/summary.json" || fail "summary.json lacks $key"
done
[ "$(head -1 "$WORK/r/frf.csv" | cut -d, -f1-3)" = "freq_hz,hxx_re,hxx_im" ] || fail "frf.csv header"
[ $(($(wc -l < "$WORK/r/map.csv") - 1)) -eq 12 ] || fail "map.csv should have 4 x 3 rows"
[ $(($(wc -l < "$WORK/r/modes.csv") - 1)) -eq 3 ] || fail "three joint modes expected"
grep -qi 'nan\|inf' "$WORK/r/summary.json" "$WORK/r/frf.csv" "$WORK/r/map.csv" \
  && fail "non-finite number written"

# A robot without link masses (000's KR600): statics only, said in the summary.
"$ROBOMILL" robot "$SOURCE/examples/000_kr600_multipoint.yaml" --out "$WORK/r0" --quiet \
  || fail "KR600 robot exit code"
grep -q '"dynamics_note"' "$WORK/r0/summary.json" || fail "KR600: statics-only note missing"
grep -q '"principal_stiffness"' "$WORK/r0/summary.json" || fail "KR600: principal stiffness missing"
[ ! -e "$WORK/r0/frf.csv" ] || fail "KR600 without masses should write no frf.csv"

# The stability engine takes the robot's tool-tip modes (dynamics.from_robot).
STAB='stability={speeds: {from: 500 rpm, to: 3000 rpm, count: 8}, depth_max: 20 mm, method: zoa}'
"$ROBOMILL" stability "$JOB" --set dynamics.from_robot=true --set "$STAB" --out "$WORK/s" --quiet \
  || fail "stability from_robot exit code"
grep -q '"dynamics": "robot"' "$WORK/s/summary.json" || fail "stability from_robot: dynamics not robot"
grep -q '"mode_count": 3' "$WORK/s/summary.json" || fail "stability from_robot: three robot modes"
expect_exit2 "robot.posture" stability "$JOB" --set dynamics.from_robot=true --set "$STAB" \
  --set 'robot.posture=null'

# The KR270-class robot as a DH table (003's example) and as a URDF file
# (002's example, examples/robots/kr270_r2900.urdf): one robot, so the same
# modes (frequencies and |tip shapes|) to 1e-9 relative.
"$ROBOMILL" robot "$SOURCE/examples/003_kr270_process_damping.yaml" \
  --out "$WORK/dh" --quiet || fail "KR270 DH exit code"
"$ROBOMILL" robot "$SOURCE/examples/002_kr270_fractional_law.yaml" --out "$WORK/urdf" --quiet \
  || fail "KR270 URDF exit code"
paste -d, "$WORK/dh/modes.csv" "$WORK/urdf/modes.csv" | awk -F, 'NR > 1 {
    for (c = 2; c <= 6; c++) { if (c == 3) continue
      a = $c; b = $(c + 6); if (a < 0) a = -a; if (b < 0) b = -b
      d = a - b; if (d < 0) d = -d; if (d > 1e-9 * (a > 0.01 ? a : 0.01)) bad = 1 } }
    END { if (NR != 7) bad = 1; exit bad }' \
  || fail "KR270: the URDF file and the DH table give different modes"

expect_exit2 "robot.posture[2]" robot "$JOB" --set 'robot.posture=[0, 45, -80]'
expect_exit2 "robot.joint_stiffness[1]" robot "$JOB" --set 'robot.joint_stiffness=[2.4e5, -5, 1e5]'
expect_exit2 "robot.joints[2].upper" robot "$JOB" --set 'robot.joints[2].upper=-70'
expect_exit2 "robot.posture" robot "$JOB" --set 'robot.posture=[0, 45]'
expect_exit2 "robot.links[0].mass" robot "$JOB" --set 'robot.links[0].mass=-1'
expect_exit2 "either as a DH table" robot "$JOB" --set 'robot.urdf={file: a.urdf, base: a, tip: b}'
expect_exit2 "robot" robot "$SOURCE/examples/demo.yaml"
finish
