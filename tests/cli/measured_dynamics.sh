#!/usr/bin/env bash
# Measured dynamics end to end: `robomill frf` writes FRFs of a modal table,
# `robomill fit-modes` recovers the modes, `robomill stability` runs from the
# fitted modes and from the FRFs directly; bad FRF input exits 2 naming the field.
source "$(dirname "$0")/lib.bash"
JOB="$SOURCE/examples/003_kr270_measured_frf.yaml"

# FRFs of the modal table, ASCII and binary UFF58 and CSV.
"$ROBOMILL" frf "$JOB" --spacing log --from 10 --to 6000 --points 3000 --out "$WORK/frf" --quiet \
  || fail "frf exit code"
[ "$(grep -c '^    58$' "$WORK/frf/frf.uff")" -eq 2 ] || fail "frf.uff should hold two datasets 58"
"$ROBOMILL" frf "$JOB" --format uff58b --out "$WORK/frfb" --from 10 --to 100 --step 0.5 --quiet \
  || fail "frf binary exit code"
grep -q '58b' "$WORK/frfb/frf.uff" || fail "binary UFF58 header"
"$ROBOMILL" frf "$JOB" --format csv --kind mobility --out "$WORK/frfc" --from 10 --to 100 --step 1 \
  --quiet || fail "frf csv exit code"
[ -s "$WORK/frfc/frf_xx.csv" ] && [ -s "$WORK/frfc/frf_yy.csv" ] || fail "frf csv files"

# Fit the bundled measurement (2 % noise) and check every file and column.
"$ROBOMILL" fit-modes "$JOB" --out "$WORK/fit" --quiet || fail "fit-modes exit code"
for f in modes.csv frf_fit.csv stabilization.csv modes.yaml summary.json; do
  [ -s "$WORK/fit/$f" ] || fail "fit-modes did not write $f"
done
[ "$(head -1 "$WORK/fit/modes.csv")" = \
  "direction,fn_hz,zeta,k_N_per_m,m_kg,frf,mode,band_low_hz,band_high_hz,fit_error,assurance,contribution" ] \
  || fail "modes.csv header"
[ "$(head -1 "$WORK/fit/frf_fit.csv")" = "frf,freq_hz,measured_re,measured_im,fitted_re,fitted_im" ] \
  || fail "frf_fit.csv header"
[ $(($(wc -l < "$WORK/fit/modes.csv") - 1)) -eq 9 ] || fail "expected the nine Tab. 1 modes"
grep -qi 'nan\|inf' "$WORK/fit/modes.csv" "$WORK/fit/summary.json" && fail "non-finite number"
for key in modes fit_error; do
  grep -q "\"$key\"" "$WORK/fit/summary.json" || fail "fit-modes summary.json lacks $key"
done

# The fitted table pasted into a job reproduces the fitted modes.
{ sed -n '/^name:/,/^dynamics:/p' "$JOB"; sed 's/^/  /' "$WORK/fit/modes.yaml"; } > "$WORK/pasted.yaml"
"$ROBOMILL" validate "$WORK/pasted.yaml" --quiet || fail "modes.yaml does not paste into a job"

# Stability from the fitted modes and from the measured FRFs directly.
for use in fit frf; do
  "$ROBOMILL" stability "$JOB" --set dynamics.use=$use --set stability.speeds.count=20 \
    --out "$WORK/sld-$use" --quiet || fail "stability from $use: exit code"
  grep -q "\"dynamics\": \"$use\"" "$WORK/sld-$use/summary.json" || fail "summary names dynamics $use"
done

# Bad FRF input: exit 2, the field named, nothing written.
expect_exit2 "dynamics.frf[0].file" fit-modes "$JOB" --set 'dynamics.frf=[{file: missing.uff}]'
printf 'freq_hz,re,im\n10,1e-6,0\n9,1e-6,0\n' > "$WORK/decreasing.csv"
expect_exit2 "line 3" fit-modes "$JOB" \
  --set "dynamics.frf=[{file: $WORK/decreasing.csv, response: x, units: m/N}]"
printf '    -1\n    58\nnot a dataset\n' > "$WORK/truncated.uff"
expect_exit2 "dynamics.frf[0].file" fit-modes "$JOB" --set "dynamics.frf=[{file: $WORK/truncated.uff}]"
expect_exit2 "only the zero-order method" stability "$JOB" --set dynamics.use=frf \
  --set stability.method=fdm
expect_exit2 "--noise" frf "$JOB" --noise 2
finish
