# Sourced by the scripts that regenerate part of a page (benchmarks.sh, coverage.sh,
# scale_benchmark.sh): the part between a page's "generated" markers, and the commit a
# measurement was taken at.

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
