#!/usr/bin/env bash
# ctest `browser`: the explorer page of a small synthetic study, then of a small real study, in
# headless Chromium.
# Usage: browser_test.sh LAMINA SRC_DIR BUILD_DIR
set -euo pipefail
lamina=$1 src=$2 build=$3
study="$build/report-fixture"
rm -rf "$study"
python3 "$src/tests/report/make_fixture.py" "$study"
"$lamina" explorer "$study"
if [ ! -d "$src/node_modules/playwright-core" ]; then
    echo "FAIL playwright-core is not installed: run \`make deps\` (npm ci)"; exit 1
fi
node "$src/tests/report/browser_test.js" "$study" "$build/screenshots"

# And the page of a small real study, end to end: lamina study writes it, Chromium opens it. The
# 2019 reference (--physics bpb19), whose single-scattering microsurfaces lose energy that the
# albedo view must draw.
real="$build/report-real-study"
rm -rf "$real"
"$lamina" study --only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --theta-i 30 --particles 2e4 \
    --grid 18x18 --physics bpb19 --no-figures --out "$real" >/dev/null
node "$src/tests/report/browser_smoke.js" "$real" "$build/screenshots/real-study.png"

# And the same two configurations with the polarized reference (the default, exact physics) and
# its Stokes vectors stored: the polarization view draws the degree and angle of polarization of
# reference_stokes.lza.
polarized="$build/report-polarized-study"
rm -rf "$polarized"
"$lamina" study --only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --theta-i 60 --particles 2e4 \
    --grid 18x18 --models ww-prime --reference-stokes on --no-figures --out "$polarized" >/dev/null
node "$src/tests/report/browser_polarization.js" "$polarized" "$build/screenshots/polarized-study.png"

# And a study of one brushed configuration (anisotropic: unfolded tables, lit from φi = 0°, 45°
# and 90°): the page offers φi and draws each incidence on the full hemisphere, its polarization
# too.
brushed="$build/report-brushed-study"
rm -rf "$brushed"
"$lamina" study --preset standard --only 'brushed-al-a0.05x.2-a1.05x.3-t90' --theta-i 0,45 \
    --particles 2e4 --grid 18x18 --models openpbr,bel-prime --reference-stokes on --no-figures \
    --out "$brushed" >/dev/null
node "$src/tests/report/browser_unfolded.js" "$brushed" "$build/screenshots/brushed-study.png"

# And a study of one iridescent configuration (spectral: the reference traced over 360–830 nm,
# its tables linear sRGB under D65): the colour view shows the reference's colours as the tables
# give them.
spectral="$build/report-spectral-study"
rm -rf "$spectral"
"$lamina" study --preset standard --only 'irid-ti-oxide-a0.05-a1.05' --theta-i 0,45 \
    --particles 2e4 --grid 18x18 --models openpbr --no-figures --out "$spectral" >/dev/null
node "$src/tests/report/browser_spectral.js" "$spectral" "$build/screenshots/spectral-colour.png"
