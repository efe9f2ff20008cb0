#!/usr/bin/env bash
# Regenerates docs/scene-suite.md (between its generated markers): the randomized scene
# suite of issue 17 (benchmarks/scene_suite.cc over datasets/scene_suite.h), the default
# trajectory fit on 500 logs drawn widely, judged against the fits with 25-, 50- and
# 100-interval segments and single shooting (fixtures/suite_check.h). A few minutes on 2 cores.
#
#   bash scripts/scene_suite.sh            # 500 logs: what docs/scene-suite.md shows
#   bash scripts/scene_suite.sh --logs N   # another count; still writes the page
#
# SCENE_SUITE_CSV=FILE also keeps the default fit's per-log table (--csv) there.
#
# BUILD_DIR (default build) is the CMake build directory to use.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=generated_section.sh
source scripts/generated_section.sh

suite_setup 500 scene_suite "$@"
"$build_dir/bin/scene_suite" --logs "$logs" --threads "$(nproc)" --markdown "$work/suite.md" \
  --csv "${SCENE_SUITE_CSV:-$work/suite.csv}" 2>/dev/null >/dev/null
"$build_dir/bin/scene_suite" --logs "$logs" --threads "$(nproc)" --second-start \
  --markdown "$work/second.md" 2>/dev/null >/dev/null
{
  echo "Measured $(date -u +%Y-%m-%d) at commit $commit in $((SECONDS - start)) s"
  echo "(\`build/bin/scene_suite --logs $logs\`, then with \`--second-start\`)."
  echo
  cat "$work/suite.md"
  echo
  echo "### With the second start (\`TrajectoryOptions::second_start\`, off by default)"
  echo
  sed -n 3,5p "$work/second.md"
} > "$work/generated.md"
splice docs/scene-suite.md "$work/generated.md"
echo "scene_suite: wrote docs/scene-suite.md"
