#!/usr/bin/env bash
# Runs the importers and identify on the real push logs of ../shared/data/real-pushes (next
# to the checkout; README there) and rewrites the generated section of docs/real-data.md.
# The third-party files are read in place, never copied into the repository; the imported
# logs, reports and fits go to $WORK.
# Usage: bash scripts/real_data.sh
# Environment: SLIDEID_REAL_DATA (the real-pushes folder), SLIDEID_BIN_DIR (build/bin),
#              WORK (build/real-data).
# Exits 0 with a message when the data is not there. Each section is one function: a new
# data set is one more function and one more entry in `sections`.
set -euo pipefail
data=${SLIDEID_REAL_DATA:-"$(dirname "$0")/../../shared/data/real-pushes"}
if [ ! -d "$data" ]; then
  echo "real_data: no real data at $data (set SLIDEID_REAL_DATA); nothing to do"
  exit 0
fi
data=$(cd "$data" && pwd)
cd "$(dirname "$0")/.."
bin=${SLIDEID_BIN_DIR:-build/bin}
work=${WORK:-build/real-data}
for tool in import-log identify validate; do
  [ -x "$bin/$tool" ] || { echo "real_data: no $bin/$tool: run scripts/build.sh"; exit 1; }
done
rm -rf "$work"
mkdir -p "$work"

# import-log exits 1 when it rejected a file (the others are written): that is a result.
import() {
  local name=$1
  shift
  local code=0
  "$bin/import-log" "$@" --out "$work/$name" > "$work/$name.import.txt" 2>&1 || code=$?
  if [ "$code" -gt 1 ]; then
    echo "real_data: import-log failed on $name (exit $code):"
    cat "$work/$name.import.txt"
    exit 1
  fi
  echo "real_data: $name: $(tail -n 2 "$work/$name.import.txt" | head -n 1)"
}

