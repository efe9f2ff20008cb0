#!/usr/bin/env bash
# Regenerates docs/coverage.md (between its generated markers): the Monte Carlo coverage
# suite of the 95% intervals (benchmarks/coverage.cc), every method over the 11 conditions
# of datasets/coverage_conditions.h, and a control: the trajectory fit without its
# model-mismatch correction. About 15 minutes on 2 cores.
#
# 1000 logs per condition, because 200 cannot tell the band's edges: a true 95% measured
# over 200 logs spreads over about 92-98% (Wilson 95%), over 1000 logs 93.5-96.2%.
#
#   bash scripts/coverage.sh            # 1000 logs per condition: what docs/coverage.md shows
#   bash scripts/coverage.sh --logs N   # another count; still writes docs/coverage.md
#
# BUILD_DIR (default build) is the CMake build directory to use.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=generated_section.sh
source scripts/generated_section.sh

suite_setup 1000 coverage "$@"

"$build_dir/bin/coverage" --logs "$logs" --threads "$(nproc)" --csv "$work/all.csv" \
  --markdown "$work/all.md" | tee "$work/all.txt"
"$build_dir/bin/coverage" --logs "$logs" --threads "$(nproc)" --methods trajectory \
  --no-mismatch --csv "$work/control.csv" --markdown "$work/control.md" | tee "$work/control.txt"

{
  echo "Measured $(date -u +%Y-%m-%d) at commit $commit in $((SECONDS - start)) s; $logs logs"
  echo "per condition, fixed seeds (\`build/bin/coverage --logs $logs\`)."
  echo
  echo "Summary (cells: condition x parameter whose method reports an interval):"
  echo
  echo '```'
  grep '^coverage: ' "$work/all.txt" | grep -v ' conditions x '
  echo '```'
  echo
  cat "$work/all.md"
  echo
  echo "### Control: the trajectory fit without its model-mismatch correction"
  echo
  echo "The same logs, \`--no-mismatch\`: the estimate is the fit's own, and the intervals"
  echo "are the cluster-robust ones alone."
  echo
  echo '```'
  grep '^coverage: trajectory' "$work/control.txt"
  echo '```'
  echo
  awk '/^### trajectory/ { on = 1; next } on' "$work/control.md"
} > "$work/generated.md"

doc=docs/coverage.md
splice "$doc" "$work/generated.md"
echo "coverage: wrote $doc"
