#!/usr/bin/env bash
# ctest `figures`: `lamina figures` on a small synthetic study writes every figure, and its errors
# name what is wrong. Usage: figures_test.sh LAMINA SRC_DIR BUILD_DIR
set -uo pipefail
lamina=$1 src=$2 build=$3
study="$build/figures-fixture"
fails=0 passes=0
ok() { if "$@"; then passes=$((passes + 1)); else echo "FAIL: $*"; fails=$((fails + 1)); fi; }
rm -rf "$study"
python3 "$src/tests/report/make_fixture.py" "$study" || exit 1

"$lamina" figures "$study" --formats png,svg --only 'plastic-P1*,slab-*'
ok test $? -eq 0
for f in slices/plastic-P1-a0.05-R slices/slab-a0.1-a1.3-clear-R slices/slab-a0.1-a1.3-clear-T \
         colour/plastic-P1-a0.05-R colour/slab-a0.1-a1.3-clear-R colour/slab-a0.1-a1.3-clear-T \
         error-matrix-R error-matrix-T albedo-plastic albedo-slab albedo-metallic-paint; do
    ok test -s "$study/figures/$f.png"
    ok test -s "$study/figures/$f.svg"
done
ok test ! -e "$study/figures/slices/plastic-P2-a0.3-R.png"   # --only

# The colour strips of the coloured plastic: at each incidence, the reference's brightest bin on the
# incident plane (the mirror side, φ bin n_phi − 1) and its darkest, as computed here from
# tables.npy (whole stops below the reference's largest channel on the plane, negative channels
# as 0, the sRGB curve of IEC 61966-2-1), are colours of the PNG, to one 8-bit step.
"$lamina" figures "$study" --formats png --only 'plastic-P2*' >/dev/null
ok test -s "$study/figures/colour/plastic-P2-a0.3-R.png"
colour_check() {
    "${LAMINA_PYTHON:-/usr/bin/python3}" - "$study" <<'PY'
import math, sys
import numpy as np
import matplotlib.image as mpimg
root = sys.argv[1]
tab = np.load(f"{root}/configs/plastic-P2-a0.3/tables.npy").astype(np.float64)
png = (mpimg.imread(f"{root}/figures/colour/plastic-P2-a0.3-R.png")[..., :3] * 255).round()
colours = np.unique(png.reshape(-1, 3), axis=0)
enc = lambda v: 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
found = 0
for i in range(tab.shape[1]):
    plane = np.concatenate([tab[0, i, 0, ::-1, 0, :], tab[0, i, 0, :, -1, :]])  # [2T, 3]
    k = 2.0 ** -math.ceil(math.log2(plane.max()))
    for x in (plane.max(axis=1).argmax(), plane.max(axis=1).argmin()):
        want = np.array([round(255 * enc(max(0.0, v * k))) for v in plane[x]])
        near = np.abs(colours - want).max(axis=1).min()
        print(f"theta_i index {i}, plane bin {x}: sRGB {want}, nearest colour in the figure {near} steps away")
        found += near <= 1
sys.exit(0 if found == 2 * tab.shape[1] else 1)
PY
}
ok colour_check

# Errors: each names the file or the option, and exits 1.
out=$("$lamina" figures "$build/no-such-study" 2>&1); rc=$?
ok test $rc -eq 1
ok grep -q "no-such-study/study.json: not found" <<<"$out"
out=$("$lamina" figures "$study" --formats gif 2>&1); rc=$?
ok test $rc -eq 1
ok grep -q "'gif' is not a figure format" <<<"$out"
out=$("$lamina" figures "$study" --python "$build/no-such-python" 2>&1); rc=$?
ok test $rc -eq 1
ok grep -q "cannot run" <<<"$out"
out=$("$lamina" explorer "$build/no-such-study" 2>&1); rc=$?
ok test $rc -eq 1
ok grep -q "no-such-study/study.json: not found" <<<"$out"
if [ "$(id -u)" -ne 0 ]; then  # root writes anywhere: the check means nothing there
    chmod a-w "$study"
    out=$("$lamina" explorer "$study" 2>&1); rc=$?
    chmod u+w "$study"
    ok test $rc -eq 1
