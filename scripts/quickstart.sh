#!/usr/bin/env bash
# Quick start, first command: install what is missing, build, and run the main job on the
# bundled default (the paper's Example 1: where the slider comes to rest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
build/bin/simulate --scene datasets/scenes/example1_square.ini --duration 0.6 --out build/example1_square.csv
