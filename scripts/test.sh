#!/usr/bin/env bash
# Quick start, second command: install what is missing, build, run every test (what CI
# runs): ctest runs the GoogleTest suites, pytest on the Python module (python/tests, with
# /usr/bin/python3) and the CMake package test (tests/consumer against a fresh install).
# Then the robustness passes of docs/robustness.md: each fuzzer for 30 s (scripts/fuzz.sh)
# and the whole suite under ASan + UBSan (scripts/sanitizers.sh), then the thread-safety test
# under ThreadSanitizer (scripts/tsan.sh).
# After the build, that every relative link in README.md and docs/ resolves
# (scripts/check_links.py) and that every C++ file is formatted as .clang-format says
# (scripts/check_format.sh).
# SLIDEID_QUICK=1 skips the robustness passes.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh  # installs what is missing first (scripts/setup.sh), python3 included
/usr/bin/python3 scripts/check_links.py  # every relative link of README.md and docs/ resolves
bash scripts/check_format.sh  # every C++ file as .clang-format says
(cd build && ctest --output-on-failure -j"$(nproc)")
if [ "${SLIDEID_QUICK:-0}" != 1 ]; then
  bash scripts/fuzz.sh 30
  # The scene suite's statistics (80 logs, 5 fits each) take 134 s under the sanitizers and
  # run no code the other tests do not: they are checked in the Release pass above.
  bash scripts/sanitizers.sh -E '^SceneSuite\.DefaultFitOnWidelyDrawnLogs$'
  bash scripts/tsan.sh  # the thread-safety test under ThreadSanitizer: its own small build
fi
