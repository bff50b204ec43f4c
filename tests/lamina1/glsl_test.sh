#!/usr/bin/env bash
# lamina-1's GLSL form against the C++ in headless Chromium (glsl_test.js): a plastic, a coated
# rough gold with an absorbing coat, a metallic paint, a slab's reflection (its later orders in
# bins and as the series; a clear, nearly smooth slab), two of the model's other choices and
# smooth coats (a plastic, a gold with coat and base smooth, with and without inter-reflection); 300 direction pairs each, fixed seed; lamina1_delta against the closed form of
# a smooth coat's specular reflection (glsl_test.js); and a stack the form does not cover refused.
# The sampler (not slabs) against the C++ one through the Python module, where it is built
# (BUILD_DIR/python, for the interpreter PYTHON): the pdf at those pairs and a draw from fixed
# uniforms at each.
# usage: glsl_test.sh LAMINA REPO_ROOT [BUILD_DIR PYTHON]
set -u
lamina=$1 root=$2 build=${3:-} python=${4:-python3}
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
    cp "$stack" "$tmp/$name.stack.json"
    echo "$@" > "$tmp/$name.options"
    if [[ "$name" != slab* ]] && [[ "$name" != smooth-* ]] && [ -n "$build" ] &&
        [ -d "$build/python/lamina" ]; then
        # Per pair: the C++ pdf at (wi, wo) and the draw from u, with whether u0 sits within 1e-3
        # of a lobe boundary (the draws at u0 ± 1e-3 differ from the one at u0).
        if ! PYTHONPATH="$build/python" "$python" - "$tmp/$name" "$stack" "$@" <<'PY' > "$tmp/$name.log" 2>&1
import csv, math, random, sys
import numpy as np
import lamina
out, stack, opts = sys.argv[1], sys.argv[2], dict(o.split("=", 1) for o in sys.argv[3:])
model = lamina.Model("lamina-1", lamina.Stack(stack), **opts)
rows = list(csv.DictReader(open(out + ".dirs.csv")))
d = lambda t, p: [math.sin(math.radians(t)) * math.cos(math.radians(p)),
                  math.sin(math.radians(t)) * math.sin(math.radians(p)), math.cos(math.radians(t))]
rng = random.Random(5)
with open(out + ".sampling.csv", "w") as f:
    f.write("u0,u1,u2,pdf,valid,ws0,ws1,ws2,boundary\n")
    for r in rows:
        wi, wo = d(float(r["theta_i"]), 0.0), d(float(r["theta_o"]), float(r["phi_o"]))
        u = [rng.random() for _ in range(3)]
        pdf = float(model.pdf(wi, wo))
        draws = [model.sample(wi, [min(max(u[0] + e, 0.0), 0.999999), u[1], u[2]])
                 for e in (0.0, -1e-3, 1e-3)]
        ws, _, _, valid = draws[0]
        same = all(bool(v) == bool(valid) and np.allclose(w, ws, atol=1e-9) for w, _, _, v in draws)
        f.write(f"{u[0]:.9g},{u[1]:.9g},{u[2]:.9g},{pdf:.9g},{int(bool(valid))},"
                f"{ws[0]:.9g},{ws[1]:.9g},{ws[2]:.9g},{1 if same else 0}\n")
PY
        then fail "sampling reference $name: $(cat "$tmp/$name.log")"; return; fi
    fi
    cases+=("$name")
}
add_case plastic "$root/examples/plastic.json"
add_case frosted-gold "$root/examples/frosted-gold.json"
add_case metallic-paint "$root/examples/metallic-paint.json"
# A slab's reflection with its later orders in bins (the default), and as the uniform series.
add_case slab "$root/examples/slab.json"
add_case slab-series "$root/examples/slab.json" slab-orders=series
add_case gold-ggx-lobe "$root/examples/frosted-gold.json" first-order-lobe=ggx spread=normal
add_case plastic-fresnel "$root/examples/plastic.json" coat-transmittance=fresnel
# Smooth coats (delta lobes, lamina1_delta): the plastic's coat smooth; gold with coat and base
# smooth under an absorbing coat, with the inter-reflection series and without it. And a clear,
# nearly smooth slab.
python3 - "$root/examples" "$tmp" <<'PY' || fail "smooth stacks"
import json, sys
plastic = json.load(open(f"{sys.argv[1]}/plastic.json"))
plastic["layers"][0]["interface"]["alpha"] = 0
gold = json.load(open(f"{sys.argv[1]}/frosted-gold.json"))
gold["layers"][0]["interface"]["alpha"] = gold["layers"][1]["interface"]["alpha"] = 0
gold["layers"][0]["medium"]["tau_a"] = [0.3, 0.1, 0.0]
clear = json.load(open(f"{sys.argv[1]}/slab.json"))
del clear["layers"][0]["medium"]
clear["layers"][0]["interface"]["alpha"] = 0.02
clear["layers"][1]["interface"]["alpha"] = 0.05
json.dump(clear, open(f"{sys.argv[2]}/slab-clear-in.json", "w"))
smooth_slab = json.load(open(f"{sys.argv[1]}/slab.json"))
smooth_slab["layers"][0]["interface"]["alpha"] = smooth_slab["layers"][1]["interface"]["alpha"] = 0
json.dump(smooth_slab, open(f"{sys.argv[2]}/smooth-slab-in.json", "w"))
json.dump(plastic, open(f"{sys.argv[2]}/smooth-plastic-in.json", "w"))
json.dump(gold, open(f"{sys.argv[2]}/smooth-gold-in.json", "w"))
PY
# A clear, nearly smooth slab: its bins in one channel, the entry curve's segments crowded.
add_case slab-clear "$tmp/slab-clear-in.json"
add_case smooth-plastic "$tmp/smooth-plastic-in.json"
add_case smooth-gold "$tmp/smooth-gold-in.json"
add_case smooth-gold-single "$tmp/smooth-gold-in.json" inter-reflection=off
# A smooth slab, polarized (the series per polarization) and not.
add_case smooth-slab "$tmp/smooth-slab-in.json"
add_case smooth-slab-unpolarized "$tmp/smooth-slab-in.json" polarization=off

if node "$root/tests/lamina1/glsl_test.js" "$root" "$tmp" "${cases[@]}"; then ok; else fail "GLSL"; fi

# A scattering coat is outside the GLSL form: refused with the reason.
if out=$("$lamina" export --lamina1-gpu "$tmp/milky.state" --stack "$root/examples/milky-coat.json" 2>&1); then
    fail "milky-coat exported: $out"
elif [[ "$out" == *"scattering medium"* ]]; then ok; else fail "milky-coat: $out"; fi
finish
