#!/usr/bin/env bash
# Scale-out benchmark: many short logs identified one by one, by identify --batch with 1 and
# 2 threads, by slideid.identify_file in a Python loop, and on a local Dask cluster of 1 and 2
# worker processes (python3 -m slideid.dask), all against identify --batch --jobs 1 measured
# in the same run. Reports logs and rows per second, the speed-up, and the peak resident
# memory of every process (scripts/measure_run.py), also on a quarter of the logs, to show
# that it does not grow with the number of logs (results stream to disk). Checks that every
# run gave the same result for every log (but for run times).
#
#   bash scripts/scale_benchmark.sh           # 10,000 logs: the generated part of docs/scale-out.md
#   bash scripts/scale_benchmark.sh --quick   # 500 logs: $BUILD_DIR/scale-quick/scale-out_generated.md
#
# The logs (60-300 rows, made once by make-dataset) stay in $WORK (default
# /tmp/slideid-scale), about 27 kB each, and are reused by the next run. BUILD_DIR (default
# build) is the CMake build directory. Times are wall-clock: run it on an idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=generated_section.sh
source scripts/generated_section.sh

quick_option "$@"
work="${WORK:-/tmp/slideid-scale}"
python=/usr/bin/python3
count=$((quick ? 500 : 10000))
quarter=$((count / 4))
started=$(date +%s)

"$python" -c "import distributed" 2>/dev/null ||
  { echo "scale_benchmark: $python has no distributed (bash scripts/setup.sh)" >&2; exit 1; }
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target identify make_dataset slideid_python >/dev/null
bin="$build_dir/bin"
export PYTHONPATH="$PWD/$build_dir/python${PYTHONPATH:+:$PYTHONPATH}"

cpu_model="$(awk -F': ' '/^model name/ {print $2; exit}' /proc/cpuinfo)"
cpu_mhz="$(awk -F': ' '/^cpu MHz/ {printf "%.0f", $2; exit}' /proc/cpuinfo)"
memory_gb="$(awk '/^MemTotal/ {printf "%.0f", $2 / 1048576}' /proc/meminfo)"
machine="$(nproc) cores, ${cpu_model:-unknown CPU} at ${cpu_mhz:-?} MHz, ${memory_gb} GB, $(uname -sr)"
commit="$(commit_label)"
load_before="$(cut -d' ' -f1-3 /proc/loadavg)"

# ---- the logs, made once ------------------------------------------------------------------
# Two random pushes of 0.1-1 s each with 0.1-0.5 s rests, logged at 100 Hz with motion-capture
# noise (0.3 mm, 3 mrad): 56-300 rows.
logs="$work/logs_$count"
dataset_args=(--count "$count" --seed 1 --pushes 2 --push-duration-range 0.1:1.0
              --rest-range 0.1:0.5 --noise-pose 3e-4 --noise-angle 3e-3)
if [ "$(awk 'END { print NR - 1 }' "$logs/truth.csv" 2>/dev/null)" != "$count" ]; then
  echo "scale_benchmark: make-dataset ${dataset_args[*]} --out $logs"
  rm -rf "$logs"
  mkdir -p "$work"
  made=$(date +%s)
  "$bin/make-dataset" "${dataset_args[@]}" --out "$logs" --quiet
  made="made in this run in $(($(date +%s) - made)) s"
else
  made="made by an earlier run"
fi
# A quarter of them (the first), for memory against the number of logs.
part="$work/logs_${count}_first_$quarter"
if [ "$(find "$part" -name 'log_*.csv' 2>/dev/null | wc -l)" != "$quarter" ]; then
  rm -rf "$part" && mkdir -p "$part"
  # (awk reads to the end: head would end the pipe early, a failure under pipefail)
  find "$logs" -name 'log_*.csv' | sort | awk -v q="$quarter" 'NR <= q' | xargs -I{} ln -s {} "$part/"
fi
read -r rows_total rows_min rows_median rows_max < <(awk -F, '
  NR == 1 { for (i = 1; i <= NF; i++) if ($i == "rows") c = i; next }
  { print $c }' "$logs/truth.csv" | sort -n |
  awk '{ r[NR] = $1; total += $1 } END { print total, r[1], r[int((NR + 1) / 2)], r[NR] }')
