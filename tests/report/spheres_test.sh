#!/usr/bin/env bash
# ctest `spheres`: the explorer's live spheres (web/spheres.js) in headless Chromium against
# `lamina render`'s images of the same scenes (spheres_test.js states the statistics): lamina-1
# (the state `lamina export --lamina1-gpu` writes) on the plastic under studio and uniform and the
# frosted gold under studio, lamina-coat on the plastic under studio, each rendered twice by lamina
# render (seeds 1, 2) at 64² pixels and 256 samples per pixel; then the table path's furnace and
# the message without WebGL2.
# usage: spheres_test.sh LAMINA REPO_ROOT
set -u
lamina=$1 root=$2
. "$root/tests/support/script_lib.sh"
if [ ! -d "$root/node_modules/playwright-core" ]; then
    echo "FAIL playwright-core is not installed: run \`make deps\` (npm ci)"; exit 1
fi
for stack in plastic frosted-gold; do
    cp "$root/examples/$stack.json" "$tmp/"
    "$lamina" export --lamina1-gpu "$tmp/$stack.l1gpu" --stack "$tmp/$stack.json" > /dev/null ||
        fail "export $stack"
done
for scene in "plastic lamina-1 studio" "plastic lamina-1 uniform" "frosted-gold lamina-1 studio" \
             "plastic lamina-coat studio"; do
    set -- $scene
    for seed in 1 2; do
        "$lamina" render "$tmp/$1.json" --model "$2" --env "$3" --size 64 --spp 256 --seed $seed \
            --out "$tmp/$1-$2-$3-$seed.png" > /dev/null 2>&1 || fail "render $scene seed $seed"
    done
done
if node "$root/tests/report/spheres_test.js" "$root" "$tmp"; then ok; else fail "live spheres"; fi
finish
