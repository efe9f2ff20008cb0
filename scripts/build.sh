#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), then configures and builds slideid in build/
# (Release, all cores). Executables land in build/bin/. Arguments are CMake targets to build
# (default: everything, tests and benchmarks included), e.g. `bash scripts/build.sh identify`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > build.log 2>&1 || { cat build.log; exit 1; }
targets=()
for target in "$@"; do targets+=(--target "$target"); done
cmake --build build -j"$(nproc)" "${targets[@]}" >> build.log 2>&1 || { tail -60 build.log; exit 1; }
echo "build: ok (build/bin: $(ls build/bin | tr '\n' ' '))"
