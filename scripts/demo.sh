#!/usr/bin/env bash
# `make demo`: lamina's main job. Runs the quick study (the 60 configurations and three iridescent
# ones, 10^6 particles per incidence, every model), draws its summary figures (error matrices, albedos) and the slices of
# one configuration per category (PNG; `lamina figures out/study-quick` draws every
# configuration's slices, `--formats png,pdf,svg` more formats), and says where the report is.
# Incremental: a second run does no work and rewrites no file.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
lamina="$build/lamina"

echo "== The example stacks"
"$lamina" validate examples/*.json
echo
echo "== Their energy budgets: the goniophotometer, 2x10^5 particles per incidence (out/examples/NAME)"
for stack in examples/*.json; do
    name=$(basename "$stack" .json)
    echo "-- $name"
    "$lamina" simulate "$stack" --theta-i 0,45,80 --particles 2e5 --out "out/examples/$name"
done
echo
echo "== The quick study: 63 configurations (the 60 and three iridescent) x 7 incidences x 10^6 particles, every model"
start=$(date +%s)
"$lamina" study --preset quick --no-figures --out out/study-quick
echo
echo "== Its figures: error matrices, albedos, and the slices of one configuration per category"
"$lamina" figures out/study-quick \
    --only 'plastic-P1-a0.05,paint-a0.05-a1.3,frosted-a0.3-a1.05,slab-a0.1-a1.3-clear,irid-ti-oxide-a0.05-a1.3' ||
    echo "lamina: warning: figures not written (the message is above); the study itself is done" >&2
echo
echo "Done in $(( $(date +%s) - start )) s. Report: out/study-quick/summary.md"
if [ -f out/study-quick/index.html ]; then
    echo "Explorer: open out/study-quick/index.html in a browser (figures in out/study-quick/figures/;"
    echo "every configuration's slices: $lamina figures out/study-quick)."
fi
