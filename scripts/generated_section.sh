# Sourced by the scripts that regenerate part of a page (benchmarks.sh, coverage.sh,
# scale_benchmark.sh, scene_suite.sh): the part between a page's "generated" markers, the
# commit a measurement was taken at, the --quick option of a benchmark script, and the common
# start of a suite page's script.

# Replaces what lies between the generated markers of page $1 with the file $2; a page
# without markers is created with them, under a title from its name.
splice() {
  local doc="$1" part="$2"
  if ! grep -q '<!-- generated:begin' "$doc" 2>/dev/null; then
    printf '%s\n\n<!-- generated:begin (scripts/%s) -->\n<!-- generated:end -->\n' \
      "# $(basename "$doc" .md)" "$(basename "$0")" > "$doc"
  fi
  awk -v part="$part" '
    /<!-- generated:begin/ { print; while ((getline line < part) > 0) print line; skip = 1; next }
    /<!-- generated:end/ { skip = 0 }
    !skip' "$doc" > "$doc.tmp"
  mv "$doc.tmp" "$doc"
}

# The short hash of HEAD, and whether the tree had uncommitted changes.
commit_label() {
  local commit
  commit="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
  if [ -n "$(git status --porcelain 2>/dev/null)" ]; then commit="$commit + uncommitted changes"; fi
  echo "$commit"
}

# The option of a benchmark script (benchmarks.sh, scale_benchmark.sh): reads its one
# option, --quick, into $quick (1 or 0), and $BUILD_DIR (default build) into $build_dir. The
# script's arguments follow: quick_option "$@".
quick_option() {
  quick=0
  case "${1:-}" in
    --quick) quick=1 ;;
    "") ;;
    *) echo "usage: bash scripts/$(basename "$0") [--quick]" >&2; exit 2 ;;
  esac
  build_dir="${BUILD_DIR:-build}"
}

# The common start of a suite page's script (coverage.sh, scene_suite.sh): reads its one
# option, --logs N (default $1), into $logs; builds target $2 (Release) in $BUILD_DIR
# (default build), kept in $build_dir; makes a work directory $work, removed on exit; notes
# $commit and $start (SECONDS) for the page's "Measured" line. The script's other arguments
# follow: suite_setup 200 coverage "$@".
suite_setup() {
  local default_logs="$1" target="$2"
  shift 2
  logs="$default_logs"
  case "${1:-}" in
    --logs) logs="${2:?--logs needs a count}" ;;
    "") ;;
    *) echo "usage: bash scripts/$(basename "$0") [--logs N]" >&2; exit 2 ;;
  esac
  build_dir="${BUILD_DIR:-build}"
  cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build_dir" -j"$(nproc)" --target "$target" >/dev/null
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
  commit="$(commit_label)"
  start=$SECONDS
}
