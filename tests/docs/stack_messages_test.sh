#!/usr/bin/env bash
# The error messages docs/stack-format.md quotes ("Messages you may see") are what lamina prints:
# each input below, validated as s.json, must print the block's line of the same rank, word for
# word. A message changed in the code without the page fails here.
# Usage: stack_messages_test.sh LAMINA SOURCE_DIR
set -uo pipefail
lamina=$(realpath "$1")
src=$(realpath "$2")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
. "$src/tests/docs/quoted_lib.sh"

layer='{"interface":{"type":"dielectric","eta":1.5,"alpha":0}}'
base='{"interface":{"type":"lambertian","albedo":0.5}}'
hundred=$(for _ in $(seq 100); do printf '%s,' "$layer"; done)
deep="$(printf '[%.0s' $(seq 32))0$(printf ']%.0s' $(seq 32))"
inputs=(
    '{"layers":[{"interface":{"type":"dielectric" "eta":1.5,"alpha":0}}]}'
    '[1,2]'
    '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpah":0.1}}]}'
    '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"roughness":0.1}}]}'
    '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":0,"alpha":0.1}}]}'
    NUL
    '{"layers":[{"interface":{"type":"dielectric","eta":1.5}}]}'
    '{"layers":[{"interface":{"type":"dielectric","eta":"1.5","alpha":0}}]}'
    '{"layers":[{"interface":{"type":"dielectric","eta":[1.5,1.5,1.5],"alpha":0}}]}'
    '{"layers":[{"interface":{"type":"lambertian","albedo":[1,0.5]}}]}'
    "{\"layers\":[{\"interface\":{\"type\":\"dielectric\",\"eta\":1.5,\"alpha\":0},\"medium\":{\"tau_a\":[0,1e999,0]}},$base]}"
    "{\"ambient_eta\":0,\"layers\":[$base]}"
    '{"layers":[{"interface":{"type":"dielectric","eta":1e308,"alpha":0}}]}'
    '{"layers":[{"interface":{"type":"dielectric","eta":1.5,"alpha":1.5}}]}'
    "{\"layers\":[{\"interface\":{\"type\":\"dielectric\",\"eta\":1.5,\"alpha\":0},\"medium\":{\"tau_s\":-0.5}},$base]}"
    "{\"layers\":[{\"interface\":{\"type\":\"dielectric\",\"eta\":1.5,\"alpha\":0},\"medium\":{\"tau_s\":1,\"g\":1}},$base]}"
    '{"layers":[{"interface":{"type":"conductor","eta":1.5,"k":[1,-1,1],"alpha":0}}]}'
    "{\"layers\":[$hundred$base]}"
    "{\"ambient_eta\":$deep,\"layers\":[]}"
    '{"layers":[{"interface":{"type":"dielectirc","eta":1.5,"alpha":0}}]}'
    "{\"layers\":[{\"interface\":{\"type\":\"conductor\",\"eta\":1.5,\"k\":1,\"alpha\":0}},$base]}"
    '{"layers":[{"interface":{"type":"lambertian","albedo":0.5},"medium":{"tau_a":1}}]}'
    '{"layers":[]}'
    '{}'
    MISSING
)

# The quoted block: the lines between the fences that follow "Messages you may see:".
awk '/^Messages you may see/ { seen = 1; next }
     seen && /^```/ { if (inside) exit; inside = 1; next }
     inside { print }' "$src/docs/stack-format.md" >quoted.txt

: >printed.txt
for input in "${inputs[@]}"; do
    rm -f s.json
    case $input in
        NUL) printf '{"layers":[{"interface":{"type":"dielectric","eta":1,"alpha":\0}}]}' >s.json ;;
        MISSING) ;;
        *) printf '%s' "$input" >s.json ;;
    esac
    "$lamina" validate s.json >out.txt 2>&1
    rc=$?
    if [ "$rc" -eq 0 ]; then
        echo "FAIL: accepted: $input"
        exit 1
    fi
    head -n 1 out.txt >>printed.txt
done

same_as_quoted docs/stack-format.md "${#inputs[@]}"
