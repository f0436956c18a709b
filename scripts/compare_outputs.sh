#!/usr/bin/env bash
# Runs every command of robomill on the bundled examples with two builds of
# the program and compares what they write, file by file, byte by byte.
# A refactoring that must not change behaviour (issue #32) passes when this
# prints "identical" for every run.
#
#   scripts/compare_outputs.sh BEFORE/robomill AFTER/robomill [WORKDIR]
#
# Volatile values are masked before comparing: wall-clock times
# (`elapsed_s`, `advice_s`, `optimization_s`, `grid_points_per_s`, "in 0.76 s"
# and "items/s" in messages), the thread count and the output folder, which
# differ between any two runs of the same build, and the atlas's job hash
# (its --set names each side's own store).
set -uo pipefail
cd "$(dirname "$0")/.."
before=$(realpath "$1")
after=$(realpath "$2")
work=${3:-$(mktemp -d /tmp/robomill-compare.XXXXXX)}
mkdir -p "$work"

# command | job (or input) | extra arguments
runs=(
  "validate|examples/demo.yaml|"
  "forces|examples/demo.yaml|"
  "stability|examples/demo.yaml|"
  "stability|examples/000_kr600_multipoint.yaml|"
  "stability|examples/003_kr270_measured_frf.yaml|"
  "stability|examples/003_kr270_process_damping.yaml|"
  "stability|examples/001_kr270_posture_library.yaml|"
  "frf|examples/000_kr600_multipoint.yaml|"
  "fit-modes|examples/003_kr270_measured_frf.yaml|"
  "robot|examples/004_kr300_pose_optimization.yaml|"
  "deflection|examples/000_kr600_multipoint.yaml|"
  "simulate|examples/002_case_b_1dof.yaml|"
  "simulate|examples/002_case_c_2dof.yaml|"
  "surface|examples/001_case_1_surface.yaml|"
  "forces|examples/001_ball_end_surface.yaml|"
  "advise|examples/003_kr270_cutting_advice.yaml|"
  "optimize|examples/004_kr300_pose_optimization.yaml|"
  "atlas|examples/003_kr270_atlas.yaml|--set atlas.store=@WORK@/@SIDE@-atlas.sqlite"
  "atlas|examples/003_kr270_atlas.yaml|--set atlas.store=@WORK@/@SIDE@-atlas.sqlite --export @OUT@"
  "toolpath|examples/toolpath_pocket_gcode.yaml|"
  "toolpath|examples/toolpath_ball_5axis_apt.yaml|"
  "toolpath|examples/toolpath_bull_nose_gcode.yaml|"
  "toolpath|examples/toolpath_pocket_krl.yaml|"
  "toolpath|examples/toolpath_robot_pocket.yaml|--optimize"
  "listen|examples/listen/benchmark_displacement_wav.yaml|"
  "listen|examples/listen/turning_accelerometer_mat.yaml|"
  "identify-cutting|@WORK@/cutting_tests.csv|--teeth 2 --ap 1"
  "identify-stiffness|examples/data/000_kr600_loading_tests.csv|--job examples/000_kr600_multipoint.yaml"
)

# Mean forces of four slot tests (2 teeth, ap 1 mm) for identify-cutting.
cat > "$work/cutting_tests.csv" <<'CSV'
feed_per_tooth_mm,fx_N,fy_N,fz_N
0.025,41.7,118.3,12.9
0.05,63.2,187.1,17.4
0.075,84.9,256.4,21.8
0.1,106.1,325.0,26.5
CSV

mask() {  # file -> masked text on stdout
  sed -E -e 's/"([a-z_]*elapsed_s|advice_s|optimization_s|grid_points_per_s|seconds|threads)": *[-0-9.eE+]+/"\1": MASKED/g' \
         -e 's/"job_hash": *"[0-9a-f]+"/"job_hash": MASKED/g' \
         -e 's#(<td>[a-z_.]*job_hash</td><td>)[^<]*#\1MASKED#g' \
         -e 's#(<td>[a-z_.]*(elapsed_s|advice_s|optimization_s|grid_points_per_s)</td><td>)[^<]*#\1MASKED#g' \
         -e "s#$work/(before|after)#OUT#g" \
         -e 's/ in [0-9.]+ s\b/ in (time) s/g' -e 's/[0-9]+\.[0-9]+ s;/(time) s;/g' -e 's/[0-9.]+ items\/s/(rate) items\/s/g' "$1"
}

status=0
for i in "${!runs[@]}"; do
  IFS='|' read -r command input extra <<< "${runs[$i]//@WORK@/$work}"
  [[ -e $input ]] || { echo "skip  $command $input (no such file)"; continue; }
  for side in before after; do
    bin=$before; [[ $side == after ]] && bin=$after
    out="$work/$side/$i-$command"
    rm -rf "$out"; mkdir -p "$out"
    args=${extra//@OUT@/$out}
    args=${args//@SIDE@/$side}
    # The atlas run starts from an empty store; its --export reads that store.
    [[ $command == atlas && $args != *--export* ]] && rm -f "$work/$side-atlas.sqlite"
    outarg=(--out "$out")
    [[ $command == validate || $command == atlas ]] && outarg=()
    "$bin" "$command" "$input" "${outarg[@]}" $args > "$out.stdout" 2> "$out.stderr"
    echo $? > "$out.rc"
  done
  b="$work/before/$i-$command" a="$work/after/$i-$command"
  differ=""
  if ! cmp -s "$b.rc" "$a.rc"; then differ="exit status $(cat "$b.rc") -> $(cat "$a.rc")"; fi
  cmp -s <(mask "$b.stdout") <(mask "$a.stdout") || differ+=" (stdout)"
  cmp -s <(mask "$b.stderr") <(mask "$a.stderr") || differ+=" (stderr)"
  while IFS= read -r -d '' f; do
    rel=${f#"$b"/}
    [[ $rel == *.sqlite* ]] && continue  # the atlas's store holds wall-clock times; its export is compared
    if [[ ! -e $a/$rel ]]; then differ+=" missing:$rel"; continue; fi
    cmp -s <(mask "$f") <(mask "$a/$rel") || differ+=" $rel"
  done < <(find "$b" -type f -print0 | sort -z)
  while IFS= read -r -d '' f; do
    rel=${f#"$a"/}; [[ -e $b/$rel ]] || differ+=" new:$rel"
  done < <(find "$a" -type f -print0 | sort -z)
  if [[ -z $differ ]]; then
    echo "identical  $command $input $extra ($(find "$b" -type f | wc -l) files, exit $(cat "$b.rc"))"
  else
    echo "DIFFERENT  $command $input $extra:$differ"; status=1
  fi
done
echo "outputs in $work"
exit $status
