#!/usr/bin/env bash
# robomill learn (docs/learning.md): the anchor example (fewer samples, a
# coarser grid) writes its files, prints the next test in one line and a
# summary with every variable's prior and posterior; the same seed gives the
# same posterior.csv on 1 and 2 threads; a job it cannot learn is a clear
# error that writes nothing; the hammer example's files and errors.
source "$(dirname "$0")/lib.bash" "$@"
JOB="$SOURCE/examples/learn/anchor_tool.yaml"
FAST=(--set learn.samples=400 --set uncertainty.samples=100 --set "stability.speeds.count=40"
      --set stability.depths=20)

out=$("$ROBOMILL" learn "$JOB" "${FAST[@]}" --out "$WORK/a" --threads 2) || fail "learn: exit code"
for f in posterior.csv summary.json lobes_quantiles.csv chatter_probability.csv \
         lobes_quantiles_prior.csv experiments.csv report.html; do
  [ -s "$WORK/a/$f" ] || fail "no $f"
done
echo "$out" | grep -Eq '^next test: [0-9]+ rpm, ap [0-9.]+ mm \(P\(chatter\) [0-9.]+' \
  || fail "no one-line next test: $out"
head -1 "$WORK/a/posterior.csv" | grep -q '^Ktc,Krc,fn,k,zeta$' \
  || fail "posterior.csv header: $(head -1 "$WORK/a/posterior.csv")"
[ "$(wc -l < "$WORK/a/posterior.csv")" -eq 401 ] || fail "posterior.csv: not 400 samples"
for key in '"next_test"' '"experiments_used"' '"experiments_skipped"' '"log_evidence"' \
           '"posterior_correlation"' '"q95"'; do
  grep -q "$key" "$WORK/a/summary.json" || fail "summary.json lacks $key"
done
fn_sd_prior=$(awk '/"fn": \{/ { f = 1 } f && /"prior"/ { p = 1 } f && p && /"sd"/ { gsub(/[ ,]/, ""); split($0, a, ":"); print a[2]; exit }' "$WORK/a/summary.json")
fn_sd_post=$(awk '/"fn": \{/ { f = 1 } f && /"posterior"/ { p = 1 } f && p && /"sd"/ { gsub(/[ ,]/, ""); split($0, a, ":"); print a[2]; exit }' "$WORK/a/summary.json")
awk -v a="$fn_sd_post" -v b="$fn_sd_prior" 'BEGIN { exit !(a > 0 && a < b) }' \
  || fail "fn's posterior sd ($fn_sd_post Hz) is not below its prior's ($fn_sd_prior Hz)"
grep -q 'learn' "$WORK/a/report.html" || fail "report.html"

# The same seed on one thread: the same samples.
"$ROBOMILL" learn "$JOB" "${FAST[@]}" --out "$WORK/b" --threads 1 --quiet || fail "1 thread"
cmp -s "$WORK/a/posterior.csv" "$WORK/b/posterior.csv" || fail "posterior.csv differs on 1 thread"

# Jobs it cannot learn: errors naming the field, nothing written.
expect_exit2 "uncertainty" learn "$SOURCE/examples/demo.yaml"
sed 's/path: cutting.Krc/path: process.ae/' "$JOB" > "$WORK/ae.yaml"
expect_exit2 "process.ae" learn "$WORK/ae.yaml"

# A robot learned from hammer tests (examples/learn/kr270_hammer.yaml): the
# fitted modes, every place's lobes and P(chatter) map; a hammer test
# without its posture, or at a position the robot cannot reach, is an error
# naming it.
HAMMER="$SOURCE/examples/learn/kr270_hammer.yaml"
"$ROBOMILL" learn "$HAMMER" --set learn.samples=200 --out "$WORK/h" --quiet || fail "hammer: exit code"
[ "$(wc -l < "$WORK/h/hammer_modes.csv")" -eq 9 ] || fail "hammer_modes.csv: not 8 fitted modes"
for f in places.csv chatter_probability_places.csv; do
  [ -s "$WORK/h/$f" ] || fail "hammer: no $f"
done
grep -q '"hammer_modes"' "$WORK/h/summary.json" || fail "summary.json lacks hammer_modes"
expect_exit2 "experiments[0].posture" learn "$HAMMER" \
  --set "experiments=[{frf: {x: {file: data/kr270_hammer_a_x.csv, units: m/N}}}]"
expect_exit2 "experiments[0].position" learn "$HAMMER" \
  --set "experiments=[{position: [5000, 0, 0], frf: {x: {file: data/kr270_hammer_a_x.csv, units: m/N}}}]"
finish
