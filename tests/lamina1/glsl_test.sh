#!/usr/bin/env bash
# lamina-1's GLSL form against the C++ in headless Chromium (glsl_test.js): a plastic, a coated
# rough gold with an absorbing coat, a metallic paint, a slab's reflection and two of the model's
# other choices; 300 direction pairs each, fixed seed; and a stack the form does not cover refused.
# usage: glsl_test.sh LAMINA REPO_ROOT
set -u
lamina=$1 root=$2
. "$root/tests/support/script_lib.sh"
if [ ! -d "$root/node_modules/playwright-core" ]; then
    echo "FAIL playwright-core is not installed: run \`make deps\` (npm ci)"; exit 1
fi

cases=()
add_case() {  # NAME STACK [OPTION...]
    local name=$1 stack=$2; shift 2
    local opts=()
    for o in "$@"; do opts+=(--option "$o"); done
    if ! "$lamina" export --lamina1-gpu "$tmp/$name.state" --stack "$stack" "${opts[@]}" \
        > "$tmp/$name.log" 2>&1; then fail "export $name: $(cat "$tmp/$name.log")"; return; fi
    python3 - "$tmp/$name.dirs.csv" "$name" <<'PY'
import random, sys
rng = random.Random(sys.argv[2])
with open(sys.argv[1], "w") as f:
    f.write("theta_i,theta_o,phi_o,side\n")
    for _ in range(300):
        f.write(f"{rng.uniform(0, 85):.6f},{rng.uniform(0, 85):.6f},{rng.uniform(0, 360):.6f},R\n")
PY
    if ! "$lamina" eval --model lamina-1 --stack "$stack" "${opts[@]}" \
        --directions "$tmp/$name.dirs.csv" --out "$tmp/$name.ref.csv" > "$tmp/$name.log" 2>&1; then
        fail "eval $name: $(cat "$tmp/$name.log")"; return; fi
    cases+=("$name")
}
add_case plastic "$root/examples/plastic.json"
add_case frosted-gold "$root/examples/frosted-gold.json"
add_case metallic-paint "$root/examples/metallic-paint.json"
add_case slab "$root/examples/slab.json"
add_case gold-ggx-lobe "$root/examples/frosted-gold.json" first-order-lobe=ggx spread=normal
add_case plastic-fresnel "$root/examples/plastic.json" coat-transmittance=fresnel

if node "$root/tests/lamina1/glsl_test.js" "$root" "$tmp" "${cases[@]}"; then ok; else fail "GLSL"; fi

# A scattering coat is outside the GLSL form: refused with the reason.
if out=$("$lamina" export --lamina1-gpu "$tmp/milky.state" --stack "$root/examples/milky-coat.json" 2>&1); then
    fail "milky-coat exported: $out"
elif [[ "$out" == *"scattering medium"* ]]; then ok; else fail "milky-coat: $out"; fi
finish
