#!/usr/bin/env bash
# `make demo`: the main job as it exists. Validates the example stacks and runs the reference
# (the virtual goniophotometer) on each, printing its energy budget.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
lamina="$build/lamina"

echo "== The example stacks"
"$lamina" validate examples/*.json

for stack in examples/*.json; do
    name=$(basename "$stack" .json)
    out="out/simulate/$name"
    echo
    echo "== Goniophotometer: $name (7 incidences, 10^6 particles each) -> $out"
    "$lamina" simulate "$stack" --particles 1e6 --out "$out"
done
echo
echo "Tables and budgets are in out/simulate/*/ (formats: docs/formats.md)."
