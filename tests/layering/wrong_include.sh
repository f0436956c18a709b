#!/usr/bin/env bash
# layering.detects_a_wrong_include: scripts/check_layering.py must fail on an
# include against the pipeline's order. Plants four in a copy of the tree (a
# numerical module reading the job, a numerical header reading a file format,
# a folder that is not a module, a command computing with a numerical module)
# and checks that each is named.
set -euo pipefail
root=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$root/src" "$root/include" "$root/scripts" "$work/"
python3 "$work/scripts/check_layering.py" "$work" > /dev/null \
  || { echo "the unmodified tree should pass"; exit 1; }
echo '#include "robomill/job/job.hpp"' >> "$work/src/toolpath/program.cpp"
sed -i '0,/#include "robomill\//s//#include "robomill\/io\/csv.hpp"\n#include "robomill\//' \
  "$work/include/robomill/stability/lobes.hpp"
sed -i '0,/#include "robomill\//s//#include "robomill\/stability\/lobes.hpp"\n#include "robomill\//' \
  "$work/src/commands/forces.cpp"
mkdir -p "$work/src/misc" && echo '// nothing' > "$work/src/misc/x.cpp"
if out=$(python3 "$work/scripts/check_layering.py" "$work"); then
  echo "check_layering.py passed a tree with wrong includes:"; echo "$out"; exit 1
fi
echo "$out"
grep -q 'src/toolpath/program.cpp:[0-9]*: toolpath includes robomill/job/job.hpp' <<< "$out" \
  || { echo "the toolpath -> job include was not named"; exit 1; }
grep -q 'include/robomill/stability/lobes.hpp:[0-9]*: stability includes robomill/io/csv.hpp' <<< "$out" \
  || { echo "the stability -> io include was not named"; exit 1; }
grep -q 'src/misc/: a module not in the pipeline' <<< "$out" \
  || { echo "the unknown folder was not named"; exit 1; }
grep -q 'src/commands/forces.cpp:[0-9]*: the command includes robomill/stability/lobes.hpp' <<< "$out" \
  || { echo "the command -> stability include was not named"; exit 1; }
echo "layering: the four planted violations are caught"
