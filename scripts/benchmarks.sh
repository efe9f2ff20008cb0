#!/usr/bin/env bash
# Regenerates the published benchmarks: docs/error_vs_time.csv, docs/error_vs_time.png, the
# generated part of docs/benchmarks.md (between its "generated" markers) and of
# docs/step_speed.md. Builds error_vs_time and step_benchmark (Release) and runs them with
# one thread per fit. The full run takes about 10 minutes on 2 cores; run it on an idle
# machine, since the times are wall-clock.
#
#   bash scripts/benchmarks.sh            # full run: what docs/ shows
#   bash scripts/benchmarks.sh --quick    # under two minutes; writes to $BUILD_DIR/benchmarks-quick/
#
# BUILD_DIR (default build) is the CMake build directory to use.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=generated_section.sh
source scripts/generated_section.sh

quick_option "$@"

for tool in cmake gnuplot awk; do
  command -v "$tool" >/dev/null || { echo "benchmarks: $tool not found (bash scripts/setup.sh)" >&2; exit 1; }
done
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target error_vs_time step_benchmark >/dev/null

if ((quick)); then
  out="$build_dir/benchmarks-quick"
  mkdir -p "$out"
else
  out="docs"
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

cpu_model="$(awk -F': ' '/^model name/ {print $2; exit}' /proc/cpuinfo)"
cpu_mhz="$(awk -F': ' '/^cpu MHz/ {printf "%.0f", $2; exit}' /proc/cpuinfo)"
machine="$(nproc) cores ($(getconf _NPROCESSORS_ONLN) online), ${cpu_model:-unknown CPU} at ${cpu_mhz:-?} MHz, $(uname -sr)"
commit="$(commit_label)"
load_before="$(cut -d' ' -f1-3 /proc/loadavg)"

# ---- 1. error against run time ---------------------------------------------------------
evt_args=(--threads 1 --csv "$out/error_vs_time.csv" --markdown "$work/tables.md")
if ((quick)); then evt_args+=(--quick); fi
echo "benchmarks: error_vs_time ${evt_args[*]}"
"$build_dir/bin/error_vs_time" "${evt_args[@]}" | tee "$work/evt_summary.txt"
# Control: the same suite (100- and 1000-step logs, poses only) simulated at the log rate,
# so that the estimators' model is exact at substeps 1; only its headline table is published.
if ((!quick)); then
  echo "benchmarks: error_vs_time control (--log-every 1)"
  "$build_dir/bin/error_vs_time" --lengths 100,1000 --seeds 20,6 --poses-only --log-every 1 --threads 1 \
    --csv "$work/control.csv" --markdown "$work/control.md" | tee "$work/control_summary.txt"
fi
load_after_evt="$(cut -d' ' -f1-3 /proc/loadavg)"

# Plot: one panel per (motion, noise); one curve per estimator through its log lengths;
# a point only where at least half the runs identified a.
estimators=("closed-form" "equation-error" "trajectory default" "trajectory seg25 sub1"
            "trajectory seg50 sub1" "trajectory seg100 sub1" "trajectory seg50 sub2"
            "trajectory seg50 sub4")
motions=(poses velocities)
noises=(none mocap poor)
for m in "${motions[@]}"; do
  for n in "${noises[@]}"; do
    for k in "${!estimators[@]}"; do
      awk -F, -v e="${estimators[$k]}" -v m="$m" -v n="$n" '
        NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        $col["estimator"] == e && $col["motion"] == m && $col["noise"] == n &&
        $col["scene"] == "all" {
          ok = $col["runs"] - $col["failed"] - $col["missed_a"]
          if (ok * 2 >= $col["runs"] && $col["med_err_a"] != "-" && $col["med_err_a"] > 0)
            print $col["steps"], $col["med_wall_s"], 100 * $col["med_err_a"]
        }' "$out/error_vs_time.csv" | sort -n > "$work/plot_${m}_${n}_${k}.dat"
    done
  done
