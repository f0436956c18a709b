#!/usr/bin/env bash
# `robomill forces` on the demo: files, columns, tooth-passing period, phases.
source "$(dirname "$0")/lib.bash"
out="$WORK/demo"
"$ROBOMILL" forces "$SOURCE/examples/demo.yaml" --out "$out" --quiet || fail "demo exit code $?"
[ -s "$out/forces.csv" ] || fail "forces.csv missing"
[ -s "$out/summary.json" ] || fail "summary.json missing"
header=$(head -1 "$out/forces.csv")
[ "$header" = "angle_deg,t_s,fx_N,fy_N,fz_N,torque_Nm" ] || fail "forces.csv header: $header"
ls -A "$out" | grep -q '^\.' && fail "temporary files left in $out"

# 2 revolutions × 2 teeth × 180 steps per tooth.
rows=$(($(wc -l < "$out/forces.csv") - 1))
[ "$rows" -eq 720 ] || fail "expected 720 samples, got $rows"

# Tooth period at 1000 rpm with 2 teeth: 30 ms.
period=$(grep '"tooth_period_s"' "$out/summary.json" | sed 's/.*: *//; s/,//')
awk -v p="$period" 'BEGIN { exit !(p > 0.02999 && p < 0.03001) }' || fail "tooth period $period"

# Phases of one tooth (004 Table A1): torque rises from 0° over the 16.5°
# entry, is highest in the stabilized stage, falls to zero by 64.7° and stays
# zero until the next tooth at 180°.
awk -F, 'NR > 1 && $1 < 180 {
  if ($1 > 2 && $1 < 16) { if ($6 <= last) bad = "entry torque not rising at " $1 }
  if ($1 > 66 && $1 < 179 && ($6 != 0 || $3 != 0 || $4 != 0)) bad = "force outside the cut at " $1
  if ($1 >= 17 && $1 <= 48 && $6 > peak) peak = $6
  if ($1 > 50 && $1 < 64 && $6 >= prev_exit && prev_exit > 0) bad = "exit torque not falling at " $1
  if ($1 > 50 && $1 < 64) prev_exit = $6
  last = $6
} END { if (bad) { print bad; exit 1 } if (peak <= 0) { print "no cut"; exit 1 } }' "$out/forces.csv" \
  || fail "tooth phases"

# Mean forces are in the summary and finite.
for axis in x y z; do
  value=$(json_number "$out/summary.json" mean_N "$axis")
  [ -n "$value" ] || fail "mean_N.$axis missing"
done
grep -qi 'nan\|inf' "$out/summary.json" "$out/forces.csv" && fail "non-finite number written"

# --set overrides a field; the default output folder comes from the command.
(cd "$WORK" && "$ROBOMILL" forces "$SOURCE/examples/demo.yaml" --set forces.revolutions=1 \
   --set 'process.ae=2 mm' --quiet) || fail "--set run failed"
rows=$(($(wc -l < "$WORK/out/forces/forces.csv") - 1))
[ "$rows" -eq 360 ] || fail "--set forces.revolutions=1 gave $rows samples"
grep -q '"exit": 33.55' "$WORK/out/forces/summary.json" || fail "--set process.ae=2mm not applied (exit angle)"

# Every bundled example validates and runs (the program jobs, which have no
# single cut, run in cli.toolpath).
for job in "$SOURCE"/examples/*.yaml; do
  "$ROBOMILL" validate "$job" --quiet || fail "$(basename "$job") does not validate"
  grep -q '^toolpath:' "$job" && continue
  "$ROBOMILL" forces "$job" --out "$WORK/ex-$(basename "$job" .yaml)" --quiet \
    || fail "$(basename "$job") forces failed"
done
finish
