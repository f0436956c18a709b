#!/usr/bin/env bash
# `mpirun -np 2 robomill toolpath` (issue 19 item 6): a facing program long
# enough for three blocks of samples (`toolpath.block_samples` 400 at 2 mm,
# not 4096 at the example's spacing: the same exchange at a sixth of the
# work), the robot's blocks shared over 2 ranks,
# gives the same samples.csv and summary.json (but for the timings) as the
# single process. Registered only when MPI was found (tests/CMakeLists.txt).
# Args: robomill, source dir, mpiexec.
source "$2/tests/cli/lib.bash"
MPIEXEC=$3
# Facing the example pocket's block, 1 mm a pass, 4 mm step-over, 3 levels:
# about 2.7 m of feed moves.
{
  echo "%"
  echo "O1002 (FACING 60X40, 3 LEVELS)"
  echo "G90 G94 G17 G21 G40 G80"
  echo "T1 M6"
  echo "S8000 M3"
  echo "G0 X-8. Y0. Z25."
  for z in 19 18 17; do
    echo "G0 Z$z."
    for y in 0 4 8 12 16 20 24 28 32 36 40; do
      if [ $(((y / 4) % 2)) -eq 0 ]; then x=68; else x=-8; fi
      echo "G1 Y$y. F600."
      echo "G1 X$x."
    done
    echo "G0 Z25."
    echo "G0 X-8. Y0."
  done
  echo "M30"
  echo "%"
} > "$WORK/facing.nc"
JOB="$SOURCE/examples/toolpath_robot_pocket.yaml"
BLOCKS=(--set toolpath.block_samples=400 --set "toolpath.spacing=2 mm")
"$ROBOMILL" toolpath "$JOB" --set toolpath.file="$WORK/facing.nc" "${BLOCKS[@]}" --threads 2 --quiet \
  --out "$WORK/one" || fail "single process"
samples=$(grep -m1 '"samples":' "$WORK/one/summary.json" | tr -dc 0-9)
[ "${samples:-0}" -gt 800 ] || fail "the program should span three blocks of 400 samples: $samples"
out=$("$MPIEXEC" --allow-run-as-root --oversubscribe -np 2 "$ROBOMILL" toolpath "$JOB" \
  --set toolpath.file="$WORK/facing.nc" "${BLOCKS[@]}" --threads 1 --out "$WORK/two" 2>&1) \
  || fail "mpirun -np 2: $out"
case "$out" in *"shared over 2 MPI ranks"*) ;; *) fail "MPI run output: $out" ;; esac
cmp -s "$WORK/one/samples.csv" "$WORK/two/samples.csv" || fail "samples.csv: 2 ranks differ from 1"
cmp -s <(grep -v elapsed "$WORK/one/summary.json") <(grep -v elapsed "$WORK/two/summary.json") \
  || fail "summary.json: 2 ranks differ from 1"
cmp -s "$WORK/one/moves.csv" "$WORK/two/moves.csv" || fail "moves.csv: 2 ranks differ from 1"
# With draws of the uncertain inputs (issue 33) each block's draws travel
# with it: the same P(chatter), band and expected count from 2 ranks as from 1
# (the first level alone: two blocks).
sed '/G0 Z18\./,/^M30/{/^M30/!d}' "$WORK/facing.nc" > "$WORK/facing1.nc"
UJOB="$SOURCE/examples/uncertainty_toolpath.yaml"
"$ROBOMILL" toolpath "$UJOB" --set toolpath.file="$WORK/facing1.nc" --set uncertainty.samples=1 \
  "${BLOCKS[@]}" --threads 2 --quiet --out "$WORK/drawn_one" || fail "single process with draws"
out=$("$MPIEXEC" --allow-run-as-root --oversubscribe -np 2 "$ROBOMILL" toolpath "$UJOB" \
  --set toolpath.file="$WORK/facing1.nc" --set uncertainty.samples=1 "${BLOCKS[@]}" --threads 1 \
  --out "$WORK/drawn_two" 2>&1) || fail "mpirun -np 2 with draws: $out"
cmp -s "$WORK/drawn_one/samples.csv" "$WORK/drawn_two/samples.csv" \
  || fail "samples.csv with draws: 2 ranks differ from 1"
cmp -s <(grep -v elapsed "$WORK/drawn_one/summary.json") \
  <(grep -v elapsed "$WORK/drawn_two/summary.json") \
  || fail "summary.json with draws: 2 ranks differ from 1"
grep -q '"expected_chatter_samples"' "$WORK/drawn_two/summary.json" \
  || fail "the MPI run with draws lacks the expected count"
samples=$(grep -m1 '"samples":' "$WORK/drawn_one/summary.json" | tr -dc 0-9)
[ "${samples:-0}" -gt 400 ] || fail "the one-level program should span two blocks: $samples"
# A bad job fails on every rank with the reason, exit 2, no output.
out=$("$MPIEXEC" --allow-run-as-root --oversubscribe -np 2 "$ROBOMILL" toolpath "$JOB" \
  --set toolpath.file="$WORK/missing.nc" --out "$WORK/bad" 2>&1) && fail "missing program accepted"
case "$out" in *"missing.nc"*) ;; *) fail "MPI error message: $out" ;; esac
[ ! -e "$WORK/bad" ] || fail "a failed MPI run wrote output"
finish
