#!/usr/bin/env bash
# `robomill stability` with an uncertainty: section (issue 33): the quantile
# lobes and the chatter-probability map, their columns, their consistency,
# and the refusals that name the variable.
source "$(dirname "$0")/lib.bash"
out="$WORK/band"
"$ROBOMILL" stability "$SOURCE/examples/uncertainty_stability.yaml" --set uncertainty.samples=24 \
  --set stability.speeds.count=17 --set stability.depths=13 --out "$out" > /dev/null \
  || fail "exit code"
[ "$(head -1 "$out/lobes_quantiles.csv")" = \
  "spindle_rpm,depth_limit_q05_mm,depth_limit_q50_mm,depth_limit_q95_mm,depth_limit_nominal_mm" ] \
  || fail "lobes_quantiles.csv header: $(head -1 "$out/lobes_quantiles.csv")"
[ "$(head -1 "$out/chatter_probability.csv")" = "spindle_rpm,depth_mm,p_chatter,p_chatter_se" ] \
  || fail "chatter_probability.csv header"
[ $(($(wc -l < "$out/lobes_quantiles.csv") - 1)) -eq 17 ] || fail "one quantile row per speed"
[ $(($(wc -l < "$out/chatter_probability.csv") - 1)) -eq $((17 * 13)) ] \
  || fail "17 speeds x 13 depths of probabilities"
# Quantiles in order; probabilities in [0, 1], multiples of 1/24, never
# falling as the depth rises at one speed (speed-major rows).
awk -F, 'NR > 1 && !($2 <= $3 && $3 <= $4) { print "quantiles out of order: " $0; bad = 1 }
         END { exit bad }' "$out/lobes_quantiles.csv" || fail "quantile order"
awk -F, 'NR > 1 { k = $3 * 24; if ($3 < 0 || $3 > 1 || (k - int(k + 0.5))^2 > 1e-12) { print "p: " $0; bad = 1 }
                  if ($1 == speed && $3 < last) { print "p falls with depth: " $0; bad = 1 }
                  speed = $1; last = $3 } END { exit bad }' "$out/chatter_probability.csv" \
  || fail "chatter_probability.csv rows"
for key in '"uncertainty"' '"draws": 24' '"robust_pockets"' '"depth_limit_q05_min_mm"'; do
  grep -q "$key" "$out/summary.json" || fail "summary.json lacks $key"
done
grep -q "Probability of chatter" "$out/report.html" || fail "report.html has no probability map"
grep -qi 'nan\|inf' "$out/lobes_quantiles.csv" "$out/chatter_probability.csv" && fail "non-finite number written"

# A wide normal on a stiffness draws negative values: refused naming the
# variable, nothing written.
bad="$WORK/bad"
if "$ROBOMILL" stability "$SOURCE/examples/uncertainty_stability.yaml" --set uncertainty.samples=64 \
  --set 'uncertainty.variables=[{name: k_x, path: dynamics.modes.2.k, distribution: normal, sd: 150 %}]' \
  --out "$bad" --quiet 2> "$WORK/err.txt"; then
  fail "a draw with a negative stiffness was accepted"
fi
grep -q "k_x" "$WORK/err.txt" || fail "the refusal does not name the variable: $(cat "$WORK/err.txt")"
[ ! -e "$bad/lobes_quantiles.csv" ] || fail "a refused run wrote lobes_quantiles.csv"
finish
