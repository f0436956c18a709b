#!/usr/bin/env bash
# `robomill advise` with an uncertainty: section (issue 33, deliverable 3):
# the robust advice beside the nominal one, its file and keys, the bound
# kept at the advised point and along the robust map, and the refusals.
source "$(dirname "$0")/lib.bash"
PY=/usr/bin/python3
JOB="$SOURCE/examples/uncertainty_stability.yaml"
FAST=(--set uncertainty.samples=60 --set 'advise.speeds={from: 300 rpm, to: 6000 rpm, count: 20}'
      --set advise.refine=3)
out="$WORK/robust"
"$ROBOMILL" advise "$JOB" "${FAST[@]}" --out "$out" > "$WORK/console.txt" || fail "exit code"
grep -q "robust (60 draws, P(chatter) ≤ 5 %)" "$WORK/console.txt" \
  || fail "the console does not give the robust advice: $(cat "$WORK/console.txt")"
for f in summary.json advice.json advice_map.csv advice_map_robust.csv; do
  [ -s "$out/$f" ] || fail "advise did not write $f"
done
[ "$(head -1 "$out/advice_map_robust.csv")" = \
  "spindle_rpm,stage,robust_limit_depth_mm,limited,depth_mm,offset_mm,offset_limited,mrr_cm3_per_min" ] \
  || fail "advice_map_robust.csv header: $(head -1 "$out/advice_map_robust.csv")"
[ $(($(wc -l < "$out/advice_map_robust.csv") - 1)) -eq 23 ] \
  || fail "advice_map_robust.csv: 20 scanned + 3 refined speeds"
# Every robust row keeps its depth under its robust limit (columns 3, 5).
awk -F, 'NR > 1 && $5 > $3 * (1 + 1e-9) { print; bad = 1 } END { exit bad }' \
  "$out/advice_map_robust.csv" || fail "a robust row lies above its robust limit"
grep -qi 'nan\|inf' "$out/summary.json" "$out/advice_map_robust.csv" && fail "non-finite number written"
"$PY" - "$out/summary.json" <<'EOF' || fail "summary.json's uncertainty block"
import json, sys
s = json.load(open(sys.argv[1]))
u = s["uncertainty"]
assert u["draws"] == 60 and u["source"] == "sobol", u
assert u["variables"] == ["stiffness", "damping", "coefficients"], u["variables"]
assert u["max_chatter_probability"] == 0.05, u
assert u["feasible"], u
assert 0.0 <= u["p_chatter"] <= 0.05, u["p_chatter"]
assert 0.0 <= u["nominal_p_chatter"] <= 1.0, u
a = u["advice"]
assert a["depth_mm"] <= a["robust_limit_depth_mm"] * (1 + 1e-9), a
# The robust depth is a multiple of the 0.05 mm step.
assert abs(a["depth_mm"] / 0.05 - round(a["depth_mm"] / 0.05)) < 1e-6, a
EOF

# A stricter bound never advises a faster removal rate.
"$ROBOMILL" advise "$JOB" "${FAST[@]}" --set advise.max_chatter_probability=1% --out "$WORK/strict" \
  --quiet || fail "strict exit code"
"$PY" - "$out/summary.json" "$WORK/strict/summary.json" <<'EOF' || fail "1 % removes more than 5 %"
import json, sys
loose = json.load(open(sys.argv[1]))["uncertainty"]["advice"]["mrr_cm3_per_min"]
strict = json.load(open(sys.argv[2]))["uncertainty"]["advice"]["mrr_cm3_per_min"]
assert strict <= loose * (1 + 1e-12), (strict, loose)
EOF

# Refusals: a probability outside (0, 1), and a draw the job refuses (a wide
# normal on a stiffness draws negatives): named, exit 2, nothing written.
expect_exit2 "advise.max_chatter_probability" advise "$JOB" "${FAST[@]}" \
  --set advise.max_chatter_probability=1.5
expect_exit2 "k_x" advise "$JOB" "${FAST[@]}" --set uncertainty.samples=64 \
  --set 'uncertainty.variables=[{name: k_x, path: dynamics.modes.2.k, distribution: normal, sd: 150 %}]'
finish