# identify --json on every imported log of a section; the exit code goes beside the fit.
identify_all() {
  local name=$1 log
  [ -d "$work/$name" ] || return 0
  for log in "$work/$name"/*.csv; do
    [ "$(basename "$log")" = import_report.csv ] && continue
    local code=0
    "$bin/identify" --log "$log" --json > "${log%.csv}.fit.json" 2> "${log%.csv}.fit.err" || code=$?
    echo "$code" > "${log%.csv}.fit.exit"
  done
}

# One section per data set: import, then identify every imported log.
mit_rect1() {
  local files=("$data"/mit_push_rect1_plywood_v100/*/*.json)
  ((${#files[@]})) || { echo "real_data: mit_rect1: no files; skipped"; return 0; }
  import mit_rect1 --format mit-push --objects datasets/mit_objects.csv \
    --h5-copies "$work/h5_copies/mit_rect1" "${files[@]}"
  identify_all mit_rect1
}

mit_hex() {
  local files=("$data"/mit_push_hex_plywood_v150/*.json)
  ((${#files[@]})) || { echo "real_data: mit_hex: no files; skipped"; return 0; }
  import mit_hex --format mit-push --objects datasets/mit_objects.csv \
    --h5-copies "$work/h5_copies/mit_hex" "${files[@]}"
  identify_all mit_hex
}

# The rect1 and hex pushes again through the HDF5 path: the .h5 copies our writer made of
# the JSON files as they were imported (--h5-copies), imported with --format mit-push-h5,
# must give the same logs, byte for byte but the `# source` line, and the same verdicts.
# Fails the script when they do not.
mit_h5() {
  local name json h5 logs same differ
  {
    echo "Each JSON file of rect1 and hex, as read, written to \`.h5\` by the project's own writer"
    echo "(\`io/mit_push_h5.h\`, \`import-log --h5-copies\`) and imported again with"
    echo "\`--format mit-push-h5\`:"
    echo
    echo "| pushes | .h5 files | accepted (JSON) | accepted (HDF5) | logs identical but the source line |"
    echo "|---|---|---|---|---|"
  } > "$work/mit_h5.md"
  for name in mit_rect1 mit_hex; do
    [ -d "$work/h5_copies/$name" ] || continue
    local copies=("$work/h5_copies/$name"/*.h5)
    import "${name}_h5" --format mit-push-h5 --objects datasets/mit_objects.csv "${copies[@]}"
    logs=0 same=0 differ=0
    for json in "$work/$name"/*.csv; do
      [ "$(basename "$json")" = import_report.csv ] && continue
      logs=$((logs + 1))
      h5="$work/${name}_h5/$(basename "$json")"
      if [ -f "$h5" ] && cmp -s <(grep -v '^# source = ' "$json") <(grep -v '^# source = ' "$h5"); then
        same=$((same + 1))
      else
        differ=$((differ + 1))
        echo "real_data: mit_h5: $name: $(basename "$json") differs through the HDF5 path"
      fi
    done
    local h5_logs
    h5_logs=$(find "$work/${name}_h5" -name '*.csv' ! -name import_report.csv | wc -l)
    echo "| ${name#mit_} | ${#copies[@]} | $logs | $h5_logs | $same of $logs |" >> "$work/mit_h5.md"
    echo "real_data: mit_h5: $name: $same of $logs logs identical through the HDF5 path"
    if [ "$differ" -gt 0 ] || [ "$h5_logs" -ne "$logs" ]; then
      echo "real_data: mit_h5: the HDF5 path gave other logs than the JSON path"
      exit 1
    fi
  done
}

# The rect1 pushes pooled: one estimate from all, as they are and with the sensor nuisances
# (each log's force offset; one delay for all), and the forest plot of the plain fit.
mit_rect1_pooled() {
  [ -d "$work/mit_rect1" ] || { echo "real_data: mit_rect1_pooled: no imported logs; skipped"; return 0; }
  local variant args code
  for variant in plain bias delay bias_delay; do
    case $variant in
      plain) args=() ;;
      bias) args=(--fit-force-bias) ;;
      delay) args=(--fit-delay shared) ;;
      bias_delay) args=(--fit-force-bias --fit-delay shared) ;;
    esac
    code=0
    "$bin/identify" --logs "$work/mit_rect1" --skip-bad --json "${args[@]}" \
      > "$work/mit_rect1.pooled.$variant.json" 2> "$work/mit_rect1.pooled.$variant.err" || code=$?
    echo "$code" > "$work/mit_rect1.pooled.$variant.exit"
    echo "real_data: mit_rect1_pooled: $variant: exit $code"
  done
  if [ -x "$bin/plot-fit" ] && [ -s "$work/mit_rect1.pooled.plain.json" ]; then
    "$bin/plot-fit" "$work/mit_rect1.pooled.plain.json" --out docs/real-data-rect1-pooled.png \
      --title "MIT rect1 on plywood, 100 mm/s: every accepted push, pooled" > /dev/null \
      || echo "real_data: mit_rect1_pooled: plot-fit failed (gnuplot missing?); no picture"
  fi
}

# Cross-validation over the rect1 pushes: leave-one-out, by the pusher's path and by the
# logged force, with the pushes' own fits and the textbook friction beside (validate).
mit_rect1_validate() {
  [ -d "$work/mit_rect1" ] || { echo "real_data: mit_rect1_validate: no imported logs; skipped"; return 0; }
  local drive code
  for drive in pusher force; do
    code=0
    "$bin/validate" --logs "$work/mit_rect1" --skip-bad --drive "$drive" --threads 2 \
      --json "$work/mit_rect1.validate.$drive.json" --csv "$work/mit_rect1.validate.$drive.csv" \
      --plot "$work/mit_rect1.validate.$drive.png" \
      > "$work/mit_rect1.validate.$drive.txt" 2>&1 || code=$?
    [ "$drive" != pusher ] || [ ! -s "$work/mit_rect1.validate.$drive.png" ] \
      || cp "$work/mit_rect1.validate.$drive.png" docs/real-data-rect1-validate.png
    echo "real_data: mit_rect1_validate: $drive: exit $code"
  done
  # MuJoCo with the same folds' friction and the same tip path (a benchmark program).
  if [ -x "$bin/mujoco_baseline" ] && [ -s "$work/mit_rect1.validate.pusher.json" ]; then
    code=0
    "$bin/mujoco_baseline" --validation "$work/mit_rect1.validate.pusher.json" \
      --json "$work/mit_rect1.validate.mujoco.json" > "$work/mit_rect1.validate.mujoco.txt" 2>&1 \
      || code=$?
    echo "real_data: mit_rect1_validate: mujoco: exit $code"
  else
    echo "real_data: mit_rect1_validate: no $bin/mujoco_baseline (libmujoco-dev); no MuJoCo row"
  fi
}

# The tripod logs: one wrench-twist file per configuration, fitted by the quasi-static
# method (scripts/real_data_tripod.sh prints the section's markdown).
zhou_tripod() {
  [ -d "$data/zhou_icra2016_tripod" ] || { echo "real_data: zhou_tripod: no files; skipped"; return 0; }
  BIN=$bin DATA=$data WORK=$work bash scripts/real_data_tripod.sh > "$work/zhou_tripod.md"
  echo "real_data: zhou_tripod: $(grep -c '^| ' "$work/zhou_tripod.md" || true) table rows"
}

shopt -s nullglob
sections=(mit_rect1 mit_rect1_pooled mit_rect1_validate mit_hex mit_h5 zhou_tripod)
for section in "${sections[@]}"; do "$section"; done
/usr/bin/python3 scripts/real_data_report.py --work "$work" --doc docs/real-data.md \
  --sections "${sections[@]}"
echo "real_data: wrote the generated section of docs/real-data.md"
