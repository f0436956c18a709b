#!/usr/bin/env bash
# dynamics.postures (001 Eq 16-18): the interpolated modal table reaches the
# analyses (validate lists it, stability and frf run on it), and every
# inconsistency of the library exits 2 naming the field.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/001_kr270_posture_library.yaml"

out=$("$ROBOMILL" validate "$JOB") || fail "validate exit code"
case "$out" in *"15 measured postures interpolated at robot.posture"*) ;;
  *) fail "validate does not report the interpolation: $out" ;; esac
# At a library posture the table is that posture's (here the first).
out=$("$ROBOMILL" validate "$JOB" --set 'robot.posture=[-23.199, 12.909, 32.506, 0, 44.585, -23.199]')
case "$out" in *"(= posture 1)"*"x: fn 26.0"*) ;;
  *) fail "validate at library posture 1: $out" ;; esac
# dynamics.at overrides robot.posture.
out=$("$ROBOMILL" validate "$JOB" --set 'dynamics.at=[0, 8.41, 38.308, 0, 43.282, 0]')
case "$out" in *"interpolated at dynamics.at (= posture 6)"*) ;;
  *) fail "dynamics.at: $out" ;; esac

"$ROBOMILL" stability "$JOB" --set 'stability.speeds={from: 2000 rpm, to: 4000 rpm, count: 12}' \
  --out "$WORK/s" --quiet || fail "stability exit code"
grep -q '"dynamics": "postures"' "$WORK/s/summary.json" || fail "stability: dynamics not postures"
grep -q '"posture_interpolation"' "$WORK/s/summary.json" || fail "stability: no posture_interpolation"
"$ROBOMILL" frf "$JOB" --from 5 --to 60 --step 0.5 --format csv --out "$WORK/f" --quiet \
  || fail "frf exit code"
grep -qi 'nan\|inf' "$WORK/s/sld.csv" "$WORK/s/summary.json" && fail "non-finite number written"

P='dynamics.postures'
expect_exit2 "$P[1].modes" frf "$JOB" --set "$P[1].modes=[{direction: x, fn: 20 Hz, zeta: 2 %, k: 5e6 N/m}]"
expect_exit2 "$P[2].modes" frf "$JOB" \
  --set "$P[2].modes[0]={direction: z, fn: 20 Hz, zeta: 2 %, k: 5e6 N/m}"
expect_exit2 "$P[0].modes[0].direction" frf "$JOB" \
  --set "$P[0].modes[0]={direction: [1, 1, 0], fn: 20 Hz, zeta: 2 %, k: 5e6 N/m}"
expect_exit2 "$P[3].posture" frf "$JOB" --set "$P[3].posture=[0, 10, 20]"
expect_exit2 "$P[0].posture" frf "$JOB" --set "$P[0].posture=null"
sed '/^robot:/,$d' "$JOB" > "$WORK/no_robot.yaml"
expect_exit2 "dynamics.at" frf "$WORK/no_robot.yaml"
"$ROBOMILL" validate "$WORK/no_robot.yaml" --set 'dynamics.at=[0, 8.41, 38.308, 0, 43.282, 0]' \
  --quiet || fail "a library needs no robot section when dynamics.at is given"
expect_exit2 "dynamics.at" frf "$JOB" --set 'dynamics.at=[0, 10, 20]'
expect_exit2 "dynamics.idw.power" frf "$JOB" --set 'dynamics.idw.power=0'
expect_exit2 "dynamics.idw.joint_weights" frf "$JOB" --set 'dynamics.idw.joint_weights=[0,0,0,0,0,0]'
expect_exit2 "dynamics.modes" frf "$JOB" --set 'dynamics.modes=[{direction: x, fn: 20 Hz, zeta: 2 %, k: 5e6 N/m}]'
expect_exit2 "dynamics.from_robot" frf "$JOB" --set 'dynamics.from_robot=true'
expect_exit2 "dynamics.at" frf "$SOURCE/examples/demo.yaml" --set 'dynamics.at=[0, 1]'
expect_exit2 "$P[0].modes[1].zeta" frf "$JOB" \
  --set "$P[0].modes[1]={direction: y, fn: 20 Hz, zeta: 0, k: 5e6 N/m}"
finish
