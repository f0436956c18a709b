#!/usr/bin/env bash
# `mpirun -np 2 robomill atlas` (rank 0 deals items and computes, rank 1
# computes) gives the same store as the threaded `robomill atlas`, and a
# re-run on the complete store computes nothing. Registered only when MPI was
# found (tests/CMakeLists.txt). Args: robomill, source dir, mpiexec.
source "$2/tests/cli/lib.bash"
MPIEXEC=$3
BASE="$SOURCE/examples/003_kr270_atlas.yaml"
sed -e "s|counts: \[5, 5, 1\]|counts: [4, 3, 1]|" -e "s|count: 100}|count: 30}|" \
  -e "s|store: .*|store: mpi.sqlite|" "$BASE" > "$WORK/mpi.yaml"
sed -e "s|store: .*|store: threads.sqlite|" "$WORK/mpi.yaml" > "$WORK/threads.yaml"
run_mpi() {
  "$MPIEXEC" --allow-run-as-root --oversubscribe -np 2 "$ROBOMILL" atlas "$@"
}
out=$(run_mpi "$WORK/mpi.yaml" 2>&1) || fail "mpirun -np 2: $out"
case "$out" in *"36 items computed"*"2 MPI ranks"*) ;; *) fail "MPI run output: $out" ;; esac
"$ROBOMILL" atlas "$WORK/threads.yaml" --threads 2 --quiet || fail "threaded run"
"$ROBOMILL" atlas "$WORK/mpi.yaml" --export "$WORK/m" --quiet || fail "export MPI store"
"$ROBOMILL" atlas "$WORK/threads.yaml" --export "$WORK/t" --quiet || fail "export threaded store"
[ $(($(wc -l < "$WORK/m/atlas.csv") - 1)) -eq 36 ] || fail "MPI store: 36 rows expected"
cmp -s "$WORK/m/atlas.csv" "$WORK/t/atlas.csv" || fail "2 MPI ranks differ from 2 threads"
out=$(run_mpi "$WORK/mpi.yaml" 2>&1) || fail "MPI re-run: $out"
case "$out" in *"0 items computed"*"36 were already"*) ;; *) fail "MPI re-run computed again: $out" ;; esac
# Another job on the store: exit 2 naming --restart.
out=$(run_mpi "$WORK/mpi.yaml" --set atlas.depth_max=4 2>&1) && fail "mismatch accepted: $out"
case "$out" in *"--restart"*) ;; *) fail "MPI mismatch message: $out" ;; esac
# Other commands refuse to run once per rank.
out=$("$MPIEXEC" --allow-run-as-root --oversubscribe -np 2 "$ROBOMILL" validate "$WORK/mpi.yaml" 2>&1) \
  && fail "validate over 2 ranks accepted: $out"
case "$out" in *"\`robomill toolpath JOB\` run over MPI ranks"*) ;; *) fail "non-atlas over MPI: $out" ;; esac
finish
