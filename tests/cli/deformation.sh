#!/usr/bin/env bash
# Paper 000 in full on its example (examples/000_kr600_multipoint.yaml):
# `robomill deflection` (Figure 11, Eq 22) and the four stability diagrams of
# `stability.deformation` (Figures 12-13), with the judged properties, and bad
# input exiting 2 with the field named.
#
# Assumptions of the example (docs/assumptions.md): tool Ø12 mm bending as a
# 9.6 mm round bar, KR600-class geometry from the datasheet, ap swept, down
# milling, process damping with 000's Ksp, wear land and μ.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/000_kr600_multipoint.yaml"

# --- Figure 11: node 1's deformation grows with ap up to ap_lim, then stays.
"$ROBOMILL" deflection "$JOB" --out "$WORK/d" --quiet || fail "deflection exit code"
[ "$(head -1 "$WORK/d/deflection.csv")" = \
  "ap_mm,node,z_mm,dx_um,dy_um,ae_actual_mm,entry_nominal_deg,entry_actual_deg,contact_nodes,iterations,case" ] \
  || fail "deflection.csv header"
limit=$(awk -F: '/"critical_depth_mm"/ { gsub(/[ ,]/, "", $2); print $2 }' "$WORK/d/summary.json")
awk -F, -v limit="$limit" 'NR > 1 && $2 == 1 {
    if ($6 >= 4.0 || $8 <= $7) { print "ap " $1 ": ae/entry not corrected"; bad = 1 }
    if ($1 <= limit) { if (n && $5 <= last) { print "ap " $1 ": dy did not grow"; bad = 1 }; at_limit = $5 }
    else if ($5 > 1.02 * at_limit || $5 < 0.98 * at_limit) { print "ap " $1 ": dy " $5 " moved past ap_lim"; bad = 1 }
    last = $5; n++ }
  END { exit bad }' "$WORK/d/deflection.csv" || fail "000 Fig 11 trend"
max_um=$(awk -F: '/"max_deflection_um"/ { gsub(/[ ,]/, "", $2); print $2 }' "$WORK/d/summary.json")
entry=$(awk -F: '/"max_entry_increase_deg"/ { gsub(/[ ,]/, "", $2); print $2 }' "$WORK/d/summary.json")
echo "[validation] 000 Conclusion 2 (10 000 rpm): max deformation ${max_um} um (paper: > 90 um), entry angle +${entry} deg (paper: > 1 deg); ap_lim ${limit} mm (Eq 22)"
grep -qi 'nan\|inf' "$WORK/d/deflection.csv" "$WORK/d/summary.json" && fail "non-finite number written"

# --- Figures 12-13 at a lobe bottom (7200 rpm) and a peak (8200 rpm).
SPEEDS='stability.speeds={from: 7200 rpm, to: 8200 rpm, count: 2}'
"$ROBOMILL" stability "$JOB" --set "$SPEEDS" --out "$WORK/s" --quiet || fail "stability exit code"
[ "$(head -1 "$WORK/s/sld.csv")" = \
  "spindle_rpm,depth_limit_mm,chatter_freq_hz,bifurcation,depth_limit_process_damping_mm,chatter_freq_process_damping_hz,depth_limit_deformation_mm,chatter_freq_deformation_hz,depth_limit_both_mm,chatter_freq_both_hz" ] \
  || fail "sld.csv columns"
awk -F, 'NR > 1 {
    printf "[validation] 000 Fig 12-13, %d rpm: traditional %.3f mm; process damping %+.1f %%; deformation %+.2f %%; both %+.1f %% (000 at 8200 rpm: both +25 %%)\n",
      $1, $2, 100 * ($5 / $2 - 1), 100 * ($7 / $2 - 1), 100 * ($9 / $2 - 1)
    if ($7 < $2 * 0.999 || $9 < $5 * 0.999 || $5 < $2) { print "a variant shrank the stable region"; bad = 1 }
    gain[NR] = $7 / $2 }
  END { if (!(gain[3] > gain[2])) { print "deformation should expand most at the lobe peak (8200 rpm)"; bad = 1 }; exit bad }' \
  "$WORK/s/sld.csv" || fail "000 variants"

# --- A rigid tool and robot: the deformation variant is the traditional one.
"$ROBOMILL" stability "$JOB" --set 'stability.speeds={from: 8200 rpm, count: 1}' \
  --set 'tool.E=1e9 GPa' --set deflection.robot=false --out "$WORK/rigid" --quiet \
  || fail "rigid exit code"
awk -F, 'NR == 2 { d = $7 / $2 - 1; if (d < 0) d = -d; exit d > 1e-6 }' "$WORK/rigid/sld.csv" \
  || fail "rigid system: deformation variant differs from the traditional diagram"

expect_exit2 "process.direction" deflection "$JOB" --set process.direction=up
expect_exit2 "stability.deformation" stability "$JOB" --set stability.method=zoa
expect_exit2 "deflection.equivalent_diameter" deflection "$JOB" --set 'deflection.equivalent_diameter=13 mm'
expect_exit2 "deflection.depths.to" deflection "$JOB" --set 'deflection.depths={from: 1 mm, to: 70 mm}'
expect_exit2 "deflection.elements" deflection "$JOB" --set deflection.elements=0
expect_exit2 "deflection.robot" deflection "$SOURCE/examples/demo.yaml" --set 'process.direction=down' \
  --set 'deflection={robot: true}'
expect_exit2 "cutting.law" deflection "$SOURCE/examples/002_kr270_fractional_law.yaml"
finish
