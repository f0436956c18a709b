#!/usr/bin/env bash
# `robomill surface`: files, columns, summary keys, the scallop height of a
# vertical ball end, and jobs breaking 001 Eq 29-31, the coverage of the
# patch or the shank's clearance exiting 2 with the field named, the value
# that would work, and nothing written.
source "$(dirname "$0")/lib.bash"
J="$SOURCE/examples/001_case_5_surface.yaml"
FAST=(--set surface.area=[0.5,0.5] --set surface.grid=[100,100] --set surface.vibration=false)

"$ROBOMILL" surface "$J" "${FAST[@]}" --out "$WORK/s" --quiet || fail "surface exit code"
for f in summary.json surface.csv profiles.csv surface.bmp; do
  [ -s "$WORK/s/$f" ] || fail "surface did not write $f"
done
[ "$(head -1 "$WORK/s/surface.csv")" = "x_mm,y_mm,z_um" ] || fail "surface.csv header"
[ "$(wc -l < "$WORK/s/surface.csv")" -eq $((101 * 101 + 1)) ] || fail "surface.csv rows"
[ "$(head -1 "$WORK/s/profiles.csv")" = "profile,x_mm,y_mm,z_um" ] || fail "profiles.csv header"
[ "$(head -c 2 "$WORK/s/surface.bmp")" = "BM" ] || fail "surface.bmp is not a BMP"
for key in Ra_um Rq_um Sa_um Sq_um Sz_um max_residual_um; do
  grep -q "\"$key\"" "$WORK/s/summary.json" || fail "summary.json lacks $key"
done
grep -qi 'nan\|inf' "$WORK/s/summary.json" && fail "non-finite number written"

# A vertical ball end without runout: the residual height between passes is
# the scallop R - sqrt(R^2 - (s/2)^2) = 7.8201 um for s = 0.5 mm, R = 4 mm.
"$ROBOMILL" surface "$J" --set surface.area=[1,1] --set surface.grid=[100,100] \
  --set surface.vibration=false --set surface.lead=0 --set surface.tilt=0 \
  --set surface.stepover=0.5 --set process.feed_rate=600 --set tool.runout.offset=0 \
  --out "$WORK/v" --quiet || fail "vertical exit code"
h=$(awk -F': ' '/"max_residual_um"/ { gsub(/,/, "", $2); print $2 }' "$WORK/v/summary.json")
awk -v v="$h" 'BEGIN { exit !(v > 7.8201 * 0.98 && v < 7.8201 * 1.02) }' || fail "scallop $h um"

# 001 Eq 29: at most min(fz, path interval) / 5 = 20 um cells (fz 0.25 mm,
# path interval 0.1 mm); 40 um cells exit 2 naming 100 cells.
expect_exit2 "surface.grid (line" surface "$J" --set surface.grid=[50,50]
expect_exit2 "use grid: [100, 100]" surface "$J" --set surface.grid=[50,50]
"$ROBOMILL" surface "$J" "${FAST[@]}" --set surface.grid=[25,25] --set surface.grid_rule=false \
  --out "$WORK/coarse" --quiet || fail "grid_rule: false should accept a coarse grid"
# 001 Eq 30 and Eq 31.
expect_exit2 "surface.steps_per_revolution" surface "$J" "${FAST[@]}" \
  --set surface.steps_per_revolution=10
expect_exit2 "use steps_per_revolution:" surface "$J" "${FAST[@]}" \
  --set surface.steps_per_revolution=10
expect_exit2 "surface.edge_spacing" surface "$J" "${FAST[@]}" --set surface.edge_spacing=0.01
# The passes must cover the patch.
expect_exit2 "surface.passes" surface "$J" "${FAST[@]}" --set surface.passes=3
expect_exit2 "use passes: 6 or more" surface "$J" "${FAST[@]}" --set surface.passes=3 \
  --set surface.first_pass=0
expect_exit2 "surface.first_pass" surface "$J" "${FAST[@]}" --set surface.first_pass=0.2
# The shank must clear the stock: ap 0.5 mm allows 61 deg of lead on R = 4 mm.
expect_exit2 "surface.lead" surface "$J" "${FAST[@]}" --set surface.lead=70
expect_exit2 "use |lead| <=" surface "$J" "${FAST[@]}" --set surface.lead=70
expect_exit2 "process.ap" surface "$J" "${FAST[@]}" --set process.ap=5 --set tool.overhang=30
# Vibration needs dynamics.
expect_exit2 "surface.vibration" surface "$SOURCE/examples/001_ball_end_surface.yaml" \
  --set 'surface={area: [0.5, 0.5], grid: [100, 100], vibration: true}'
# start: rest (001's dde23 reading) is a choice, only with vibration, and
# excludes warmup and entry.
expect_exit2 "surface.start" surface "$J" --set surface.start=sometimes
expect_exit2 "expected one of: steady, rest" surface "$J" --set surface.start=sometimes
expect_exit2 "surface.start" surface "$J" --set surface.start=rest --set 'surface.warmup=1 s'
expect_exit2 "surface.start" surface "$J" --set surface.start=rest --set surface.entry=1
expect_exit2 "surface.start" surface "$J" "${FAST[@]}" --set surface.start=rest
finish