rows_part=$(awk -F, -v q="$quarter" 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
  NR - 1 <= q { total += $col["rows"] } END { print total }' "$logs/truth.csv")

# ---- the runs -----------------------------------------------------------------------------
out="$work/results"
rm -rf "$out" && mkdir -p "$out"
# run NAME COMMAND...: measured; its JSON (measure_run.py) goes to $out/NAME.json.
run() {
  local name=$1
  shift
  echo "scale_benchmark: $name: $*"
  "$python" scripts/measure_run.py -- "$@" > "$out/$name.json" 2> "$out/$name.log" || true
  cat "$out/$name.json"
}
python_loop='
import json, sys, slideid
with open(sys.argv[2], "w") as out:
    for path in slideid.log_files(sys.argv[1]):
        out.write(json.dumps(slideid.identify_file(path)) + "\n")
'
run batch_jobs1 "$bin/identify" --batch "$logs" --jobs 1 --out "$out/batch_jobs1.jsonl"
run batch_jobs2 "$bin/identify" --batch "$logs" --jobs 2 --out "$out/batch_jobs2.jsonl"
run python_loop "$python" -c "$python_loop" "$logs" "$out/python_loop.jsonl"
run dask_workers1 "$python" -m slideid.dask --batch "$logs" --local-workers 1 \
  --out "$out/dask_workers1.jsonl"
run dask_workers2 "$python" -m slideid.dask --batch "$logs" --local-workers 2 \
  --out "$out/dask_workers2.jsonl"
run batch_jobs2_quarter "$bin/identify" --batch "$part" --jobs 2 \
  --out "$out/batch_jobs2_quarter.jsonl"
run dask_workers2_quarter "$python" -m slideid.dask --batch "$part" --local-workers 2 \
  --out "$out/dask_workers2_quarter.jsonl"
load_after="$(cut -d' ' -f1-3 /proc/loadavg)"
seconds=$(($(date +%s) - started))

# ---- the report ---------------------------------------------------------------------------
generated="$work/generated.md"
"$python" - "$out" "$count" "$quarter" "$rows_total" "$rows_part" > "$work/tables.md" <<'EOF'
import json, os, sys
import slideid

out, count, quarter, rows_total, rows_part = sys.argv[1], *map(int, sys.argv[2:])
RUNS = [  # name, what, processes, logs, rows
    ("batch_jobs1", "`identify --batch --jobs 1` (baseline)", "1", count, rows_total),
    ("batch_jobs2", "`identify --batch --jobs 2`", "1 (2 threads)", count, rows_total),
    ("python_loop", "`slideid.identify_file` in a Python loop", "1", count, rows_total),
    ("dask_workers1", "`python3 -m slideid.dask --local-workers 1`", "1 + 1 worker", count,
     rows_total),
    ("dask_workers2", "`python3 -m slideid.dask --local-workers 2`", "1 + 2 workers", count,
     rows_total),
    ("batch_jobs2_quarter", "`identify --batch --jobs 2`", "1 (2 threads)", quarter, rows_part),
    ("dask_workers2_quarter", "`python3 -m slideid.dask --local-workers 2`", "1 + 2 workers",
     quarter, rows_part),
]
measured = {name: json.load(open(f"{out}/{name}.json")) for name, *_ in RUNS}


def comparable(entry):
    """What every run must agree on: all but the run times, the error's type (identify's
    lines have none) and the path (the quarter's logs are links in another directory)."""
    entry = {k: v for k, v in entry.items() if k not in ("file", "seconds", "error_type")}
    if "result" in entry:
        entry["result"] = {k: v for k, v in entry["result"].items() if k != "seconds"}
    if "error" in entry:
        entry["error"] = entry["error"].split(": ", 1)[1]  # without the path
    return entry


results = {}
for name, *_ in RUNS:
    results[name] = {os.path.basename(e["file"]): comparable(e)
                     for e in slideid.read_results(f"{out}/{name}.jsonl")}
base = results["batch_jobs1"]
failed = sum(not e["ok"] for e in base.values())
mb = lambda x: "-" if x is None else f"{x:.0f}"
print(f"| run | processes | logs | wall [s] | logs/s | rows/s | speed-up | peak RSS, main [MB] "
      f"| peak RSS, largest worker [MB] | same results as the baseline |")
print("|---|---|---:|---:|---:|---:|---:|---:|---:|---|")
base_rate = count / measured["batch_jobs1"]["wall_s"]
for name, what, processes, logs, rows in RUNS:
    m = measured[name]
    rate = logs / m["wall_s"]
    got = results[name]
    same = sum(got.get(f) == base[f] for f in got)
    agree = f"{same} of {logs}" + ("" if len(got) == logs else f" ({len(got)} lines)")
    print(f"| {what} | {processes} | {logs} | {m['wall_s']:.1f} | {rate:.0f} | "
          f"{rows / m['wall_s']:.0f} | {rate / base_rate:.2f}x | {mb(m['main_peak_mb'])} | "
          f"{mb(m['worker_peak_mb'])} | {agree} |")
print()
reasons = sorted({e["error"].split(":")[0] for e in base.values() if not e["ok"]})
print(f"{failed} of the {count} logs fail (their lines say why: {'; '.join(reasons) or '-'}); "
      "they count in the rates. The speed-up is the rate in logs per second against the "
      "baseline's; rows per second count every row of every log. Wall times include starting "
      "the process, and for Dask importing it and starting the cluster. \"Same results\": "
      "logs whose line equals the baseline's but for run times.")
EOF

{
  echo "Measured $(date -u +%Y-%m-%d) at commit $commit, in $seconds s in all."
  echo "Machine: $machine (nproc; CPU and memory from /proc)."
  echo "Load average (1, 5, 15 min): $load_before before the runs, $load_after after. A load"
  echo "above about 0.5 before the runs means that other work shared the cores: wall times and"
  echo "speed-ups then understate what the machine does alone."
  echo
  echo "Logs: $count made by \`make-dataset ${dataset_args[*]}\` ($made): $rows_min to $rows_max rows"
  echo "(median $rows_median), $rows_total rows in all. The last two rows of the table fit the"
  echo "first $quarter of them, to compare the peak memory."
  echo
  cat "$work/tables.md"
} > "$generated"

if ((quick)); then
  mkdir -p "$build_dir/scale-quick"
  cp "$generated" "$build_dir/scale-quick/scale-out_generated.md"
  echo "scale_benchmark: wrote $build_dir/scale-quick/scale-out_generated.md ($seconds s)"
else
  splice docs/scale-out.md "$generated"
  echo "scale_benchmark: wrote docs/scale-out.md ($seconds s)"
fi
cat "$generated"
