#!/usr/bin/env bash
# robomill listen (docs/monitoring.md): the synthetic pair regenerated from
# `robomill simulate` (examples/listen/make_synthetic.py) is judged as
# simulate judged it, with the chatter frequency within 1 % of simulate's; the
# bundled examples run for every signal kind; bad recordings are clear errors
# that write nothing.
source "$(dirname "$0")/lib.bash" "$@"
PY=/usr/bin/python3
EX="$SOURCE/examples/listen"

# 1. Regenerate the synthetic pair with this build and judge it.
"$PY" "$EX/make_synthetic.py" "$ROBOMILL" "$WORK/synth" > /dev/null || fail "make_synthetic.py"
truth_hz=$(awk -F: '/"simulate_chatter_freq_hz"/ && $2 !~ /null/ { gsub(/[ ,]/, "", $2); print $2 }' \
  "$WORK/synth/truth.json")
cp "$EX"/benchmark_*.yaml "$WORK/synth/"
"$ROBOMILL" listen "$WORK/synth/benchmark_displacement_wav.yaml" --out "$WORK/pair" --quiet \
  || fail "listen on the pair: exit code"
for f in summary.json spectrum.csv spectrogram.csv recordings.csv sld.csv; do
  [ -s "$WORK/pair/$f" ] || fail "pair: no $f"
done
head -1 "$WORK/pair/spectrum.csv" | grep -q '^freq_hz,psd_m2_per_Hz,cause,recording$' \
  || fail "spectrum.csv header: $(head -1 "$WORK/pair/spectrum.csv")"
verdicts=$(awk -F, 'NR > 1 { printf "%s ", $7 }' "$WORK/pair/recordings.csv")
[ "$verdicts" = "stable chatter " ] || fail "pair verdicts: '$verdicts' (expected stable chatter)"
heard=$(awk -F, 'NR == 3 { print $8 }' "$WORK/pair/recordings.csv")
awk -v h="$heard" -v t="$truth_hz" 'BEGIN { d = (h - t) / t; if (d < 0) d = -d; exit !(d <= 0.01) }' \
  || fail "pair: chatter at '$heard' Hz, simulate's at $truth_hz Hz (more than 1 % apart)"
grep -q '"chatter_freq_mismatch_pct"' "$WORK/pair/summary.json" \
  || fail "pair: no model mismatch in summary.json"

# 2. Every bundled example (one per signal kind) gives its known verdict.
check_example() {  # JOB EXPECTED_CHATTER(true|false)
  local job=$1 expected=$2 out="$WORK/ex_$(basename "$1" .yaml)"
  "$ROBOMILL" listen "$EX/$job" --out "$out" --quiet || { fail "$job: exit code"; return; }
  grep -q "^  \"chatter\": $expected," "$out/summary.json" \
    || fail "$job: chatter is not $expected: $(grep '"chatter"' "$out/summary.json" | head -1)"
}
check_example benchmark_displacement_wav.yaml false   # the first recording: stable
check_example benchmark_sound_wav.yaml true
check_example benchmark_force_csv.yaml true
check_example benchmark_velocity_csv.yaml false
# A tachometer channel: the job sheet's 13 500 rpm is 11 % off the spindle's
# 12 000, beyond the comb search; the pulses give the speed, and it is stable.
check_example tachometer_wav.yaml false
grep -q '"spindle_source": "tachometer"' "$WORK/ex_tachometer_wav/summary.json" \
  || fail "tachometer: the speed is not the tachometer's"
grep -q '"spindle_rpm_measured": 12000\.0' "$WORK/ex_tachometer_wav/summary.json" \
  || fail "tachometer: $(grep spindle_rpm_measured "$WORK/ex_tachometer_wav/summary.json" | head -1)"
grep -q '"recommended_spindle_rpm": \[$' "$WORK/ex_benchmark_sound_wav/summary.json" \
  || fail "sound: no recommended speeds"
[ -s "$WORK/ex_benchmark_sound_wav/report.html" ] && fail "--quiet wrote report.html"
"$ROBOMILL" listen "$EX/benchmark_sound_wav.yaml" --out "$WORK/report" > "$WORK/report.txt" \
  || fail "listen with report: exit code"
grep -q "CHATTER at" "$WORK/report.txt" || fail "listen's message: $(cat "$WORK/report.txt")"
[ -s "$WORK/report/report.html" ] || fail "no report.html"

# 3. Bad input: the field, the reason, no output.
cp "$EX/displacement_stable.wav" "$WORK/whole.wav"
head -c 1000 "$WORK/whole.wav" > "$WORK/cut.wav"
: > "$WORK/empty.wav"
printf 't_s,x\n0,1\n0.001,nan\n' > "$WORK/nan.csv"
cat > "$WORK/bad.yaml" <<'EOF'
recording: {file: whole.wav, spindle: 12000 rpm}
listen: {teeth: 2}
EOF
expect_exit2 "empty.wav" listen "$WORK/bad.yaml" --set recording.file=empty.wav
expect_exit2 "recording.channel" listen "$WORK/bad.yaml" --set recording.channel=3
expect_exit2 "line 3" listen "$WORK/bad.yaml" --set recording.file=nan.csv
expect_exit2 "recording.start" listen "$WORK/bad.yaml" --set recording.start=5
expect_exit2 "recording.spindle" listen "$WORK/bad.yaml" --set 'recording={file: whole.wav}'
expect_exit2 "listen.teeth" listen "$WORK/bad.yaml" --set 'listen={}'
expect_exit2 "recording" listen "$SOURCE/examples/benchmark_1dof_005.yaml"
# A truncated WAV and a recording too short to judge are "unknown", never a guess.
"$ROBOMILL" listen "$WORK/bad.yaml" --set recording.file=cut.wav --out "$WORK/cut" --quiet \
  || fail "truncated WAV: exit code"
grep -q '"chatter": "unknown"' "$WORK/cut/summary.json" \
  || fail "truncated WAV (0.03 s): not unknown: $(grep '"reason"' "$WORK/cut/summary.json" | head -1)"
# A sample rate below twice the tooth frequency: unknown with the reason.
"$ROBOMILL" listen "$WORK/bad.yaml" --set recording.spindle="300000 rpm" --out "$WORK/fast" \
  --quiet || fail "fast spindle: exit code"
grep -q '"chatter": "unknown"' "$WORK/fast/summary.json" || fail "tooth above Nyquist: not unknown"
finish
