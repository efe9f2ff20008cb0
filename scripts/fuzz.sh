#!/usr/bin/env bash
# Builds the libFuzzer targets with clang in build-fuzz/ (ASan + UBSan + coverage) and runs
# each for a bounded time from its seed corpus in fuzz/corpus/ (docs/robustness.md). New
# inputs go to build-fuzz/corpus/, never into the repository; a crash leaves its input in
# build-fuzz/artifacts/ and fails the script. Reproduce one with
#   build-fuzz/bin/fuzz_push_log build-fuzz/artifacts/crash-...
# Usage: bash scripts/fuzz.sh [SECONDS per target, default 30]  (the targets run in parallel)
# Targets (name:corpus): push_log:log, scene:scene, zhou_tripod:tripod, wrench_twist:pairs,
# mcap:mcap, mit_push_h5:mit_push_h5, streams:streams, rosbag:rosbag. They run side by side, so the total time
# is about SECONDS, whatever their number (on 2 cores each gets less CPU).
# fuzz_mit_push_h5 and fuzz_rosbag run their library in a child process: when the library
# faults there (librosbag overflows and over-allocates on damaged bags), the child's copy of
# libFuzzer writes a crash-* file of its own, but the reader answered "unreadable" as it
# should; only the fuzzer's own exit status counts.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
bash scripts/setup.sh
mkdir -p build-fuzz
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Release \
  -DSLIDEID_BUILD_FUZZERS=ON -DSLIDEID_BUILD_TESTS=OFF -DSLIDEID_BUILD_BENCHMARKS=OFF \
  > build-fuzz/configure.log 2>&1 || { cat build-fuzz/configure.log; exit 1; }
cmake --build build-fuzz --target fuzz_push_log fuzz_scene fuzz_mit_push_json fuzz_zhou_tripod \
  fuzz_wrench_twist fuzz_mcap fuzz_mit_push_h5 fuzz_streams fuzz_rosbag -j"$(nproc)" > build-fuzz/build.log 2>&1 ||
  { tail -60 build-fuzz/build.log; exit 1; }
mkdir -p build-fuzz/artifacts
# Leaks inside Debian's libhdf5 on malformed files are its own (fuzz/lsan.supp); ours count.
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
pids=()
targets=()
for name in push_log:log scene:scene mit_push_json:mit_push zhou_tripod:tripod wrench_twist:pairs \
  mcap:mcap mit_push_h5:mit_push_h5 streams:streams rosbag:rosbag; do
  target=${name%%:*} corpus=${name##*:}
  mkdir -p "build-fuzz/corpus/$corpus"
  # libhdf5 asks malloc for what a damaged header says (0x4889000000000058 bytes, found by
  # fuzz_mit_push_h5): a null answer is its error path, as in a build without ASan.
  null_ok=0
  [ "$target" = mit_push_h5 ] && null_ok=1
  ASAN_OPTIONS="allocator_may_return_null=$null_ok${ASAN_OPTIONS:+:$ASAN_OPTIONS}" \
  build-fuzz/bin/fuzz_$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -dict="fuzz/$corpus.dict" -artifact_prefix=build-fuzz/artifacts/ -print_final_stats=1 \
    "build-fuzz/corpus/$corpus" "fuzz/corpus/$corpus" > "build-fuzz/fuzz_$target.log" 2>&1 &
  pids+=($!)
  targets+=("$target")
done
status=0
for i in "${!pids[@]}"; do
  target=${targets[$i]}
  if wait "${pids[$i]}"; then
    # The last count is the fuzzer's own: a reader's child process (fuzz_mit_push_h5,
    # fuzz_rosbag) that dies in the library prints its copy's statistics too.
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "build-fuzz/fuzz_$target.log" | tail -1)
    echo "fuzz: fuzz_$target ok: ${runs:-?} inputs in ${seconds} s"
  else
    status=1
    echo "fuzz: fuzz_$target FAILED:"
    grep -v -E '^#[0-9]+' "build-fuzz/fuzz_$target.log" | tail -40
  fi
done
exit $status
