#!/usr/bin/env bash
# The test suite under AddressSanitizer and UndefinedBehaviorSanitizer (docs/robustness.md):
# builds everything in build-asan/ (-fsanitize=address,undefined -fno-sanitize-recover, -O1,
# libstdc++ and Eigen assertions on) and runs ctest there. Any sanitizer report fails the
# test that triggered it, including reports from the tools the tests run: they exit with
# code 86, which no tool uses. Extra ctest arguments may be given, e.g. -E 'Heavy'.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p build-asan
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DSLIDEID_SANITIZE=ON \
  -DSLIDEID_BUILD_BENCHMARKS=OFF > build-asan/configure.log 2>&1 || { cat build-asan/configure.log; exit 1; }
cmake --build build-asan -j"$(nproc)" > build-asan/build.log 2>&1 || { tail -60 build-asan/build.log; exit 1; }
echo "sanitizers: build ok (build-asan)"
export ASAN_OPTIONS=exitcode=86:detect_leaks=1:strict_string_checks=1:check_initialization_order=1
export UBSAN_OPTIONS=exitcode=86:print_stacktrace=1:halt_on_error=1
cd build-asan
ctest --output-on-failure -j"$(nproc)" "$@"