done
lengths="$(awk -F, 'NR > 1 { print $7 }' "$out/error_vs_time.csv" | sort -nu | paste -sd, - | sed 's/,/, /g')"
{
  cat <<EOF
set terminal pngcairo size 1500,950 font "Sans,11"
set output "$out/error_vs_time.png"
set datafile missing "-"
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xrange [1e-5:10]
set yrange [1e-4:1e4]
set grid xtics ytics mxtics mytics lc rgb "#dddddd"
set multiplot layout 2,3 title "Error against run time: median relative error of a = e_t mu vs median wall time per log (one thread)\\nsynthetic 100 Hz logs, 4 scene types pooled; points: $lengths-step logs (time grows with length); no point where fewer than half the runs identified a" font "Sans,13"
EOF
  colors=("#000000" "#888888" "#1f77b4" "#2ca02c" "#ff7f0e" "#d62728" "#9467bd" "#8c564b")
  ptypes=(5 4 7 9 11 13 15 6)
  for m in "${motions[@]}"; do
    for n in "${noises[@]}"; do
      case "$n" in
        none) title="noiseless" ;;
        mocap) [ "$m" = poses ] && title="typical noise: 0.3 mm, 3 mrad" || title="typical noise: 3 mm/s, 0.03 rad/s" ;;
        poor) [ "$m" = poses ] && title="poor tracking: 2 mm, 20 mrad" || title="poor: 20 mm/s, 0.2 rad/s" ;;
      esac
      echo "set title \"$m-only logs, $title\""
      echo "set xlabel \"median wall time per log [s]\""
      echo "set ylabel \"median relative error of a [%]\""
      if [ "$m" = poses ] && [ "$n" = none ]; then
        echo "set key top right font \",9\" box opaque samplen 2 spacing 0.9"
      else
        echo "unset key"
      fi
      plots=()
      for k in "${!estimators[@]}"; do
        f="$work/plot_${m}_${n}_${k}.dat"
        plots+=("\"$f\" using 2:3 with linespoints lw 2 pt ${ptypes[$k]} ps 1.2 lc rgb \"${colors[$k]}\" title \"${estimators[$k]}\"")
      done
      (IFS=,; echo "plot ${plots[*]}")
    done
  done
  echo "unset multiplot"
} > "$work/plot.gp"
gnuplot "$work/plot.gp" 2> >(grep -v "no valid points" >&2)
echo "benchmarks: wrote $out/error_vs_time.png"

# ---- 2. step speed -----------------------------------------------------------------------
echo "benchmarks: step_benchmark"
"$build_dir/bin/step_benchmark" --benchmark_out="$work/step.csv" --benchmark_out_format=csv \
  > "$work/step_console.txt" 2> "$work/step_stderr.txt"
load_after="$(cut -d' ' -f1-3 /proc/loadavg)"

