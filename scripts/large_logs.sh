#!/usr/bin/env bash
# Reproduces the large-log figures of docs/robustness.md: identify's wall time and peak
# resident memory on pushed logs of 1e4, 1e5 and 1e6 rows (Paper Example 3's periodic push,
# run for 100 s to 10,000 s at dt = 0.01 s). The logs are written to $WORK (not the
# repository): ~2.5 GB for the 1e6-row pair.
#   closed-form, equation-error: the noise-free log with velocities (--write both);
#   trajectory: the poses-only log with 0.3 mm / 3 mrad motion-capture noise, per --threads.
# Usage: bash scripts/large_logs.sh [ROWS...]      (default: 10000 100000 1000000)
# Environment: SLIDEID_BIN_DIR (build/bin), WORK (/tmp/slideid-large-logs), THREADS ("1 2"),
# METHODS ("closed-form equation-error trajectory": the methods to measure).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${SLIDEID_BIN_DIR:-build/bin}
work=${WORK:-/tmp/slideid-large-logs}
threads=${THREADS:-"1 2"}
methods=${METHODS:-"closed-form equation-error trajectory"}
rows=("$@")
((${#rows[@]})) || rows=(10000 100000 1000000)
scene=datasets/scenes/example3_pushed_square.ini
dt=0.01
[ -x /usr/bin/time ] || { echo "large_logs: needs GNU time (apt-get install time)"; exit 1; }
[ -x "$bin/identify" ] || { echo "large_logs: no $bin/identify: run scripts/build.sh"; exit 1; }
mkdir -p "$work"

# Runs identify and prints one table row: rows, method, threads, wall s, peak MB, exit,
# solver iterations, the estimate of a.
measure() {
  local n=$1 log=$2 method=$3 nthreads=$4 extra=${5:-}
  local out="$work/out.json" tm="$work/time.txt" code=0
  /usr/bin/time -f "%e %M" -o "$tm" "$bin/identify" --log "$log" --method "$method" \
    --threads "$nthreads" --json $extra > "$out" 2> "$work/err.txt" || code=$?
  local a iterations
  a=$(sed -n 's/^{"e_t_mu": {"value": \([^,]*\),.*/\1/p' "$out" | head -1)
  iterations=$(sed -n 's/.*"iterations": \([0-9]*\).*/\1/p' "$out" | head -1)
  read -r wall kb < "$tm"
  printf "%9d  %-15s %7s  %8.2f  %8.0f  %4d  %10s  %s\n" "$n" "$method" "$nthreads" "$wall" \
    "$((kb / 1024))" "$code" "${iterations:--}" "${a:--}"
}

printf "%9s  %-15s %7s  %8s  %8s  %4s  %10s  %s\n" rows method threads "wall s" "peak MB" exit \
  iterations a
for n in "${rows[@]}"; do
  duration=$(awk -v n="$n" -v dt="$dt" 'BEGIN { printf "%.6g", (n - 1) * dt }')
  clean="$work/pushed_${n}_velocities.csv"
  noisy="$work/pushed_${n}_poses_noisy.csv"
  [ -s "$clean" ] || "$bin/simulate" --scene "$scene" --duration "$duration" --write both \
    --step-info no --out "$clean" > /dev/null
  [ -s "$noisy" ] || "$bin/simulate" --scene "$scene" --duration "$duration" --write poses \
    --step-info no --noise-pose 3e-4 --noise-angle 3e-3 --seed 1 --out "$noisy" > /dev/null
  for method in $methods; do
    case $method in
      trajectory) for t in $threads; do measure "$n" "$noisy" trajectory "$t"; done ;;
      *) measure "$n" "$clean" "$method" 1 ;;
    esac
  done
done
