#!/usr/bin/env bash
# The tripod part of docs/real-data.md's generated section, for scripts/real_data.sh:
# imports each tripod log of ../shared/data/real-pushes/zhou_icra2016_tripod/ to
# wrench-twist pairs (import-log --format zhou-tripod, assumed to write OUT/<stem>.csv),
# fits a, b, c per configuration (identify --method quasi-static) and prints markdown on
# stdout. A file that fails to import or fit is listed as such; the others go on.
# Nothing here is tuned to the data: the importer and the fit run with their defaults.
# Variables: BIN (built tools), DATA (../shared/data/real-pushes), WORK (scratch directory;
# the data are read in place, never copied into the repository).
set -euo pipefail
BIN=${BIN:-build/bin}
DATA=${DATA:-../shared/data/real-pushes}
WORK=${WORK:-build/real_data}
tripod="$DATA/zhou_icra2016_tripod"
mkdir -p "$WORK/tripod"
for dir in "$tripod"/*/; do
  cfg=$(basename "$dir")
  for f in "$dir"*.txt; do
    "$BIN/import-log" --format zhou-tripod "$f" --out "$WORK/tripod/$cfg" \
      2>> "$WORK/tripod/import.log" || echo "import-log failed on $f" >> "$WORK/tripod/import.log"
    stem=$(basename "$f" .txt)
    "$BIN/identify" --method quasi-static --log "$WORK/tripod/$cfg/$stem.csv" --json \
      > "$WORK/tripod/$cfg/$stem.fit.json" 2>> "$WORK/tripod/identify.log" || true
  done
done
/usr/bin/python3 - "$WORK/tripod" <<'PY'
import csv, glob, json, math, os, sys
root = sys.argv[1]
def meta_and_rows(path):
    meta, lines = {}, []
    for line in open(path):
        if line.startswith('#'):
            if '=' in line:
                k, v = line[1:].split('=', 1)
                meta[k.strip()] = v.strip()
        elif line.strip():
            lines.append(line)
    return meta, list(csv.DictReader(lines))
def rng(xs, fmt):
    return (fmt % min(xs)) + ' to ' + (fmt % max(xs)) if xs else '-'
def est(fit, key, scale=1.0, fmt='%.3f'):
    if not fit:
        return 'no fit (see identify.log)'
    p = fit.get(key, {})
    if not p or p.get('value') is None:
        held = p.get('held_at')
        held_text = '' if held is None else ' (held at ' + fmt % (held * scale) + ')'
        return 'not identifiable' + held_text
    lo, hi = p['ci95']
    note = '' if fit.get('converged', True) else ' (fit not converged)'
    value, lo, hi = (fmt % (x * scale) for x in (p['value'], lo, hi))
    return value + ' [' + lo + ', ' + hi + ']' + note
rows = []
for csv_path in sorted(glob.glob(os.path.join(root, '*', '*.csv'))):
    cfg = os.path.basename(os.path.dirname(csv_path))
    meta, data = meta_and_rows(csv_path)
    if not data or 'fx' not in data[0] or 'wz' not in data[0]:
        continue  # an import report, not pairs
    fit_path = csv_path[:-4] + '.fit.json'
    try:
        fit = json.load(open(fit_path))
    except (OSError, ValueError):
        fit = {}
    f = [math.hypot(float(r['fx']), float(r['fy'])) for r in data]
    m = [abs(float(r['mz'])) for r in data]
    d = [1000 * math.hypot(float(r['dx']), float(r['dy'])) for r in data if r['dx']]
    th = [abs(float(r['dtheta'])) for r in data if r['dtheta']]
    rows.append(dict(cfg=cfg, surface=meta.get('surface', '?').split(' ')[0],
                     pushes=meta.get('pushes_in_source', '?'), used=len(data),
                     f=rng(f, '%.1f'), m=rng(m, '%.3f'), d=rng(d, '%.1f'), th=rng(th, '%.3f'),
                     a=est(fit, 'e_t_mu'), b=est(fit, 'e_o_over_e_t'),
                     c=est(fit, 'e_r_over_e_t', 1000, '%.1f'),
                     c_value=(fit.get('e_r_over_e_t') or {}).get('value'),
                     rms=meta.get('support_spread_rms'),
                     wmean=meta.get('support_spread_weighted')))
print('### Tripod pushes (Zhou et al., ICRA 2016): pairs\n')
print('Mass 1.518 kg and inertia 1.9e-3 kg m^2 (the data README; the inertia is its '
      'thin-plate estimate).\n')
print('| configuration | surface | pushes | pairs used | mean \\|f\\| [N] | \\|m_z\\| [N m] '
      '| displacement [mm] | \\|rotation\\| [rad] |')
print('|---|---|---|---|---|---|---|---|')
for r in rows:
    print('| %(cfg)s | %(surface)s | %(pushes)s | %(used)d | %(f)s | %(m)s | %(d)s | %(th)s |' % r)
print('\n### Quasi-static a, b, c per configuration (95% intervals)\n')
print('Pull-test mu from the data README: 0.282 (hardboard), 0.336 (plywood). The `patch` '
      'folders are for reference only (pressure distribution unknown).\n')
print('| configuration | surface | a = e_t mu | b = e_o / e_t | c = e_r / e_t [mm] |')
print('|---|---|---|---|---|')
for r in rows:
    print('| %(cfg)s | %(surface)s | %(a)s | %(b)s | %(c)s |' % r)
print('\n### c against the spread of the supports\n')
print('Spread from the folder name (support positions in the block frame, CM at (50, 50) '
      'mm): the RMS distance of the three supports from the CM, and the weight-share mean '
      'distance sum w_i r_i (the ratio of the largest friction moment to the largest friction '
      'force for point supports under isotropic Coulomb friction).\n')
print('| configuration | surface | RMS spread [mm] | sum w_i r_i [mm] | c [mm] '
      '| c / sum w_i r_i |')
print('|---|---|---|---|---|---|')
for r in sorted((r for r in rows if r['rms']), key=lambda r: (r['surface'], float(r['rms']))):
    ratio = '%.2f' % (r['c_value'] / float(r['wmean'])) if r['c_value'] else '-'
    print('| %s | %s | %.1f | %.1f | %s | %s |' % (r['cfg'], r['surface'], 1000 * float(r['rms']),
          1000 * float(r['wmean']), r['c'], ratio))
PY
