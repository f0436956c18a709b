#!/usr/bin/env bash
# `robomill identify-stiffness` (000 §6.1): the example loading tests recover
# the Kq that synthesized them; noise-free data recover it exactly; data that
# cannot identify a joint, and malformed files, exit 2 naming the problem.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/000_kr600_multipoint.yaml"
PLAN="$SOURCE/examples/data/000_kr600_loading_plan.csv"
TESTS="$SOURCE/examples/data/000_kr600_loading_tests.csv"
KQ=(6.082e6 6.816e6 3.842e6 2.926e6 1.635e6 2.479e6)   # 000 §6.1, the job's robot.joint_stiffness

# ratio_column FILE: the "ratio_to_job" of every joint, one per line.
ratios() { grep '"ratio_to_job"' "$1" | sed 's/.*: *//; s/,//'; }
standard_errors() { grep '"relative_standard_error"' "$1" | sed 's/.*: *//; s/,//'; }

# The committed example (384 tests, 1 % displacement noise, seed 7).
"$ROBOMILL" identify-stiffness "$TESTS" --job "$JOB" --out "$WORK/id" --quiet || fail "exit code"
for f in summary.json fit.csv joint_stiffness.yaml; do
  [ -s "$WORK/id/$f" ] || fail "did not write $f"
done
[ "$(head -1 "$WORK/id/fit.csv")" = "test,dx_mm,dy_mm,dz_mm,model_dx_mm,model_dy_mm,model_dz_mm,residual_um" ] \
  || fail "fit.csv header"
[ $(($(wc -l < "$WORK/id/fit.csv") - 1)) -eq 384 ] || fail "fit.csv should have 384 rows"
grep -q '^joint_stiffness: \[' "$WORK/id/joint_stiffness.yaml" || fail "snippet lacks joint_stiffness"
# Each joint within 2 % of the truth (the issue's criterion) and within three
# of its own standard errors (the reported uncertainty is honest).
paste <(ratios "$WORK/id/summary.json") <(standard_errors "$WORK/id/summary.json") \
  | awk '{ e = $1 - 1; if (e < 0) e = -e; printf "[validation] joint %d: error %.2f %%, standard error %.2f %%\n", NR, 100 * e, 100 * $2;
           if (e > 0.02) { print "joint " NR " off by " 100 * e " %"; bad = 1 }
           if (e > 3 * $2) { print "joint " NR " error beyond 3 standard errors"; bad = 1 } }
         END { if (NR != 6) { print "expected 6 joints, got " NR; bad = 1 }; exit bad }' \
  || fail "1 % noise: Kq not recovered within 2 % / 3 standard errors"
grep -qi 'nan\|inf' "$WORK/id/summary.json" "$WORK/id/fit.csv" && fail "non-finite number written"

# Noise-free synthesis from the plan: Kq back to 1e-6 relative.
"$ROBOMILL" identify-stiffness "$PLAN" --job "$JOB" --synthesize --out "$WORK/syn" --quiet \
  || fail "synthesize exit code"
"$ROBOMILL" identify-stiffness "$WORK/syn/loading_tests.csv" --job "$JOB" --out "$WORK/id0" --quiet \
  || fail "noise-free exit code"
ratios "$WORK/id0/summary.json" | awk '{ e = $1 - 1; if (e < 0) e = -e; if (e > 1e-6) bad = 1 } END { exit bad }' \
  || fail "noise-free data should recover Kq to 1e-6"

# Synthesis with the seed of the example reproduces the committed file.
"$ROBOMILL" identify-stiffness "$PLAN" --job "$JOB" --synthesize --noise 0.01 --seed 7 \
  --out "$WORK/syn7" --quiet || fail "synthesize --noise exit code"
diff <(grep -v '^#' "$TESTS") "$WORK/syn7/loading_tests.csv" > /dev/null \
  || fail "--synthesize --noise 0.01 --seed 7 no longer reproduces $TESTS"

# The paper's own test (§6.1: 30 kg and 50 kg weights, i.e. vertical forces
# only) cannot turn joint 1, whose axis is vertical: refused, naming joint 1.
grep -v '^#' "$TESTS" | awk -F, 'NR == 1 || ($7 == 0 && $8 == 0)' > "$WORK/vertical.csv"
expect_exit2 "joint 1" identify-stiffness "$WORK/vertical.csv" --job "$JOB"
# A target on the flange axis (the tool tip) cannot see joint 6.
sed 's/,300,0,0,0,-500,0,/,0,0,0,0,-500,0,/' "$TESTS" > "$WORK/on_axis.csv"
expect_exit2 "joint 6" identify-stiffness "$WORK/on_axis.csv" --job "$JOB"
# Fewer equations than joints.
grep -v '^#' "$TESTS" | head -2 > "$WORK/one.csv"
expect_exit2 "identification" identify-stiffness "$WORK/one.csv" --job "$JOB"

# Malformed files: the problem is named.
grep -v '^#' "$TESTS" | cut -d, -f1-5,7- > "$WORK/no_q6.csv"
expect_exit2 "q6_deg" identify-stiffness "$WORK/no_q6.csv" --job "$JOB"
grep -v '^#' "$TESTS" | sed '3s/^-71.73/-271.73/' > "$WORK/range.csv"
expect_exit2 "test 2: q1_deg = -271.73 is outside joint 1's range" identify-stiffness \
  "$WORK/range.csv" --job "$JOB"
grep -v '^#' "$TESTS" | sed '2s/,-294.2,/,abc,/' > "$WORK/text.csv"
expect_exit2 "line" identify-stiffness "$WORK/text.csv" --job "$JOB"
grep -v '^#' "$TESTS" | cut -d, -f1-17 > "$WORK/no_dz.csv"
expect_exit2 "dx_mm, dy_mm, dz_mm" identify-stiffness "$WORK/no_dz.csv" --job "$JOB"
grep -v '^#' "$TESTS" | sed '2s/,0,0,-294.2,/,0,0,0,/' > "$WORK/zero.csv"
expect_exit2 "test 1: no load" identify-stiffness "$WORK/zero.csv" --job "$JOB"
expect_exit2 "robot" identify-stiffness "$TESTS" --job "$SOURCE/examples/demo.yaml"
expect_exit2 "--noise" identify-stiffness "$PLAN" --job "$JOB" --synthesize --noise -1
finish
