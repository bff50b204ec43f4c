#!/usr/bin/env bash
# `make demo`: lamina's main job. Runs the quick study (the 60 configurations, 10^6 particles per
# incidence, every model; PNG figures: `lamina study --formats png,pdf,svg` for more) and says where
# the report is. Incremental: a second run does no work and rewrites no file.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
lamina="$build/lamina"

echo "== The example stacks"
"$lamina" validate examples/*.json
echo
echo "== Their energy budgets: the goniophotometer, 10^6 particles per incidence (out/examples/NAME)"
for stack in examples/*.json; do
    name=$(basename "$stack" .json)
    echo "-- $name"
    "$lamina" simulate "$stack" --theta-i 0,45,80 --particles 1e6 --out "out/examples/$name"
done
echo
echo "== The quick study: 60 configurations x 7 incidences x 10^6 particles, every model"
start=$(date +%s)
"$lamina" study --preset quick --out out/study-quick
echo
echo "Done in $(( $(date +%s) - start )) s. Report: out/study-quick/summary.md"
if [ -f out/study-quick/index.html ]; then
    echo "Explorer: open out/study-quick/index.html in a browser (figures in out/study-quick/figures/)."
fi
