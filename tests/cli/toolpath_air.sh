#!/usr/bin/env bash
# `robomill toolpath` with a mistyped coordinate (issue 31, point 5): a 100 km
# feed move (G1 X100000000) is timed in full but sampled only near the stock,
# so the run answers in seconds, and a warning names its line. The sample
# count, not the wall-clock time, is what is checked.
source "$(dirname "$0")/lib.bash"
G="$SOURCE/examples/toolpath_pocket_gcode.yaml"
cat > "$WORK/typo.nc" <<'NC'
%
O1031 (A SLOT, THEN A MISTYPED X)
G90 G94 G17 G21
T1 M6
S8000 M3
G0 X-10. Y20. Z25.
G0 Z17.
G1 X50. F600.
G1 X100000000. F600.
G0 Z25.
M30
%
NC
"$ROBOMILL" toolpath "$G" --set "toolpath.file=$WORK/typo.nc" --out "$WORK/typo" > "$WORK/typo.log" 2>&1 \
  || fail "typo program exit code: $(cat "$WORK/typo.log")"
grep -q 'warning (line 9): a move 99.9999 km long' "$WORK/typo.log" || fail "no warning naming line 9: $(cat "$WORK/typo.log")"
grep -q 'away from the stock' "$WORK/typo.log" || fail "the unsampled path is not reported"
num() { awk -F': ' -v k="\"$1\"" '$1 ~ k { gsub(/,/, "", $2); print $2; exit }' "$WORK/typo/summary.json"; }
samples=$(num samples)
# Near the 60 x 40 x 20 mm block at 0.125 mm (half the 0.25 mm resolution):
# the slot (60 mm) and the cutter's reach beyond the block (40.3 mm, plus a
# few steps): under a thousand samples; sampling the whole 100 km would be 8e8.
awk -v n="$samples" 'BEGIN { exit !(n > 500 && n < 3000) }' || fail "samples $samples"
# The times: 60 mm and 100 km - 50 mm at 600 mm/min, then the 8 mm retract
# at 30 m/min.
cutting=$(num cutting_time_s)
awk -v t="$cutting" 'BEGIN { e = (60 + 1e8 - 50) / 10; exit !(t > e * (1 - 1e-9) && t < e * (1 + 1e-9)) }' \
  || fail "cutting time $cutting s"
unsampled=$(num unsampled_length_mm)
awk -v u="$unsampled" 'BEGIN { exit !(u > 1e8 - 200 && u < 1e8) }' || fail "unsampled length $unsampled mm"
# The slot is cut through the block as before: 60 mm x 10 mm x 3 mm (the
# long move cuts its last 10 mm).
v=$(num volume_removed_mm3)
awk -v v="$v" 'BEGIN { a = 60 * 10 * 3; exit !(v > 0.99 * a && v < 1.01 * a) }' \
  || fail "removed volume $v mm^3"
finish
