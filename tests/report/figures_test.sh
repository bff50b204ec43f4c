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
         error-matrix-R error-matrix-T albedo-plastic albedo-slab albedo-metallic-paint; do
    ok test -s "$study/figures/$f.png"
    ok test -s "$study/figures/$f.svg"
done
ok test ! -e "$study/figures/slices/plastic-P2-a0.3-R.png"   # --only

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
# An unfolded configuration (brushed: anisotropic, lit from φi = 0°, 45°, 90°) of a tiny real
# study: its slices (the plane φ = φi of each azimuth), albedo panel and error-matrix row are drawn.
brushed="$build/figures-brushed"
rm -rf "$brushed"
"$lamina" study --preset standard --only 'brushed-gold-a0.001-a1.05x.3-t30' --theta-i 0,45 \
    --particles 2e4 --grid 18x18 --models openpbr,bel-prime --no-figures --out "$brushed" >/dev/null
ok test $? -eq 0
out=$("$lamina" figures "$brushed" --formats png 2>&1)
ok test $? -eq 0
for f in slices/brushed-gold-a0.001-a1.05x.3-t30-R error-matrix-R albedo-brushed; do
    ok test -s "$brushed/figures/$f.png"
done
ok grep -q "3 drawn" <<<"$out"
echo "$passes passed, $fails failed"
test "$fails" -eq 0
