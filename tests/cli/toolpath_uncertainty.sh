#!/usr/bin/env bash
# `robomill toolpath` with an uncertainty: section (issue 33, deliverable 4):
# P(chatter) and the band of the stable depth per sample, the expected
# number of chattering samples and the lines over the bound, all consistent
# with samples.csv; a tiny spread gives the nominal verdicts; the report's
# figure; --optimize keeping P(chatter) under the bound, its after-numbers
# those of the written program; refusals of what would move the postures.
source "$(dirname "$0")/lib.bash"
PY=/usr/bin/python3
JOB="$SOURCE/examples/uncertainty_toolpath.yaml"
# The example's pocket sampled every 1 mm (257 samples, not its own 1960):
# every check below holds for any spacing, at an eighth of the time.
SPACING=(--set "toolpath.spacing=1 mm")
out="$WORK/drawn"
"$ROBOMILL" toolpath "$JOB" "${SPACING[@]}" --set uncertainty.samples=12 --out "$out" > "$WORK/console.txt" \
  || fail "exit code"
grep -q "uncertainty: 12 draws, expected chattering samples" "$WORK/console.txt" \
  || fail "the console does not give the draws: $(cat "$WORK/console.txt")"
head -1 "$out/samples.csv" | grep -q ",p_chatter,p_chatter_se,ap_limit_q05_mm,ap_limit_q95_mm$" \
  || fail "samples.csv header: $(head -1 "$out/samples.csv")"
grep -qi 'nan\|inf' "$out/summary.json" "$out/samples.csv" && fail "non-finite number written"
grep -q "Chatter probability along the program" "$out/report.html" \
  || fail "the report lacks the chatter-probability figure"
"$PY" - "$out/samples.csv" "$out/summary.json" <<'EOF' || fail "samples.csv against summary.json"
import csv, json, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
u = json.load(open(sys.argv[2]))["robot_along_path"]["uncertainty"]
n = u["draws"]
assert n == 12 and u["source"] == "sobol", u
assert u["variables"] == ["joint_stiffness", "damping", "coefficients"], u["variables"]
drawn = [r for r in rows if r["p_chatter"] != ""]
assert drawn, "no sample with P(chatter)"
# Exactly the samples with a stable depth have draws.
assert all((r["p_chatter"] != "") == (r["ap_limit_mm"] != "") for r in rows)
total, lines = 0.0, {}
for r in drawn:
    p, se = float(r["p_chatter"]), float(r["p_chatter_se"])
    assert 0 <= p <= 1 and abs(p * n - round(p * n)) < 1e-9, p       # a count of draws
    assert abs(se - math.sqrt(p * (1 - p) / n)) < 1e-9, (p, se)
    assert float(r["ap_limit_q05_mm"]) <= float(r["ap_limit_q95_mm"]) * (1 + 1e-12), r
    total += p
    line = int(r["line"])
    lines[line] = max(lines.get(line, 0.0), p)
assert abs(u["expected_chatter_samples"] - total) <= 1e-6 * max(total, 1), (u, total)
bound = u["max_chatter_probability"]
assert bound == 0.05, bound
over = sorted(l for l, p in lines.items() if p > bound)
listed = sorted({l["line"] for l in u["lines_over_bound"]})
assert listed == over, (listed, over)
assert u["lines_over_bound_count"] == len(u["lines_over_bound"])
best = max(drawn, key=lambda r: float(r["p_chatter"]))
assert abs(u["max_p_chatter"] - float(best["p_chatter"])) < 1e-12, u
EOF

# A tiny spread: every draw is the nominal job to 1e-9, so P(chatter) is the
# nominal verdict wherever the depth is not within 1e-6 of the limit.
TINY='uncertainty.variables=[{name: joint_stiffness, path: robot.joint_stiffness, mode: scale, distribution: lognormal, sigma: 1e-9}]'
"$ROBOMILL" toolpath "$JOB" "${SPACING[@]}" --set uncertainty.samples=4 --set "$TINY" --out "$WORK/tiny" --quiet \
  || fail "tiny spread exit code"
