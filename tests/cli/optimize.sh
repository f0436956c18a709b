#!/usr/bin/env bash
# `robomill optimize`: files, columns, summary keys (DESIGN.md: best, objective,
# evaluations), determinism, and bad planning input exiting 2 with the field
# named and nothing written.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/004_kr300_pose_optimization.yaml"
FAST=(--set optimize.budget=40 --set optimize.local_budget=20 --set 'optimize.landscape={x: 3, y: 2, theta: [0, 60]}')

"$ROBOMILL" optimize "$JOB" "${FAST[@]}" --out "$WORK/o" --quiet || fail "optimize exit code"
for f in summary.json evaluations.csv path.csv landscape.csv; do
  [ -s "$WORK/o/$f" ] || fail "optimize did not write $f"
done
for key in best objective evaluations dm_mm measure poses elapsed_s global_status; do
  grep -q "\"$key\"" "$WORK/o/summary.json" || fail "summary.json lacks $key"
done
[ "$(head -1 "$WORK/o/evaluations.csv")" = "evaluation,phase,x_mm,y_mm,theta_deg,reachable,dm_mm,objective_mm" ] \
  || fail "evaluations.csv header"
evaluations=$(grep '"evaluations"' "$WORK/o/summary.json" | tr -dc '0-9')
[ $(($(wc -l < "$WORK/o/evaluations.csv") - 1)) -eq "$evaluations" ] || fail "one row per evaluation"
[ $(($(wc -l < "$WORK/o/landscape.csv") - 1)) -eq 12 ] || fail "landscape: 3 x 2 x 2 cells"
[ $(($(wc -l < "$WORK/o/path.csv") - 1)) -eq 140 ] || fail "path.csv: 20 points x (best + 6 poses)"
grep -qi 'nan\|inf' "$WORK/o/summary.json" "$WORK/o/evaluations.csv" "$WORK/o/path.csv" \
  && fail "non-finite number written"
best_x=$(json_number "$WORK/o/summary.json" best x_mm)
"$ROBOMILL" optimize "$JOB" "${FAST[@]}" --out "$WORK/o2" --quiet --threads 1 || fail "second run"
[ "$best_x" = "$(json_number "$WORK/o2/summary.json" best x_mm)" ] || fail "not deterministic"

# The time-domain check of the harmonic steady state (004 Eq 1 integrated).
"$ROBOMILL" optimize "$JOB" --set optimize.budget=10 --set optimize.local=none \
  --set optimize.check_time_domain=true --set 'optimize.poses=[]' --out "$WORK/c" --quiet \
  || fail "check_time_domain exit code"
grep -q '"time_domain_check"' "$WORK/c/summary.json" || fail "time_domain_check missing"

expect_exit2 "optimize.measure" optimize "$JOB" --set optimize.measure=amplitude
expect_exit2 "optimize.bounds.x" optimize "$JOB" --set 'optimize.bounds.x=[600, 0]'
expect_exit2 "optimize.samples" optimize "$JOB" --set optimize.samples=50
expect_exit2 "optimize.poses[0]" optimize "$JOB" --set 'optimize.poses=[{x: 2000, y: 0, theta: 0}]'
expect_exit2 "outside the robot's workspace" optimize "$JOB" \
  --set 'optimize.poses=[{x: 2000, y: 0, theta: 0}]'
expect_exit2 "needs joint" optimize "$JOB" --set 'workpiece.table=[0, 0, 500]' \
  --set 'optimize.poses=[{x: 200, y: 0, theta: 0}]'
expect_exit2 "optimize.bounds" optimize "$JOB" --set 'optimize.poses=[]' --set optimize.budget=20 \
  --set 'optimize.bounds.x=[1500, 2000]'
expect_exit2 "workpiece.table" optimize "$JOB" --set "workpiece=null"
expect_exit2 "path.points" optimize "$JOB" --set path.points=0
expect_exit2 "workpiece.tilt_axis" optimize "$JOB" --set workpiece.tilt_axis=z
expect_exit2 "optimize" optimize "$SOURCE/examples/demo.yaml"
finish
