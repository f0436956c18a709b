#!/usr/bin/env bash
# `robomill simulate`: files, columns, summary keys, 002's Case B numbers,
# the robot's structure two ways, and bad settings exiting 2 with the field
# named, the value that would work, and nothing written.
source "$(dirname "$0")/lib.bash"
B="$SOURCE/examples/002_case_b_1dof.yaml"
C="$SOURCE/examples/002_case_c_2dof.yaml"

"$ROBOMILL" simulate "$B" --set simulation.duration=1.2 --out "$WORK/b" --quiet || fail "case B exit code"
for f in summary.json timeseries.csv spectrum.csv; do
  [ -s "$WORK/b/$f" ] || fail "simulate did not write $f"
done
[ "$(head -1 "$WORK/b/timeseries.csv" | cut -d, -f1-7)" = "t_s,fx_N,fy_N,fz_N,x_mm,y_mm,z_mm" ] \
  || fail "timeseries.csv header"
[ "$(head -1 "$WORK/b/spectrum.csv")" = "frequency_hz,fx_N,fy_N,fz_N,x_mm,y_mm,z_mm" ] \
  || fail "spectrum.csv header"
for key in static_deviation_mm overshoot_pct settling_time_s first_frequency_hz chatter \
  chatter_freq_hz peak_to_peak_mm mean_force_N; do
  grep -q "\"$key\"" "$WORK/b/summary.json" || fail "summary.json lacks $key"
done
grep -qi 'nan\|inf' "$WORK/b/summary.json" "$WORK/b/spectrum.csv" && fail "non-finite number written"
# 002 Table 1 row 2: |x_s| 0.13 mm, f1 8.8 Hz (ours 0.1333 mm, 8.70 Hz).
xs=$(json_number "$WORK/b/summary.json" static_deviation_mm x)
f1=$(json_number "$WORK/b/summary.json" first_frequency_hz x)
awk -v v="$xs" 'BEGIN { exit !(v < -0.125 && v > -0.142) }' || fail "case B x_s $xs mm"
awk -v v="$f1" 'BEGIN { exit !(v > 8.36 && v < 9.24) }' || fail "case B f1 $f1 Hz"
grep -q '"chatter": false' "$WORK/b/summary.json" || fail "case B should not chatter"

# Case C: y deviates 3.33 times as far as x (1/kr).
"$ROBOMILL" simulate "$C" --set simulation.duration=1.2 --out "$WORK/c" --quiet || fail "case C exit code"
ys=$(json_number "$WORK/c/summary.json" static_deviation_mm y)
awk -v v="$ys" 'BEGIN { exit !(v > 0.42 && v < 0.47) }' || fail "case C y_s $ys mm"

# A 3-joint robot: the reduced model (3-D, exact for 3 joints) and the
# joint-space modes (dynamics.from_robot) are the same structure.
R="$SOURCE/examples/004_kr300_pose_optimization.yaml"
SIM='simulation={duration: 0.6 s, steps_per_tooth: 48, damping_ratio: 0.05, model: reduced6d}'
"$ROBOMILL" simulate "$R" --set "$SIM" --out "$WORK/r1" --quiet || fail "reduced6d exit code"
"$ROBOMILL" simulate "$R" --set 'simulation={duration: 0.6 s, steps_per_tooth: 48}' \
  --set dynamics.from_robot=true --out "$WORK/r2" --quiet || fail "from_robot exit code"
a=$(json_number "$WORK/r1/summary.json" static_deviation_mm y)
b=$(json_number "$WORK/r2/summary.json" static_deviation_mm y)
awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; if (d < 0) d = -d; s = b < 0 ? -b : b; exit !(d <= 1e-6 * s) }' \
  || fail "reduced6d ($a) and from_robot ($b) differ"

# Issue 20: a one-mode slot (12.99 Hz, k 8e5 N/m, zeta 5 %, 4 straight teeth,
# 10 000 rpm, ap 2 mm, linear law without edge forces) settles: two teeth
# always cut and their forces sum to a constant, so the vibration left is
# numerical noise (1.6e-9 mm peak-to-peak, 2e-8 of the static deviation)
# that the former verdict called chatter at 335 Hz. The verdict weighs the
# non-harmonic RMS against 1 % of fz (docs/simulation.md) and says stable.
cat > "$WORK/issue20.yaml" <<'EOF_JOB'
tool: {type: flat, diameter: 20 mm, teeth: 4, helix: 0 deg}
cutting: {law: linear, Ktc: 855 N/mm^2, Krc: 270.93 N/mm^2}
process: {spindle: 10000 rpm, feed_per_tooth: 0.1 mm, ap: 2 mm, ae: 20 mm, direction: down}
dynamics:
  modes: [{direction: x, fn: 12.99 Hz, zeta: 5 %, k: 8e5 N/m}]
