#!/usr/bin/env bash
# The browser test of report.html (issue 10): runs the example jobs' commands,
# rebuilds one report with `robomill report`, then opens every report.html in
# headless Chromium (check_reports.cjs) and fails on any console error, page
# error, network request or figure without data. Screenshots: SHOTS/*.png.
#
# usage: run.sh ROBOMILL SOURCE NODE NODE_MODULES CHROMIUM SHOTS [REPORTS]
set -u
ROBOMILL=$1
SOURCE=$2
NODE=$3
NODE_MODULES=$4
CHROMIUM=$5
SHOTS=$6
REPORTS=${7:-$SHOTS/reports}
EX="$SOURCE/examples"
rm -rf "$REPORTS" "$SHOTS"/*.png
mkdir -p "$REPORTS" "$SHOTS"
failures=0

# run NAME COMMAND ARGS...: one command into $REPORTS/NAME.
run() {
  local name=$1; shift
  local started=$SECONDS
  if ! "$ROBOMILL" "$@" --out "$REPORTS/$name" > "$REPORTS/$name.log" 2>&1; then
    echo "FAIL: robomill $* (log: $REPORTS/$name.log)" >&2
    cat "$REPORTS/$name.log" >&2
    failures=$((failures + 1))
  fi
  echo "ran $name in $((SECONDS - started)) s"
}

run forces          forces     "$EX/demo.yaml"
run stability       stability  "$EX/003_kr270_process_damping.yaml"
run stability-demo  stability  "$EX/demo.yaml"
run fit-modes       fit-modes  "$EX/003_kr270_measured_frf.yaml"
run frf             frf        "$EX/003_kr270_process_damping.yaml"
run simulate        simulate   "$EX/002_case_b_1dof.yaml"
run simulate-2dof   simulate   "$EX/002_case_c_2dof.yaml"
run robot           robot      "$EX/001_kr270_posture_library.yaml"
run deflection      deflection "$EX/000_kr600_multipoint.yaml"
run optimize        optimize   "$EX/004_kr300_pose_optimization.yaml"
run advise          advise     "$EX/003_kr270_cutting_advice.yaml"
run surface         surface    "$EX/001_case_5_surface.yaml"
run toolpath        toolpath   "$EX/toolpath_pocket_gcode.yaml"
# Sampled every 1 mm (257 samples, not 1 960): the same figures, a quarter of
# the run and of the page's drawing.
run toolpath-uncertainty toolpath "$EX/uncertainty_toolpath.yaml" --set uncertainty.samples=8 \
    --set "toolpath.spacing=1 mm"
run listen          listen     "$EX/listen/benchmark_displacement_wav.yaml"
run learn           learn      "$EX/learn/anchor_tool.yaml" --set learn.samples=500 \
    --set uncertainty.samples=200
# A robot learned from hammer tests: the other places' lobes and the fitted modes.
run learn-hammer    learn      "$EX/learn/kr270_hammer.yaml" --set learn.samples=300
run identify-stiffness identify-stiffness "$EX/data/000_kr600_loading_tests.csv" \
    --job "$EX/000_kr600_multipoint.yaml"

# identify-cutting: mean forces of the demo at four feeds, as a user measures them.
echo "feed_per_tooth_mm,fx_N,fy_N,fz_N" > "$REPORTS/cutting_tests.csv"
for fz in 0.03 0.05 0.07 0.09; do
  "$ROBOMILL" forces "$EX/demo.yaml" --set "process.feed_per_tooth=$fz" --out "$REPORTS/f$fz" --quiet
  awk -v fz="$fz" '/"mean_N"/ { inside = 1; next }
    inside && /"[xyz]"/ { gsub(/[ ,]/, ""); split($0, kv, ":"); v[++n] = kv[2] }
    inside && /}/ { inside = 0 }
    END { printf "%s,%s,%s,%s\n", fz, v[1], v[2], v[3] }' "$REPORTS/f$fz/summary.json" \
    >> "$REPORTS/cutting_tests.csv"
  rm -rf "$REPORTS/f$fz"
done
run identify-cutting identify-cutting "$REPORTS/cutting_tests.csv" --job "$EX/demo.yaml"

# atlas --export: a 5 x 4 grid of the atlas example with 2 redundancy angles
# (the store lies next to the copied job).
sed -e "s|counts: \[5, 5, 1\]|counts: [5, 4, 1]|" -e "s|count: 3}|count: 2}|" \
    -e "s|count: 100}|count: 40}|" -e "s|store: .*|store: atlas.sqlite|" \
    "$EX/003_kr270_atlas.yaml" > "$REPORTS/atlas.yaml"
if "$ROBOMILL" atlas "$REPORTS/atlas.yaml" --quiet > "$REPORTS/atlas.log" 2>&1; then
  "$ROBOMILL" atlas "$REPORTS/atlas.yaml" --export "$REPORTS/atlas" >> "$REPORTS/atlas.log" 2>&1 \
    || { echo "FAIL: robomill atlas --export" >&2; failures=$((failures + 1)); }
else
  echo "FAIL: robomill atlas (log: $REPORTS/atlas.log)" >&2; cat "$REPORTS/atlas.log" >&2
  failures=$((failures + 1))
fi

# `robomill report OUTDIR` rebuilds a report from the files on disk.
rm -f "$REPORTS/forces/report.html"
"$ROBOMILL" report "$REPORTS/forces" --quiet || { echo "FAIL: robomill report" >&2; failures=$((failures + 1)); }

reports=()
for dir in "$REPORTS"/*/; do
  name=$(basename "$dir")
  if [ -f "$dir/report.html" ]; then
    reports+=("$name=$dir/report.html")
  else
    echo "FAIL: $name wrote no report.html" >&2
    failures=$((failures + 1))
  fi
done
"$NODE" "$SOURCE/tests/browser/check_reports.cjs" "$NODE_MODULES" "$CHROMIUM" "$SHOTS" "${reports[@]}" \
  || failures=$((failures + 1))
if [ "$failures" -ne 0 ]; then
  echo "browser test: $failures failure(s)" >&2
  exit 1
fi
echo "browser test: ${#reports[@]} reports passed; screenshots in $SHOTS"
