#!/usr/bin/env bash
# Quick start, first command: install what is missing, build, and run the main job:
# identify the friction of the bundled default log (known truth, printed beside).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh identify  # only what the main job needs; scripts/test.sh builds the rest
build/bin/identify --log datasets/logs/default_push.csv
