#!/usr/bin/env bash
# `make fuzz`: libFuzzer on every parser, seeded from fuzz/corpus*; any crash,
# leak or hang fails. Each fuzzer is one process on one core, so they run in
# as many lanes as there are cores (a 2-core CI machine: two at a time), each
# for its own number of seconds.
#
#   scripts/fuzz.sh BUILD_DIR JOB_S FRF_S PROGRAM_S RECORDING_S [LANES]
set -uo pipefail
build=$1 job_s=$2 frf_s=$3 program_s=$4 recording_s=$5 lanes=${6:-$(nproc)}
cd "$(dirname "$0")/.."

# name | seconds | extra options (the dictionary, limits) | seed corpus | environment
fuzzers=(
  "job_parser|$job_s|-dict=fuzz/job.dict|fuzz/corpus|"
  "frf_readers|$frf_s|-dict=fuzz/frf.dict|fuzz/corpus-frf|"
  "gcode_reader|$program_s|-dict=fuzz/gcode.dict -rss_limit_mb=2048|fuzz/corpus-gcode|"
  "apt_reader|$program_s|-dict=fuzz/apt.dict -rss_limit_mb=2048|fuzz/corpus-apt|"
  "krl_reader|$program_s|-dict=fuzz/krl.dict -rss_limit_mb=2048|fuzz/corpus-krl|"
  "recording_readers|$recording_s|-rss_limit_mb=2048|fuzz/corpus-recording|LSAN_OPTIONS=suppressions=fuzz/lsan-recording.supp"
)

run_one() {  # one fuzzer, its log in $build/fuzz-NAME.log; exit status 1 on a finding
  IFS='|' read -r name seconds options corpus environment <<< "$1"
  local log=$build/fuzz-$name.log
  mkdir -p "$build/corpus-$name-run"
  # shellcheck disable=SC2086
  env $environment "./$build/fuzz/fuzz_$name" $options -max_total_time="$seconds" -timeout=10 \
    -print_final_stats=1 -artifact_prefix="$build/" "$build/corpus-$name-run" "$corpus" \
    > "$log" 2>&1
}

# Longest first, each lane taking the next fuzzer when its last one is done.
status=0
pids=() names=()
for entry in "${fuzzers[@]}"; do
  while (( $(jobs -rp | wc -l) >= lanes )); do wait -n; done
  IFS='|' read -r name seconds _ <<< "$entry"
  echo "fuzz: $name for $seconds s (log: $build/fuzz-$name.log)"
  run_one "$entry" &
  pids+=($!) names+=("$name")
done
for i in "${!pids[@]}"; do
  log=$build/fuzz-${names[$i]}.log
  if wait "${pids[$i]}"; then
    echo "fuzz: ${names[$i]}: $(grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$log" | tr '\n' ' ')"
  else
    tail -40 "$log"
    echo "fuzz: ${names[$i]}: FAILED (crash, leak or hang; reproducer in $build/)"
    status=1
  fi
done
exit $status