simulation: {duration: 3 s}
EOF_JOB
"$ROBOMILL" simulate "$WORK/issue20.yaml" --out "$WORK/i20" --quiet || fail "issue 20 exit code"
grep -q '"chatter": false' "$WORK/i20/summary.json" || fail "issue 20: numerical noise judged chatter"
for key in nonharmonic_rms_mm forced_rms_mm floor_mm floor_basis persistence \
  nonharmonic_energy_fraction once_per_period_spread largest_nonharmonic_hz; do
  grep -q "\"$key\"" "$WORK/i20/summary.json" || fail "chatter_evidence lacks $key"
done
grep -q '"floor_basis": "feed_per_tooth"' "$WORK/i20/summary.json" || fail "issue 20: floor basis"
nh=$(json_number "$WORK/i20/summary.json" chatter_evidence nonharmonic_rms_mm)
fl=$(json_number "$WORK/i20/summary.json" chatter_evidence floor_mm)
awk -v n="$nh" -v f="$fl" 'BEGIN { exit !(n < 1e-6 * f && f > 0.00099 && f < 0.00101) }' \
  || fail "issue 20: non-harmonic RMS $nh mm against floor $fl mm (expected noise << 0.001 mm)"

# A deliberately unstable cut: the benchmark (a/D 0.05) at 12 000 rpm, 1.25x
# the depth `stability` gives there, chatters in `simulate` at the frequency
# `stability` predicts (within 5 %).
BM="$SOURCE/examples/benchmark_1dof_005.yaml"
"$ROBOMILL" stability "$BM" --set 'stability.speeds={from: 12000 rpm, to: 12000 rpm, count: 1}' \
  --out "$WORK/bm_sld" --quiet || fail "benchmark stability exit code"
limit=$(awk -F, 'NR == 2 { print $2 }' "$WORK/bm_sld/sld.csv")
predicted=$(awk -F, 'NR == 2 { print $3 }' "$WORK/bm_sld/sld.csv")
ap=$(awk -v l="$limit" 'BEGIN { print 1.25 * l }')
"$ROBOMILL" simulate "$BM" --set process.spindle="12000 rpm" --set process.ap="$ap mm" \
  --set 'simulation={revolutions: 300}' --out "$WORK/bm_sim" --quiet || fail "benchmark simulate exit code"
grep -q '"chatter": true' "$WORK/bm_sim/summary.json" || fail "benchmark at 1.25x the limit: no chatter"
simulated=$(awk -F: '/"chatter_freq_hz"/ { gsub(/[ ,]/, "", $2); print $2 }' "$WORK/bm_sim/summary.json")
awk -v s="$simulated" -v p="$predicted" 'BEGIN { d = (s - p) / p; if (d < 0) d = -d; exit !(d <= 0.05) }' \
  || fail "benchmark chatter at $simulated Hz, stability predicts $predicted Hz (more than 5 % apart)"

# Bad settings: the field, and what would work.
expect_exit2 "steps_per_tooth: 8" simulate "$B" --set simulation.steps_per_tooth=4
expect_exit2 "simulation.workpiece.border" simulate "$B" --set simulation.workpiece.border=200
# validate names the simulation section among the job's sections.
case "$("$ROBOMILL" validate "$B")" in *"process, simulation)"*) ;; *) fail "validate: no simulation section" ;; esac
# DESIGN.md's name for the part is accepted too, once.
sed 's/workpiece: {border: 0 mm}/workpiece_mesh: {border: 200 mm}/' "$B" > "$WORK/mesh.yaml"
expect_exit2 "simulation.workpiece_mesh.border" simulate "$WORK/mesh.yaml"
expect_exit2 "the same section" simulate "$B" --set 'simulation.workpiece_mesh={border: 2}'
expect_exit2 "needs duration" simulate "$B" --set simulation.duration=0.3
expect_exit2 "simulation.fixation" simulate "$B" --set simulation.model=2dof
expect_exit2 "give either duration or revolutions" simulate "$B" --set simulation.revolutions=10
expect_exit2 "simulation.fixation.stiffness" simulate "$B" --set simulation.fixation.stiffness=-5
# The benchmark's 922 Hz mode at 10000 rpm needs 8 steps per 1.09 ms period.
expect_exit2 "highest mode" simulate "$SOURCE/examples/benchmark_1dof_005.yaml" \
  --set 'simulation={duration: 0.2 s, steps_per_tooth: 10}' --set process.ae=10
# Process damping is applied explicitly: strong damping on a light mode needs
# a fine step (simulation::process_damping_step_limit_s), named with its value.
expect_exit2 "process damping (rate 2.15e+05 1/s on the lightest direction) needs steps_per_tooth: 4305" \
  simulate "$SOURCE/examples/benchmark_1dof_005.yaml" --set process.spindle="1500 rpm" \
  --set process.ap="8 mm" --set 'simulation={duration: 2 s, steps_per_tooth: 200,
  process_damping: {Ksp: 1.5e14 N/m^3, wear_land: 150 um}}'
finish
