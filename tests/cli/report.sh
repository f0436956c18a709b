#!/usr/bin/env bash
# report.html (issue 10): every command writes one self-contained report in
# its output bundle (Plotly inlined, nothing loaded from the network, no NaN),
# `robomill report OUTDIR` rebuilds it from the files on disk, --quiet and
# output.formats without html write none, and a folder without summary.json
# exits 2.
source "$(dirname "$0")/lib.bash"
EX="$SOURCE/examples"

# check_report FILE WHAT: self-contained, complete, finite.
check_report() {
  local file=$1 what=$2
  [ -s "$file" ] || { fail "$what: no report.html"; return; }
  grep -qi '<script[^>]*src=' "$file" && fail "$what: loads a script from a URL"
  grep -qi '<link[^>]*href=' "$file" && fail "$what: loads a stylesheet"
  grep -q 'plotly.js v' "$file" || fail "$what: Plotly is not inlined"
  grep -q 'id="robomill-figures"' "$file" || fail "$what: no figures"
  grep -q 'class="plot"' "$file" || fail "$what: no plot"
  grep -q '<h2>Key results</h2>' "$file" || fail "$what: no key-results table"
  # The figures' JSON (the last script before the page's own) holds no NaN.
  sed -n '/id="robomill-figures"/,/<\/script>/p' "$file" | grep -qE 'NaN|Infinity' \
    && fail "$what: NaN or Infinity in the figures"
  tail -c 200 "$file" | grep -q '</html>' || fail "$what: truncated"
}

"$ROBOMILL" forces "$EX/demo.yaml" --out "$WORK/forces" > /dev/null || fail "forces exit code"
check_report "$WORK/forces/report.html" forces
grep -q '<h2>Key inputs</h2>' "$WORK/forces/report.html" || fail "forces: no key-inputs table"
grep -q '855, 270.9, 0 N/mm²' "$WORK/forces/report.html" || fail "forces: Ktc, Krc, Kac missing from the inputs"
grep -q 'force (N)' "$WORK/forces/report.html" || fail "forces: axis title with unit missing"
[ -s "$WORK/forces/inputs.json" ] || fail "forces: no inputs.json"
ls -A "$WORK/forces" | grep -q '^\.' && fail "temporary files left in $WORK/forces"

# The same files give the same page: rebuild from disk and compare.
cp "$WORK/forces/report.html" "$WORK/original.html"
rm "$WORK/forces/report.html"
out=$("$ROBOMILL" report "$WORK/forces") || fail "robomill report exit code"
case "$out" in *report.html*) ;; *) fail "robomill report said: $out" ;; esac
cmp -s "$WORK/forces/report.html" "$WORK/original.html" || fail "rebuilt report differs"

# Stability with the job's cutting tests: the tests appear as markers.
"$ROBOMILL" stability "$EX/003_kr270_process_damping.yaml" --set stability.speeds.count=25 \
  --out "$WORK/stability" > /dev/null || fail "stability exit code"
check_report "$WORK/stability/report.html" stability
grep -q 'chatter observed' "$WORK/stability/report.html" || fail "stability: no test markers"
grep -q 'limiting depth (mm)' "$WORK/stability/report.html" || fail "stability: depth axis"

# --quiet: no report; output.formats without html: no report.
"$ROBOMILL" forces "$EX/demo.yaml" --out "$WORK/quiet" --quiet || fail "quiet exit code"
[ -e "$WORK/quiet/report.html" ] && fail "--quiet wrote report.html"
[ -s "$WORK/quiet/forces.csv" ] || fail "--quiet: no forces.csv"
"$ROBOMILL" forces "$EX/demo.yaml" --set 'output.formats=[csv, json]' --out "$WORK/nohtml" \
  > /dev/null || fail "formats exit code"
[ -e "$WORK/nohtml/report.html" ] && fail "output.formats without html wrote report.html"

# A rebuilt report from a folder written with --quiet.
"$ROBOMILL" report "$WORK/quiet" --quiet || fail "report of a --quiet folder"
check_report "$WORK/quiet/report.html" "rebuilt forces"

# A --quiet run into a folder with an earlier run's report removes it: the
# report would describe results that are no longer there.
"$ROBOMILL" forces "$EX/demo.yaml" --set process.spindle=5000rpm --out "$WORK/quiet" --quiet \
  || fail "quiet re-run exit code"
[ -e "$WORK/quiet/report.html" ] && fail "--quiet left the earlier run's report.html"

# Not an output folder: exit 2 with a clear message, nothing written.
mkdir -p "$WORK/empty"
msg=$("$ROBOMILL" report "$WORK/empty" 2>&1); code=$?
[ "$code" -eq 2 ] || fail "folder without summary.json: exit $code"
case "$msg" in *summary.json*) ;; *) fail "message lacks summary.json: $msg" ;; esac
[ -e "$WORK/empty/report.html" ] && fail "wrote a report into a folder without summary.json"
msg=$("$ROBOMILL" report "$WORK/missing" 2>&1); code=$?
[ "$code" -eq 2 ] || fail "missing folder: exit $code"
finish
