#!/usr/bin/env bash
# ctest `spheres`: the explorer's live spheres (web/spheres.js) in headless Chromium against
# `lamina render`'s images of the same scenes (spheres_test.js states the statistics): lamina-1
# (the state `lamina export --lamina1-gpu` writes) on the plastic under studio and uniform and the
# frosted gold under studio, lamina-coat on the plastic under studio, each rendered twice by lamina
# render (seeds 1, 2) at 64² pixels and 256 samples per pixel; the slab's reflection (its later
# orders in bins) under studio; the plastic under sky; smooth coats
# (delta lobes: the mirror reflection), the plastic's coat smooth with lamina-1 under studio and
# sky and with lamina-coat under studio, the gold with coat and base smooth with both models under
# studio; wrong variants, which must be rejected; then the table path's furnace, a variant's
# state composed as the page does it (the slab's with a rougher coat's per-material part) against
# that stack's own, and the message without WebGL2.
# usage: spheres_test.sh LAMINA REPO_ROOT
set -u
lamina=$1 root=$2
. "$root/tests/support/script_lib.sh"
if [ ! -d "$root/node_modules/playwright-core" ]; then
    echo "FAIL playwright-core is not installed: run \`make deps\` (npm ci)"; exit 1
fi
cp "$root/examples/plastic.json" "$root/examples/frosted-gold.json" "$root/examples/slab.json" "$tmp/"
# Smooth coats (α = 0: delta lobes): the plastic's coat, and the gold with coat and base smooth.
python3 - "$tmp" <<'PY' || fail "smooth stacks"
import json, sys
for name, out, layers in (("plastic", "smooth-plastic", [0]), ("frosted-gold", "smooth-gold", [0, 1])):
    stack = json.load(open(f"{sys.argv[1]}/{name}.json"))
    for k in layers:
        stack["layers"][k]["interface"]["alpha"] = 0
    json.dump(stack, open(f"{sys.argv[1]}/{out}.json", "w"))
PY
# The slab with a rougher coat: a variant's state, which the page composes from the slab's.
python3 - "$tmp" <<'PY' || fail "rough slab"
import json, sys
stack = json.load(open(f"{sys.argv[1]}/slab.json"))
stack["layers"][0]["interface"]["alpha"] = 0.4
json.dump(stack, open(f"{sys.argv[1]}/slab-rough.json", "w"))
PY
for stack in plastic frosted-gold slab slab-rough smooth-plastic smooth-gold; do
    "$lamina" export --lamina1-gpu "$tmp/$stack.l1gpu" --stack "$tmp/$stack.json" > /dev/null ||
        fail "export $stack"
done
for scene in "plastic lamina-1 studio" "plastic lamina-1 uniform" "frosted-gold lamina-1 studio" \
             "slab lamina-1 studio" \
             "plastic lamina-coat studio" "plastic lamina-1 sky" "smooth-plastic lamina-1 studio" \
             "smooth-plastic lamina-coat studio" "smooth-plastic lamina-1 sky" \
             "smooth-gold lamina-1 studio" "smooth-gold lamina-coat studio"; do
    set -- $scene
    for seed in 1 2; do
        "$lamina" render "$tmp/$1.json" --model "$2" --env "$3" --size 64 --spp 256 --seed $seed \
            --out "$tmp/$1-$2-$3-$seed.png" > /dev/null 2>&1 || fail "render $scene seed $seed"
    done
done
if node "$root/tests/report/spheres_test.js" "$root" "$tmp"; then ok; else fail "live spheres"; fi
finish