"$PY" - "$WORK/tiny/samples.csv" "$WORK/tiny/summary.json" <<'EOF' || fail "tiny spread is not nominal"
import csv, json, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["p_chatter"] != ""]
along = json.load(open(sys.argv[2]))["robot_along_path"]
for r in rows:
    ap, limit = float(r["ap_mm"]), float(r["ap_limit_mm"])
    assert abs(float(r["ap_limit_q05_mm"]) - limit) <= 1e-5 * limit, r
    if abs(ap - limit) > 1e-6 * limit:
        assert float(r["p_chatter"]) == float(r["chatter"]), r
assert along["uncertainty"]["expected_chatter_samples"] == along["chatter_samples"], along
EOF

# Zero spread under --optimize: the bounded limit is the nominal one, so the
# choices and their margins are those of the same job without uncertainty:.
sed '/^uncertainty:/,$d' "$JOB" > "$WORK/nominal.yaml"
"$ROBOMILL" toolpath "$WORK/nominal.yaml" "${SPACING[@]}" --set "toolpath.file=$SOURCE/examples/programs/pocket.nc" \
  --optimize --out "$WORK/nominal_opt" --quiet || fail "nominal --optimize exit code"
"$ROBOMILL" toolpath "$JOB" "${SPACING[@]}" --set uncertainty.samples=4 --set "$TINY" --optimize \
  --out "$WORK/tiny_opt" --quiet || fail "tiny spread --optimize exit code"
"$PY" - "$WORK/nominal_opt/summary.json" "$WORK/tiny_opt/summary.json" <<'EOF' \
  || fail "tiny spread --optimize is not the nominal one"
import json, sys
a, b = (json.load(open(f))["optimization"] for f in sys.argv[1:3])
assert "risk_note" not in a and "risk_note" in b
ca, cb = a["spindle_choices"], b["spindle_choices"]
assert len(ca) == len(cb) > 0, (ca, cb)
for x, y in zip(ca, cb):
    assert x["chosen_rpm"] == y["chosen_rpm"] and x["at_risk_after"] == y["at_risk_after"], (x, y)
    for k in ("min_margin_before", "min_margin_after"):
        assert abs(x[k] - y[k]) <= 1e-6 * abs(x[k]), (k, x[k], y[k])
for k in ("samples_newly_at_risk", "samples_relieved", "samples_compared"):
    assert a[k] == b[k], (k, a[k], b[k])
assert abs(a["after"]["min_margin"] - b["after"]["min_margin"]) <= 1e-9 * a["after"]["min_margin"]
EOF

# --optimize under the bound: the choices read the draws' limit at the bound,
# and the written program's P(chatter) is measured with every draw: the
# same numbers as `toolpath` on the written program with the same job.
opt="$WORK/optimized"
"$ROBOMILL" toolpath "$JOB" "${SPACING[@]}" --set uncertainty.samples=12 --optimize --out "$opt" \
  > "$WORK/optimize.txt" || fail "--optimize exit code"
grep -q "after: uncertainty: 12 draws" "$WORK/optimize.txt" \
  || fail "the console lacks the written program's draws: $(cat "$WORK/optimize.txt")"
"$ROBOMILL" toolpath "$JOB" "${SPACING[@]}" --set uncertainty.samples=12 \
  --set "toolpath.file=$opt/program_optimized.nc" --out "$WORK/rerun" --quiet \
  || fail "toolpath on the written program"
"$PY" - "$opt/summary.json" "$WORK/rerun/summary.json" <<'EOF' || fail "--optimize under the bound"
import json, sys
s = json.load(open(sys.argv[1]))
before, o = s["robot_along_path"]["uncertainty"], s["optimization"]
assert "draws' limit at robot_path.max_chatter_probability" in o["risk_note"], o["risk_note"]
after = o["after"]["uncertainty"]
rerun = json.load(open(sys.argv[2]))["robot_along_path"]["uncertainty"]
assert after == rerun, (after, rerun)           # measured on the program written
assert after["lines_over_bound_count"] < before["lines_over_bound_count"], (before, after)
assert after["expected_chatter_samples"] < before["expected_chatter_samples"], (before, after)
EOF

# What moves the postures or the cut cannot be drawn along a program.
expect_exit2 "uncertainty.variables[0].path" toolpath "$JOB" --set uncertainty.samples=4 \
  --set 'uncertainty.variables=[{name: reach, path: robot.dh.1.a, distribution: normal, sd: 1 %}]'
expect_exit2 "robot_path.max_chatter_probability" toolpath "$JOB" \
  --set robot_path.max_chatter_probability=0
finish
