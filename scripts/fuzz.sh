#!/usr/bin/env bash
# Builds rastray's libFuzzer targets (fuzz/, -DRASTRAY_FUZZ=ON, clang) in
# build-fuzz/ and runs each for a bounded time, one after the other.
#
# Usage: scripts/fuzz.sh [--seconds N] [target...]
#   --seconds N  how long each target runs (default 60)
#   target       gltf_loader_fuzzer, exr_reader_fuzzer (default: both)
#
# Each target starts from its seeds (fuzz/corpus/<target>/, copied into the
# scratch corpus build-fuzz/corpus/<target>/, which keeps what earlier runs
# found; git stays clean). Prints per target the executions, duration,
# executions per second, coverage and corpus, writes them to
# build-fuzz/fuzz-summary.csv, and exits 1 when a target found a crash
# (its input is in build-fuzz/artifacts/<target>/, named in the output).
# Environment: FUZZ_BUILD_JOBS (default 2) for the build.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=60
targets=()
all_targets=(gltf_loader_fuzzer exr_reader_fuzzer)
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds)
      [ $# -ge 2 ] || { echo "fuzz.sh: --seconds needs a value" >&2; exit 2; }
      seconds="$2"
      shift 2
      ;;
    --seconds=*) seconds="${1#--seconds=}"; shift ;;
    -h | --help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *)
      case " ${all_targets[*]} " in
        *" $1 "*) targets+=("$1") ;;
        *) echo "fuzz.sh: unknown target $1 (have: ${all_targets[*]})" >&2; exit 2 ;;
      esac
      shift
      ;;
  esac
done
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || { echo "fuzz.sh: --seconds must be a positive integer" >&2; exit 2; }
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")

build=build-fuzz
# Lean: the fuzz targets need only the libraries, not tests or benchmarks.
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DRASTRAY_FUZZ=ON \
  -DRASTRAY_BUILD_TESTS=OFF -DRASTRAY_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j"${FUZZ_BUILD_JOBS:-2}" --target "${targets[@]}" >/dev/null

summary="$build/fuzz-summary.csv"
echo "target,seconds,executions,exec_per_sec,cov,ft,corp,folder_files,folder_bytes,peak_rss_mb,result,crash_file" >"$summary"
failed=0
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  artifacts="$build/artifacts/$t"
  log="$build/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$build/logs"
  # Seeds a previous run already holds are left as they are.
  cp -n fuzz/corpus/"$t"/* "$corpus"/
  dict=()
  [ -f "fuzz/$t.dict" ] && dict=(-dict="fuzz/$t.dict")
  before=$(ls "$artifacts" | wc -l)
  echo "fuzz: $t for ${seconds} s (log: $log)"
  start=$(date +%s.%N)
  status=0
  "$build/fuzz/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" "${dict[@]}" "$corpus" >"$log" 2>&1 || status=$?
  end=$(date +%s.%N)
  duration=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')

  stat() { awk -v key="stat::$1:" '$1 == key { print $2 }' "$log" | tail -n 1; }
  executions=$(stat number_of_executed_units)
  rate=$(stat average_exec_per_sec)
  rss=$(stat peak_rss_mb)
  # The last status line: "#N DONE cov: C ft: F corp: U/SIZE ...".
  last=$(grep -E '^#[0-9]+' "$log" | tail -n 1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  # libFuzzer's corpus (the inputs it keeps, "corp: U/SIZE") and the
  # scratch folder (everything written to it, by this run and earlier ones).
  corp=$(sed -n 's/.* corp: \([0-9]*\/[0-9]*[a-zA-Z]*\).*/\1/p' <<<"$last")
  units=$(ls "$corpus" | wc -l)
  bytes=$(du -sb "$corpus" | cut -f1)
  crash=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -n 1)
  if [ "$status" -eq 0 ] && [ -z "$crash" ] && [ "$(ls "$artifacts" | wc -l)" -eq "$before" ]; then
    result=clean
  else
    result="crash (exit $status)"
    failed=1
  fi
  echo "fuzz: $t: $result; ${executions:-?} executions in ${duration} s (${rate:-?}/s), cov ${cov:-?}," \
    "ft ${ft:-?}, corp ${corp:-?} (folder: $units files, $bytes bytes), peak RSS ${rss:-?} MB"
  if [ "$result" != clean ]; then
    grep -E '^(==[0-9]+==ERROR|SUMMARY|rastray: internal)|runtime error|terminate called|uncaught' "$log" | head -n 5 || true
    echo "fuzz: $t: crash input: ${crash:-see $artifacts/ and $log}"
  fi
  echo "$t,$seconds,${executions},${rate},${cov},${ft},${corp},$units,$bytes,${rss},$result,${crash}" >>"$summary"
done
echo "fuzz: summary in $summary"
exit "$failed"
