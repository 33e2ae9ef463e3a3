#!/usr/bin/env bash
# Builds the libFuzzer targets in build-fuzz (clang, -fsanitize=fuzzer,address,undefined)
# and runs each for SECONDS (default 60), one after the other.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      targets: ray_parser obj_loader image scene
#
# Environment: FUZZ_BUILD (default build-fuzz), FUZZ_JOBS (build parallelism, default nproc),
# FUZZ_RSS_MB (default 2048), FUZZ_TIMEOUT (seconds per input before it counts as a hang,
# default 10). Corpora live in $FUZZ_BUILD/corpus/<target> and grow from run to run;
# crashes, hangs (timeout-*), leaks and out-of-memory inputs land in
# $FUZZ_BUILD/artifacts/<target>/. Logs: $FUZZ_BUILD/logs/<target>.log. A summary line
# per target (executions, coverage, features, corpus, findings) is printed and appended to
# $FUZZ_BUILD/logs/summary.tsv. Exits 1 when any target found something.
#
# A finding is fixed, then the input is copied to data/regressions/<target>/ where the
# normal test suite replays it (src/app/fuzz_regression_test.cpp). To reproduce one:
#   build-fuzz/fuzz/<target>_fuzz path/to/crash-...
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"

seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(ray_parser obj_loader image scene)
build="${FUZZ_BUILD:-build-fuzz}"
jobs="${FUZZ_JOBS:-$(nproc)}"
rss_mb="${FUZZ_RSS_MB:-2048}"
timeout_s="${FUZZ_TIMEOUT:-10}"

# Debian's clang and its sanitizer/libFuzzer runtime; installed only when missing.
scripts/install-deps.sh clang-14 libclang-rt-14-dev

flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DLC_FUZZ=ON -DLC_BUILD_TESTS=OFF -DLC_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target $(printf '%s_fuzz ' "${targets[@]}")

corpus="$build/corpus"
fuzz/seed_corpus.sh "$corpus" >/dev/null
mkdir -p "$build/logs"
summary="$build/logs/summary.tsv"
[ -f "$summary" ] || printf 'date\ttarget\tseconds\texecs\texecs_per_s\tcov\tft\tcorpus\tfindings\n' > "$summary"

# Leaks are findings; UBSan stops at the first report (-fno-sanitize-recover).
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0:abort_on_error=0:symbolize=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

status=0
for t in "${targets[@]}"; do
  bin="$build/fuzz/${t}_fuzz"
  art="$build/artifacts/$t"
  mkdir -p "$art"
  dict=()
  case "$t" in
    ray_parser | scene) dict=(-dict="$root/fuzz/dict/ray.dict") ;;
    obj_loader) dict=(-dict="$root/fuzz/dict/obj.dict") ;;
    image) dict=(-dict="$root/fuzz/dict/image.dict") ;;
  esac
  log="$build/logs/$t.log"
  before=$(find "$art" -type f | wc -l)
  echo "fuzz: $t for ${seconds}s (log: $log)"
  set +e
  # -ignore_crashes etc. would hide findings: a run stops at the first one.
  "$bin" "$corpus/$t" "${dict[@]}" -max_total_time="$seconds" -timeout="$timeout_s" \
    -rss_limit_mb="$rss_mb" -malloc_limit_mb="$rss_mb" -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$art/" >"$log" 2>&1
  rc=$?
  set -e
  after=$(find "$art" -type f | wc -l)
  findings=$((after - before))
  # The last status line ("#N DONE cov: C ft: F corp: K/S ...") and the final stats.
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  execs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' || echo 0)
  rate=$(grep -oE 'stat::average_exec_per_sec: *[0-9]+' "$log" | grep -oE '[0-9]+$' || echo 0)
  cov=$(echo "$last" | grep -oE 'cov: [0-9]+' | grep -oE '[0-9]+' || echo "?")
  ft=$(echo "$last" | grep -oE 'ft: [0-9]+' | grep -oE '[0-9]+' || echo "?")
  corp=$(ls "$corpus/$t" | wc -l)
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$(date -u +%FT%TZ)" "$t" "$seconds" "$execs" "$rate" \
    "$cov" "$ft" "$corp" "$findings" >> "$summary"
  echo "fuzz: $t: ${execs} execs (${rate}/s), cov ${cov}, ft ${ft}, corpus ${corp}, findings ${findings} (exit ${rc})"
  if [ "$rc" -ne 0 ] || [ "$findings" -gt 0 ]; then
    status=1
    grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -5 | sed 's/^/  /' || true
  fi
done
exit $status
