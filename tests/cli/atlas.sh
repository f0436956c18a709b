#!/usr/bin/env bash
# `robomill atlas`: 1 and 2 threads give identical results, a re-run resumes
# (computes nothing when complete), a run killed with SIGKILL mid-way and then
# resumed ends with one row per item equal to an uninterrupted run, a second
# run on a store in use is refused (locked), a store of another job is
# refused unless --restart, a corrupt store is an error naming the file, and
# bad atlas input exits 2 naming the field.
source "$(dirname "$0")/lib.bash"
BASE="$SOURCE/examples/003_kr270_atlas.yaml"

# job NAME COUNTS REDUNDANCY_COUNT SPEEDS: a copy of the example with its own
# grid and a store next to it (atlas.store is relative to the job file).
job() {
  sed -e "s|counts: \[5, 5, 1\]|counts: $2|" -e "s|count: 3}|count: $3}|" \
    -e "s|count: 100}|count: $4}|" -e "s|store: .*|store: $1.sqlite|" "$BASE" > "$WORK/$1.yaml"
}
# expect CODE FRAGMENT ARGS...: robomill ARGS exits CODE with FRAGMENT in its message.
expect() {
  local code=$1 fragment=$2; shift 2
  msg=$("$ROBOMILL" "$@" 2>&1); got=$?
  [ "$got" -eq "$code" ] || fail "$*: exit $got (expected $code): $msg"
  case "$msg" in *"$fragment"*) ;; *) fail "$*: message lacks '$fragment': $msg" ;; esac
}

# 1 vs 2 threads: identical exported tables (every value, all digits written).
job small "[4, 3, 1]" 2 30
cp "$WORK/small.yaml" "$WORK/small2.yaml"
sed -i "s|store: .*|store: small2.sqlite|" "$WORK/small2.yaml"
"$ROBOMILL" atlas "$WORK/small.yaml" --threads 1 --quiet || fail "1-thread run"
"$ROBOMILL" atlas "$WORK/small2.yaml" --threads 2 --quiet || fail "2-thread run"
"$ROBOMILL" atlas "$WORK/small.yaml" --export "$WORK/e1" --quiet || fail "export 1"
"$ROBOMILL" atlas "$WORK/small2.yaml" --export "$WORK/e2" --quiet || fail "export 2"
[ -s "$WORK/e1/atlas.csv" ] && [ -s "$WORK/e1/summary.json" ] || fail "export files"
[ $(($(wc -l < "$WORK/e1/atlas.csv") - 1)) -eq 24 ] || fail "4 x 3 points x 2 angles = 24 rows"
cmp -s "$WORK/e1/atlas.csv" "$WORK/e2/atlas.csv" || fail "1 and 2 threads differ"
grep -q '"complete": true' "$WORK/e1/summary.json" || fail "summary: complete"
grep -qi 'nan\|inf' "$WORK/e1/atlas.csv" "$WORK/e1/summary.json" && fail "non-finite number written"
# Physics sanity: stable depths positive and ordered, frequencies in the robot's range.
awk -F, 'NR > 1 && $6 == 1 && !($12 > 0 && $14 >= $12 && $7 > 5 && $7 < 100) { bad = 1 }
  END { exit bad }' "$WORK/e1/atlas.csv" || fail "implausible values in atlas.csv"
# A complete store: the same command computes nothing.
out=$("$ROBOMILL" atlas "$WORK/small.yaml" --threads 2) || fail "re-run"
case "$out" in *"0 items computed"*"24 were already"*) ;; *) fail "re-run computed again: $out" ;; esac

# Another job on the same store: refused (exit 2, naming --restart), unless --restart.
expect 2 "--restart" atlas "$WORK/small.yaml" --set atlas.depth_max=4
"$ROBOMILL" atlas "$WORK/small.yaml" --set atlas.depth_max=4 --restart --quiet || fail "--restart"

# SIGKILL mid-run, then resume: one row per item, equal to an uninterrupted run.
# 400 speeds per item (about 2 s on one thread): long enough that the run is
# still going when the loop below sees its first commit (at 100 it could end
# first on an idle machine).
job big "[12, 10, 1]" 3 400
cp "$WORK/big.yaml" "$WORK/ref.yaml"
sed -i "s|store: .*|store: ref.sqlite|" "$WORK/ref.yaml"
"$ROBOMILL" atlas "$WORK/big.yaml" --threads 1 --quiet &
pid=$!
# Wait until a batch of results is committed after the store was created: the
# write-ahead log grows past the size it had with the job and items alone.
wal="$WORK/big.sqlite-wal"
first=0
for _ in $(seq 1 400); do
  size=$(stat -c %s "$wal" 2> /dev/null || echo 0)
  if [ "$first" -eq 0 ]; then first=$size; elif [ "$size" -gt "$first" ]; then break; fi
  sleep 0.05
done
# While it runs the store is locked: a second run is refused with the path.
expect 1 "locked" atlas "$WORK/big.yaml" --threads 1
kill -9 "$pid" 2> /dev/null
wait "$pid" 2> /dev/null
out=$("$ROBOMILL" atlas "$WORK/big.yaml" --threads 2) || fail "resume after SIGKILL"
already=$(echo "$out" | sed -n 's/.* \([0-9]*\) were already.*/\1/p')
{ [ -n "$already" ] && [ "$already" -gt 0 ] && [ "$already" -lt 360 ]; } \
  || fail "the killed run should have committed part of the 360 items: $out"
"$ROBOMILL" atlas "$WORK/ref.yaml" --threads 2 --quiet || fail "uninterrupted run"
"$ROBOMILL" atlas "$WORK/big.yaml" --export "$WORK/k" --quiet || fail "export resumed"
"$ROBOMILL" atlas "$WORK/ref.yaml" --export "$WORK/r" --quiet || fail "export reference"
[ $(($(wc -l < "$WORK/k/atlas.csv") - 1)) -eq 360 ] || fail "resumed store: 360 rows expected"
[ "$(cut -d, -f1 "$WORK/k/atlas.csv" | sort -u | wc -l)" -eq 361 ] || fail "duplicate item rows"
cmp -s "$WORK/k/atlas.csv" "$WORK/r/atlas.csv" || fail "killed + resumed differs from uninterrupted"

# A file that is not a store: an error naming it, never a silent restart.
echo "not a database, just text that is long enough to fill a page header" > "$WORK/junk.sqlite"
expect 1 "junk.sqlite" atlas "$WORK/small.yaml" --set atlas.store=junk.sqlite
grep -q "not a database" "$WORK/junk.sqlite" || fail "the corrupt file was overwritten"
expect 1 "no such file" atlas "$WORK/small.yaml" --set atlas.store=none.sqlite --export "$WORK/x"

# Bad input: exit 2 naming the field.
expect 2 "atlas.analyses[0]" atlas "$WORK/small.yaml" --set 'atlas.analyses=[stiffness]'
expect 2 "atlas.grid.counts[0]" atlas "$WORK/small.yaml" --set 'atlas.grid.counts=[0, 1, 1]'
expect 2 "atlas.depth_max" atlas "$WORK/small.yaml" --set 'atlas.depth_max=60 mm'
expect 2 "atlas.speeds" atlas "$WORK/small.yaml" --set 'atlas.speeds=null'
finish
