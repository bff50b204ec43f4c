#!/usr/bin/env bash
# ctest `lamina_coat_glsl`: docs/lamina-coat/lamina_coat.glsl in headless Chromium (WebGL2) against
# `lamina eval --model lamina-coat` (the C++ model) at 128 direction pairs on eight stacks (two
# with smooth coats), to 1e-4 relative; lamina_coat_delta against the smooth limits' closed forms
# (glsl_test.js); and docs/lamina-coat/tables.png holds the integers of tables.csv.
# Usage: glsl_test.sh LAMINA SRC_DIR [PYTHON (with numpy and Pillow)]
set -euo pipefail
lamina=$1 src=$2 python=${3:-python3}
. "$src/tests/support/script_lib.sh"
if [ ! -d "$src/node_modules/playwright-core" ]; then
    echo "FAIL playwright-core is not installed: run \`make deps\` (npm ci)"; exit 1
fi

if "$python" -c "
import sys, numpy as np
from PIL import Image
png = np.array(Image.open(sys.argv[1]))
csv = np.loadtxt(sys.argv[2], delimiter=',', comments='#')
sys.exit(0 if png.shape == csv.shape and (png == csv).all() else 1)
" "$src/docs/lamina-coat/tables.png" "$src/docs/lamina-coat/tables.csv"; then ok; else fail "tables.png != tables.csv"; fi

# The GLSL's constants are the fit's (docs/lamina-coat/fit.csv); the C++ agrees with the GLSL below.
for pair in "k_g LC_GRAZING" "c_tau LC_TINT_PATH" "k_r LC_ROUGHENING"; do
    set -- $pair
    fitted=$(awk -F, -v k="$1" '$1 == k { print $2 + 0 }' "$src/docs/lamina-coat/fit.csv")
    shader=$(awk -v k="$2" '$1 == "const" && $3 == k { sub(";", "", $5); print $5 + 0 }' \
        "$src/docs/lamina-coat/lamina_coat.glsl")
    if [ -n "$fitted" ] && [ "$fitted" = "$shader" ]; then ok; else fail "$1: fit.csv $fitted, GLSL $shader"; fi
done

# Stacks: plastics (clear, tinted, rough), metals under smooth and rough coats, another index;
# a smooth-coated plastic, and gold with coat and base smooth under an absorbing coat.
stacks=(
  '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0.1},"medium":{"tau_a":[0.1,0,0.9]}},{"interface":{"type":"lambertian","albedo":[0.8,0.5,0.2]}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0.5}},{"interface":{"type":"lambertian","albedo":0.9}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0.05},"medium":{"tau_a":0.1}},{"interface":{"type":"conductor","eta":1.45,"k":[1.0,0.01,0.01],"alpha":0.3}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0.3}},{"interface":{"type":"conductor","eta":[0.143,0.374,1.442],"k":[3.983,2.385,1.603],"alpha":0.05}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.83,"alpha":0.2},"medium":{"tau_a":[0.3,0.05,0]}},{"interface":{"type":"lambertian","albedo":[0.3,0.6,0.9]}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.27,"alpha":0.4}},{"interface":{"type":"conductor","eta":[0.2,0.9,1.1],"k":[3.9,2.4,2.2],"alpha":0.12}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0},"medium":{"tau_a":[0.1,0,0.9]}},{"interface":{"type":"lambertian","albedo":0.8}}]}'
  '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0},"medium":{"tau_a":[0.3,0.1,0]}},{"interface":{"type":"conductor","eta":[0.143,0.374,1.442],"k":[3.983,2.385,1.603],"alpha":0}}]}'
)
python3 -c "
import random
random.seed(29)
print('theta_i,theta_o,phi_o,side')
for _ in range(16):
    print(f'{random.uniform(0, 85):.6f},{random.uniform(0, 85):.6f},{random.uniform(0, 360):.6f},R')
" > "$tmp/directions.csv"
for i in "${!stacks[@]}"; do
    echo "${stacks[$i]}" > "$tmp/stack$i.json"
    "$lamina" eval --model lamina-coat --stack "$tmp/stack$i.json" --directions "$tmp/directions.csv" \
        --out "$tmp/cpp$i.csv"
done
if node "$src/tests/models/lamina_coat/glsl_test.js" "$src" "$tmp" "${#stacks[@]}"; then ok; else fail "GLSL != C++"; fi
finish
