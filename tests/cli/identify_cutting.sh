#!/usr/bin/env bash
# End to end: synthesize slot-milling mean forces with `robomill forces` at
# five feeds (001 §3.2's procedure), identify the coefficients with
# `robomill identify-cutting`, and recover the job's coefficients within 1 %.
source "$(dirname "$0")/lib.bash"
cat > "$WORK/slot.yaml" <<'JOB'
tool: {type: flat, diameter: 8 mm, teeth: 2, helix: 30 deg, overhang: 25 mm}
cutting: {law: linear, Ktc: 1661.8 N/mm^2, Krc: 1240.8 N/mm^2, Kac: 19.1 N/mm^2,
          Kte: 7.1 N/mm, Kre: 15.9 N/mm, Kae: 2.3 N/mm}
process: {spindle: 5000 rpm, feed_per_tooth: 0.02 mm, ap: 1 mm, ae: 8 mm, direction: down}
forces: {revolutions: 1, steps_per_tooth: 2000, axial_elements: 100}
JOB
echo "feed_per_tooth_mm,fx_N,fy_N,fz_N" > "$WORK/tests.csv"
for fz in 0.02 0.04 0.06 0.08 0.10; do
  "$ROBOMILL" forces "$WORK/slot.yaml" --set "process.feed_per_tooth=$fz" --out "$WORK/f$fz" --quiet \
    || fail "forces at fz=$fz"
  s="$WORK/f$fz/summary.json"
  echo "$fz,$(json_number "$s" mean_N x),$(json_number "$s" mean_N y),$(json_number "$s" mean_N z)" \
    >> "$WORK/tests.csv"
done
"$ROBOMILL" identify-cutting "$WORK/tests.csv" --teeth 2 --ap "1 mm" --out "$WORK/id" --quiet \
  || fail "identify-cutting exit code"
for pair in Ktc_N_per_mm2:1661.8 Krc_N_per_mm2:1240.8 Kac_N_per_mm2:19.1 \
            Kte_N_per_mm:7.1 Kre_N_per_mm:15.9 Kae_N_per_mm:2.3; do
  key=${pair%%:*}; truth=${pair##*:}
  found=$(json_number "$WORK/id/summary.json" coefficients "$key")
  awk -v f="$found" -v t="$truth" 'BEGIN { d = f - t; if (d < 0) d = -d; exit !(d <= 0.01 * t) }' \
    || fail "$key: identified $found, synthesized with $truth"
done
[ -s "$WORK/id/fit.csv" ] && [ -s "$WORK/id/cutting.yaml" ] || fail "fit.csv or cutting.yaml missing"
# The ready-to-paste cutting section is a valid job section.
{ cat "$WORK/id/cutting.yaml"; echo "tool: {diameter: 8 mm, teeth: 2}"; } > "$WORK/pasted.yaml"
"$ROBOMILL" validate "$WORK/pasted.yaml" --quiet || fail "cutting.yaml does not validate"

# Bad data: one feed only, a missing column, a non-number.
printf 'feed_per_tooth_mm,fx_N,fy_N,fz_N\n0.05,1,2,3\n0.05,1,2,3\n' > "$WORK/one.csv"
"$ROBOMILL" identify-cutting "$WORK/one.csv" --teeth 2 --ap 1 --out "$WORK/bad1" 2>/dev/null
[ $? -eq 2 ] || fail "single feed: exit code"
printf 'feed_per_tooth_mm,fx_N,fy_N\n0.05,1,2\n' > "$WORK/col.csv"
msg=$("$ROBOMILL" identify-cutting "$WORK/col.csv" --teeth 2 --ap 1 --out "$WORK/bad2" 2>&1)
[ $? -eq 2 ] || fail "missing column: exit code"
case "$msg" in *fz_N*) ;; *) fail "missing column not named: $msg" ;; esac
printf 'feed_per_tooth_mm,fx_N,fy_N,fz_N\n0.05,1,abc,3\n' > "$WORK/nan.csv"
msg=$("$ROBOMILL" identify-cutting "$WORK/nan.csv" --teeth 2 --ap 1 --out "$WORK/bad3" 2>&1)
[ $? -eq 2 ] || fail "non-number: exit code"
case "$msg" in *"line 2"*) ;; *) fail "bad cell line not named: $msg" ;; esac
[ ! -e "$WORK/bad1" ] && [ ! -e "$WORK/bad2" ] && [ ! -e "$WORK/bad3" ] || fail "output left after an error"
finish
