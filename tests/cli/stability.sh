#!/usr/bin/env bash
# `robomill stability`: files, columns, summary keys, map mode, experiments.
source "$(dirname "$0")/lib.bash"
out="$WORK/bench"
"$ROBOMILL" stability "$SOURCE/examples/benchmark_1dof_005.yaml" --set stability.speeds.count=12 \
  --out "$out" --quiet || fail "benchmark exit code"
header=$(head -1 "$out/sld.csv")
[ "$header" = "spindle_rpm,depth_limit_mm,chatter_freq_hz,bifurcation" ] || fail "sld.csv header: $header"
rows=$(($(wc -l < "$out/sld.csv") - 1))
[ "$rows" -eq 12 ] || fail "expected 12 speeds, got $rows"
for key in method elapsed_s min_limit_mm max_limit_mm; do
  grep -q "\"$key\"" "$out/summary.json" || fail "summary.json lacks $key"
done
awk -F, 'NR > 1 && ($2 <= 0 || $2 > 10 || ($4 != "hopf" && $4 != "flip" && $4 != "fold" && $4 != "none")) {
  print "bad row: " $0; bad = 1 } END { exit bad }' "$out/sld.csv" || fail "sld.csv rows"
grep -qi 'nan\|inf' "$out/sld.csv" "$out/summary.json" && fail "non-finite number written"

# Map mode writes the spectral radius on the grid.
"$ROBOMILL" stability "$SOURCE/examples/benchmark_1dof_slot.yaml" --set stability.mode=map \
  --set stability.speeds.count=4 --set stability.depths=5 --out "$WORK/map" --quiet || fail "map exit code"
[ "$(head -1 "$WORK/map/map.csv")" = "spindle_rpm,depth_mm,spectral_radius" ] || fail "map.csv header"
[ $(($(wc -l < "$WORK/map/map.csv") - 1)) -eq 20 ] || fail "map.csv should have 4 x 5 rows"

# 003: experiments are checked against the prediction.
"$ROBOMILL" stability "$SOURCE/examples/003_kr270_process_damping.yaml" \
  --set stability.speeds.count=30 --out "$WORK/003" --quiet || fail "003 exit code"
grep -q '"compared": 4' "$WORK/003/summary.json" || fail "003: the four 1660 rpm tests not compared"
[ -s "$WORK/003/sld_envelope.csv" ] || fail "003: modes both should write sld_envelope.csv"
grep -q '"governing_mode"' "$WORK/003/summary.json" || fail "003: envelope tests name no governing mode"
grep -q '"chatter_freq_hz"' "$WORK/003/summary.json" || fail "003: tests carry no chatter frequency"

# The demo's diagram.
"$ROBOMILL" stability "$SOURCE/examples/demo.yaml" --set stability.speeds.count=20 --out "$WORK/demo" \
  --quiet || fail "demo stability exit code"

# Invalid combinations exit 2 naming the field, and write nothing.
msg=$("$ROBOMILL" stability "$SOURCE/examples/benchmark_1dof_slot.yaml" --set stability.method=zoa \
  --set stability.mode=map --out "$WORK/bad" 2>&1); code=$?
[ "$code" -eq 2 ] || fail "zoa map: exit $code"
case "$msg" in *stability.mode*) ;; *) fail "zoa map: field not named: $msg" ;; esac
"$ROBOMILL" stability "$SOURCE/examples/001_ball_end_surface.yaml" --out "$WORK/bad2" 2>/dev/null
[ $? -eq 2 ] || fail "job without stability section: exit code"
[ ! -e "$WORK/bad" ] && [ ! -e "$WORK/bad2" ] || fail "output left after an error"
# Two steps per mode period pass the parser (no aliasing) but do not converge
# the boundary: at 1500 rpm the benchmark's 40 steps are 2.2 per period of its
# 922 Hz mode, and the command says so, with the discretization that gives 8.
out=$("$ROBOMILL" stability "$SOURCE/examples/benchmark_1dof_005.yaml" --out "$WORK/coarse" \
  --set stability.speeds.from="1500 rpm" --set stability.speeds.count=3) || fail "coarse run"
case "$out" in *"2.2 steps per period of the 922 Hz mode"*"discretization: 148 gives 8"*) ;;
  *) fail "no convergence warning: $out" ;; esac
grep -q '"discretization_warning"' "$WORK/coarse/summary.json" || fail "warning not in summary.json"
finish
