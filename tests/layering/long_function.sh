#!/usr/bin/env bash
# layering.detects_a_long_function: scripts/long_functions.py must name a
# free function and a member function defined inside a class body when they
# run over the limit without a reason, and accept them with one.
set -euo pipefail
root=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/src/planted"
python3 - "$work/src/planted/long.cpp" <<'PY'
import sys
body = "\n".join(f"    total += {i};" for i in range(151))
open(sys.argv[1], "w").write(f"""namespace robomill::planted {{
int free_function(int total) {{
{body}
  return total;
}}
template <typename T>
class Accumulator : public Base<T> {{
 public:
  int member(int total) const {{
{body}
    return total;
  }}
}};
}}  // namespace robomill::planted
""")
PY
if out=$(python3 "$root/scripts/long_functions.py" "$work"); then
  echo "long_functions.py passed two functions over the limit:"; echo "$out"; exit 1
fi
echo "$out"
grep -q 'src/planted/long.cpp:2: 154 lines' <<< "$out" || { echo "the free function was not named"; exit 1; }
grep -q 'src/planted/long.cpp:[0-9]*: 15[0-9] lines (limit 150): int member' <<< "$out" \
  || { echo "the member function was not named"; exit 1; }
sed -i 's|^int free_function|// cannot be split: planted\nint free_function|; s|^  int member|  // cannot be split: planted\n  int member|' \
  "$work/src/planted/long.cpp"
python3 "$root/scripts/long_functions.py" "$work" > /dev/null \
  || { echo "the functions with a reason should pass"; exit 1; }
echo "long_functions: the planted free and member functions are caught"