# Median real and CPU time per step [ns] of each benchmark.
awk -F, '
  /^"BM_/ && /_median"/ {
    name = $1; gsub(/"/, "", name); sub(/\/.*/, "", name)
    unit = $5; gsub(/"/, "", unit)
    scale = unit == "ns" ? 1 : unit == "us" ? 1e3 : unit == "ms" ? 1e6 : 1
    print name, $3 * scale, $4 * scale
  }' "$work/step.csv" > "$work/step_medians.txt"
step_time() {  # name column(2 real, 3 cpu)
  awk -v n="$1" -v c="$2" '$1 == n { print $c }' "$work/step_medians.txt"
}
us() { awk -v x="$1" 'BEGIN { printf (x < 1000 ? "%.2f us" : "%.1f us"), x / 1000 }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf (a / b >= 10 ? "%.0fx" : "%.1fx"), a / b }'; }
per_paper() {  # our ns vs the paper's ms
  awk -v ours="$1" -v paper_ms="$2" 'BEGIN { printf "%.0fx", paper_ms * 1e6 / ours }'
}
{
  general=$(step_time BM_GeneralStep 2); general_cpu=$(step_time BM_GeneralStep 3)
  decoupled=$(step_time BM_DecoupledStep 2); decoupled_cpu=$(step_time BM_DecoupledStep 3)
  closed=$(step_time BM_ClosedFormStep 2); closed_cpu=$(step_time BM_ClosedFormStep 3)
  forced=$(step_time BM_GeneralStepForcedGeneralPath 2); forced_cpu=$(step_time BM_GeneralStepForcedGeneralPath 3)
  dog_g=$(step_time BM_DoglegBaseline_General 2); dog_g_cpu=$(step_time BM_DoglegBaseline_General 3)
  dog_d=$(step_time BM_DoglegBaseline_Decoupled 2); dog_d_cpu=$(step_time BM_DoglegBaseline_Decoupled 3)
  echo "Measured $(date -u +%Y-%m-%d) at commit $commit."
  echo "Machine: $machine (nproc; CPU model and clock from /proc/cpuinfo)."
  echo "Load average (1, 5, 15 min): $load_before before the benchmarks, $load_after after."
  echo
  echo "| path (1024 seeded sliding steps each) | slideid, wall | slideid, CPU | dogleg baseline, wall (same steps) | speed-up, wall | speed-up, CPU |"
  echo "|---|---:|---:|---:|---:|---:|"
  echo "| general (q_z > 0, tilting moments) | $(us "$general") | $(us "$general_cpu") | $(us "$dog_g") | $(ratio "$dog_g" "$general") | $(ratio "$dog_g_cpu" "$general_cpu") |"
  echo "| decoupled (q_z = 0, no tilting: scalar root) | $(us "$decoupled") | $(us "$decoupled_cpu") | $(us "$dog_d") | $(ratio "$dog_d" "$decoupled") | $(ratio "$dog_d_cpu" "$decoupled_cpu") |"
  echo "| decoupled steps forced through the general Newton path | $(us "$forced") | $(us "$forced_cpu") | $(us "$dog_d") | $(ratio "$dog_d" "$forced") | $(ratio "$dog_d_cpu" "$forced_cpu") |"
  echo "| pure translation, b = 1 (closed form) | $(us "$closed") | $(us "$closed_cpu") | - | - | - |"
  echo
  echo "Against the paper's Table 1 (MATLAB, 2.6 GHz MacBook Pro, per step; Examples 1 / 2 / 3),"
  echo "as the paper's time divided by this run's wall time of the general path ($(us "$general"))"
  echo "for all three examples: each has q_z = 0.08 m, and Example 3 turns (its push is 2.5 mm"
  echo "off the centre line), so every one of their steps takes the general path:"
  echo
  echo "| paper's solver | Example 1 | Example 2 | Example 3 | paper / slideid |"
  echo "|---|---:|---:|---:|---:|"
  echo "| NCP-based model, PATH | 6.4 ms | 6.4 ms | 3.6 ms | $(per_paper "$general" 6.4) / $(per_paper "$general" 6.4) / $(per_paper "$general" 3.6) |"
  echo "| quadratic model, PATH | 2.4 ms | 2.6 ms | 1.4 ms | $(per_paper "$general" 2.4) / $(per_paper "$general" 2.6) / $(per_paper "$general" 1.4) |"
  echo "| quadratic model, fsolve | 9.9 ms | 8.3 ms | 5.8 ms | $(per_paper "$general" 9.9) / $(per_paper "$general" 8.3) / $(per_paper "$general" 5.8) |"
  echo
  echo "Accuracy of both solvers on the same steps, from the same run (residual ="
  echo "max|SlidingEquationResiduals| at the solution):"
  echo
  echo '```'
  sed -n '1,/^(mean work/p' "$work/step_console.txt"
  echo '```'
} > "$work/step_generated.md"

{
  echo "Measured $(date -u +%Y-%m-%d) at commit $commit."
  echo "Machine: $machine (nproc; CPU model and clock from /proc/cpuinfo)."
  echo "Load average (1, 5, 15 min): $load_before before the run, $load_after_evt after; wall times"
  echo "exceed CPU times when other processes compete for the cores."
  echo "Run: $(sed 's/^error_vs_time: //; s/; wrote .*$//' "$work/evt_summary.txt")."
  cat "$work/tables.md"
  if ((!quick)); then
    echo
    echo "### Control: the same kinds of scene simulated at the log rate (poses only)"
    echo
    echo "Simulated at 10 ms and logged every step, with the wrench held over each interval:"
    echo "the estimators' model is then exact at substeps 1, and what remains is noise."
    echo "Run: $(sed 's/^error_vs_time: //; s/; wrote .*$//' "$work/control_summary.txt")."
    awk '/^### / { n++ } n == 1 && !/^### /' "$work/control.md"
  fi
} > "$work/evt_generated.md"

if ((quick)); then
  cp "$work/evt_generated.md" "$out/benchmarks_generated.md"
  cp "$work/step_generated.md" "$out/step_speed_generated.md"
else
  splice docs/benchmarks.md "$work/evt_generated.md"
  splice docs/step_speed.md "$work/step_generated.md"
fi
echo "benchmarks: wrote $out/ (error_vs_time.csv, error_vs_time.png, $( ((quick)) && echo "benchmarks_generated.md, step_speed_generated.md" || echo "benchmarks.md, step_speed.md"))"
