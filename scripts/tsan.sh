#!/usr/bin/env bash
# The thread-safety test under ThreadSanitizer (docs/robustness.md, "Thread and process
# safety"): builds only tests/tsan/thread_safety_test and the libraries it links, with
# -fsanitize=thread -O1, in build-tsan/, and runs it (8 threads fitting the same logs; a
# batch on 4 jobs). Any data race is a report, and a report fails the run (exit code 66,
# which no tool uses). Python and the benchmarks are left out: they add build time and no
# thread the test does not have.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p build-tsan
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=Debug -DSLIDEID_TSAN=ON -DSLIDEID_BUILD_BENCHMARKS=OFF \
  -DSLIDEID_BUILD_PYTHON=OFF > build-tsan/configure.log 2>&1 || { cat build-tsan/configure.log; exit 1; }
cmake --build build-tsan -j"$(nproc)" --target thread_safety_test > build-tsan/build.log 2>&1 ||
  { tail -60 build-tsan/build.log; exit 1; }
echo "tsan: build ok (build-tsan)"
export TSAN_OPTIONS="exitcode=66 halt_on_error=1 second_deadlock_stack=1"
build-tsan/bin/thread_safety_test