fi
# A damaged study folder (a hand-edited study.json) is one named error, not a traceback.
damaged="$build/figures-damaged"
rm -rf "$damaged"
cp -r "$study" "$damaged"
echo '{' >"$damaged/study.json"
out=$("$lamina" figures "$damaged" 2>&1); rc=$?
ok test $rc -eq 1
ok grep -q "cannot draw the figures from this study folder (JSONDecodeError" <<<"$out"
ok test "$(grep -c Traceback <<<"$out")" -eq 0
# A study folder without metrics.csv: the page is written, and the missing file named.
nometrics="$build/explorer-no-metrics"
rm -rf "$nometrics"
cp -r "$study" "$nometrics"
rm "$nometrics/metrics.csv"
out=$("$lamina" explorer "$nometrics" 2>&1); rc=$?
ok test $rc -eq 0
ok grep -q "metrics.csv is missing: the page's leaderboard is empty" <<<"$out"
# A study run with --tables none keeps no tables: the page says so, by the option.
notables="$build/explorer-no-tables"
rm -rf "$notables"
"$lamina" compare "$src/examples/plastic.json" --particles 2e3 --grid 9x9 --theta-i 30 --models ww09 \
    --tables none --no-figures --out "$notables" >/dev/null
out=$("$lamina" explorer "$notables" 2>&1); rc=$?
ok test $rc -eq 1
ok grep -q "config.json: tables: none: the study was run with --tables none" <<<"$out"
# An unfolded configuration (brushed: anisotropic, lit from φi = 0°, 45°, 90°) of a tiny real
# study: its slices (the plane φ = φi of each azimuth), albedo panel and error-matrix row are drawn.
brushed="$build/figures-brushed"
rm -rf "$brushed"
"$lamina" study --preset standard --only 'brushed-gold-a0.001-a1.05x.3-t30' --theta-i 0,45 \
    --particles 2e4 --grid 18x18 --models openpbr,bel-prime --no-figures --out "$brushed" >/dev/null
ok test $? -eq 0
out=$("$lamina" figures "$brushed" --formats png 2>&1)
ok test $? -eq 0
for f in slices/brushed-gold-a0.001-a1.05x.3-t30-R colour/brushed-gold-a0.001-a1.05x.3-t30-R \
         error-matrix-R albedo-brushed; do
    ok test -s "$brushed/figures/$f.png"
done
ok grep -q "4 drawn" <<<"$out"

# A slab that transmits nothing (τa = 100): its transmission's misplaced energies are 1e-49 and 0,
# which the error matrix's log scale could not take (matplotlib's float32 image rounds them to 0),
# and its slices have no positive value; every figure is still drawn.
opaque="$build/figures-opaque"
rm -rf "$opaque"
cat >"$build/figures-opaque.json" <<'JSON'
{"configurations": [{"id": "opaque-slab", "stack": {"layers": [
  {"interface": {"type": "dielectric", "eta": 1, "alpha": 0.3}, "medium": {"tau_a": 100}},
  {"interface": {"type": "dielectric", "eta": 1, "alpha": 0.3}}]}}]}
JSON
out=$("$lamina" study --configs "$build/figures-opaque.json" --models bel-prime,tm2 --theta-i 30 \
      --particles 2e4 --grid 6x6 --threads 1 --out "$opaque" 2>&1)
ok test $? -eq 0
ok test -s "$opaque/figures/error-matrix-T.png"
if grep -q "figures not written\|Warning" <<<"$out"; then
    echo "FAIL: the opaque slab's figures: $out"; fails=$((fails + 1))
fi

# lamina stopped while it draws (SIGTERM, as a supervisor or `timeout` sends it to lamina alone):
# the figure script and its workers stop with it and leave no temporary file.
"$lamina" figures "$study" --force &
pid=$!
for _ in $(seq 100); do  # until the first figure is on disk (or lamina is done)
    [ -n "$(find "$study/figures" -newer "$build/figures-opaque.json" -name '*.png' 2>/dev/null)" ] &&
        break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.05
done
kill -TERM "$pid" 2>/dev/null
wait "$pid"
sleep 1
ok test -z "$(ps -eo args | grep -F -- "--script-id" | grep -F -- "$study" || true)"
ok test -z "$(find "$study/figures" -name '*.tmp-*')"

echo "$passes passed, $fails failed"
test "$fails" -eq 0
