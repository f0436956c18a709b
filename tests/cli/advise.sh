#!/usr/bin/env bash
# `robomill advise`: files, columns, summary keys, the advice inside its own
# limits, the path and redundancy options, and bad advise input exiting 2
# with the field named and nothing written.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/003_kr270_cutting_advice.yaml"
FAST=(--set 'advise.speeds={from: 1000 rpm, to: 12000 rpm, count: 23}' --set advise.refine=4)
ANGLES=(--set 'advise.redundancy.angles={from: -60 deg, to: 30 deg, count: 4}')

"$ROBOMILL" advise "$JOB" "${FAST[@]}" "${ANGLES[@]}" --out "$WORK/a" --quiet || fail "advise exit code"
for f in summary.json advice.json advice_map.csv redundancy.csv; do
  [ -s "$WORK/a/$f" ] || fail "advise did not write $f"
done
for key in spindle_rpm depth_mm mrr_cm3_per_min margin_to_chatter expected_offset_mm limit_depth_mm \
  feasible elapsed_s redundancy_angle_deg; do
  grep -q "\"$key\"" "$WORK/a/summary.json" || fail "summary.json lacks $key"
done
for key in advice floquet_check peaks limits redundancy best_constant_angle_deg per_point; do
  grep -q "\"$key\"" "$WORK/a/advice.json" || fail "advice.json lacks $key"
done
[ "$(head -1 "$WORK/a/advice_map.csv")" = "spindle_rpm,stage,limit_depth_mm,limited,station,chatter_freq_hz,stable_depth_mm,depth_mm,offset_mm,offset_limited,mrr_cm3_per_min" ] \
  || fail "advice_map.csv header"
[ $(($(wc -l < "$WORK/a/advice_map.csv") - 1)) -eq 27 ] || fail "advice_map.csv: 23 scanned + 4 refined speeds"
[ $(($(wc -l < "$WORK/a/redundancy.csv") - 1)) -eq 32 ] || fail "redundancy.csv: 8 points x 4 angles"
grep -qi 'nan\|inf' "$WORK/a/summary.json" "$WORK/a/advice.json" "$WORK/a/advice_map.csv" \
  && fail "non-finite number written"
# The advice keeps its limits: depth ≤ 0.8 x limit, offset ≤ 0.1 mm; every
# map row too (awk: columns 3 limit, 8 depth, 9 offset).
awk -F, 'NR > 1 && ($8 > 0.8 * $3 * (1 + 1e-9) || $9 > 0.1) { bad = 1 } END { exit bad }' \
  "$WORK/a/advice_map.csv" || fail "a map row breaks the margin or the offset limit"
depth=$(grep '"depth_mm"' "$WORK/a/summary.json" | tr -dc '0-9.')
limit=$(grep '"limit_depth_mm"' "$WORK/a/summary.json" | tr -dc '0-9.')
awk -v d="$depth" -v l="$limit" 'BEGIN { exit !(d > 0 && d <= 0.8 * l * (1 + 1e-9)) }' \
  || fail "advised depth $depth mm not within 0.8 x $limit mm"

# A tight offset limit binds, and the advice follows it.
"$ROBOMILL" advise "$JOB" "${FAST[@]}" --set advise.max_offset=0.02 --set 'advise.redundancy.angles={from: 0, to: 0, count: 1}' \
  --out "$WORK/t" --quiet || fail "tight offset exit code"
grep -q '"offset_limited": true' "$WORK/t/summary.json" || fail "0.02 mm offset limit did not bind"
[ $(($(wc -l < "$WORK/t/redundancy.csv") - 1)) -eq 8 ] || fail "redundancy.csv: 8 points x 1 angle"
awk -F, 'NR > 1 && $9 > 0.02 { bad = 1 } END { exit bad }' "$WORK/t/advice_map.csv" \
  || fail "offset above 0.02 mm advised"

# Along the path: every point is a station.
"$ROBOMILL" advise "$JOB" "${FAST[@]}" --set advise.along=path --set advise.redundancy_angle=30 --set 'advise.redundancy.angles={from: 0, to: 0, count: 1}' \
  --out "$WORK/p" --quiet || fail "along path exit code"
grep -q '"stations": 8' "$WORK/p/summary.json" || fail "along path: 8 stations expected"

# ... and a point the robot cannot reach at that angle is named, not skipped.
expect_exit2 "point 4 of 8" advise "$JOB" "${FAST[@]}" --set advise.along=path \
  --set advise.redundancy_angle=0
expect_exit2 "advise.margin" advise "$JOB" --set advise.margin=1.5
expect_exit2 "advise.speeds.to" advise "$JOB" --set 'advise.speeds={from: 5000, to: 1000, count: 5}'
expect_exit2 "advise.depth_step" advise "$JOB" --set advise.depth_step=20
expect_exit2 "advise.depth_max" advise "$JOB" --set advise.depth_max=80
expect_exit2 "advise.max_offset" advise "$JOB" --set advise.max_offset=-1
expect_exit2 "advise.method" advise "$JOB" --set advise.method=exact
expect_exit2 "advise.measure" advise "$JOB" --set advise.measure=startup
expect_exit2 "advise.samples" advise "$JOB" --set advise.samples=50
expect_exit2 "advise.redundancy.angles" advise "$JOB" --set 'advise.redundancy={at: range}'
expect_exit2 "advise.discretization" advise "$JOB" --set advise.method=fdm --set advise.discretization=8
expect_exit2 "advise.colour" advise "$JOB" --set advise.colour=red
expect_exit2 "no rotation about the tool axis" advise \
  "$SOURCE/examples/004_kr300_pose_optimization.yaml" \
  --set 'advise={speeds: {from: 500, to: 2000, count: 4}, depth_max: 5, redundancy: {angles: {from: 0, to: 90, count: 3}}}'
expect_exit2 "advise" advise "$SOURCE/examples/demo.yaml"
finish
