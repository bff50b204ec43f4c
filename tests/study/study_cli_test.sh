#!/usr/bin/env bash
# End-to-end checks of `lamina study` and `lamina compare` on a tiny budget: outputs, resuming
# after a kill, a corrupt cache, bad arguments. Usage: study_cli_test.sh LAMINA SRC_DIR
set -u
lamina=$1
src=$2
pass=0
fails=0
ok() { pass=$((pass + 1)); }
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

tiny=(--only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --models ww-prime,bel-prime
      --theta-i 0,60 --particles 4e4 --grid 18x18)

# 1. A tiny study runs end to end and writes the documented files.
if "$lamina" study "${tiny[@]}" --out "$tmp/a" >"$tmp/a.log" 2>&1; then ok; else fail "study run"; cat "$tmp/a.log"; fi
for f in study.json metrics.csv summary.md summary.json \
         configs/plastic-P1-a0.05/config.json configs/plastic-P1-a0.05/tables.npy \
         configs/plastic-P1-a0.05/reference_se.npy configs/slab-a0.1-a1.3-clear/tables.npy; do
    [ -s "$tmp/a/$f" ] && ok || fail "missing $f"
done
head -1 "$tmp/a/metrics.csv" | grep -qx \
    'config,category,model,theta_i,side,channel,misplaced_energy,albedo_ref,albedo_model,albedo_error,rmse,log_rmse,noise_floor,supported' \
    && ok || fail "metrics.csv header"
# plastic: 2 models × 2 incidences × R × 3 channels; slab: 2 × 2 × (R, T) × 3; plus the header.
[ "$(wc -l <"$tmp/a/metrics.csv")" -eq 37 ] && ok || fail "metrics.csv rows: $(wc -l <"$tmp/a/metrics.csv")"
# bel-prime has no Lambertian base: its plastic rows are 'not supported' with empty metrics.
grep -q '^plastic-P1-a0.05,plastic,bel-prime,0,R,r,,,,,,,,false$' "$tmp/a/metrics.csv" \
    && ok || fail "unsupported rows"
grep -q '^slab-a0.1-a1.3-clear,slab,bel-prime,60,T,b,[0-9]' "$tmp/a/metrics.csv" \
    && ok || fail "bel-prime BTDF rows"
grep -q '^## Findings' "$tmp/a/summary.md" && ok || fail "summary findings"
grep -q '^## Approximations assessment' "$tmp/a/summary.md" && ok || fail "summary assessment"
grep -q 'Findings' "$tmp/a.log" && ok || fail "findings printed"

# 2. Re-running reuses every stored piece and gives the same metrics.
"$lamina" study "${tiny[@]}" --out "$tmp/a" >/dev/null 2>&1
cmp -s "$tmp/a/metrics.csv" "$tmp/a/metrics.csv" && ok || fail "rerun"

# 3. Killed part-way (kill -9 as soon as the first piece is stored), then resumed: the same
#    metrics.csv as the uninterrupted run.
"$lamina" study "${tiny[@]}" --out "$tmp/b" >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 600); do
    if [ -n "$(find "$tmp/b/cache" -name '*.bin' 2>/dev/null | head -1)" ]; then break; fi
    sleep 0.05
done
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
pieces=$(find "$tmp/b/cache" -name '*.bin' 2>/dev/null | wc -l)
if [ "$pieces" -ge 1 ] && [ ! -e "$tmp/b/metrics.csv" ]; then ok; else fail "kill: $pieces pieces, metrics present: $([ -e "$tmp/b/metrics.csv" ] && echo yes)"; fi
[ -z "$(find "$tmp/b" -name '*.tmp-*')" ] || echo "note: a killed write left a temporary file (ignored by readers)"
"$lamina" study "${tiny[@]}" --out "$tmp/b" >/dev/null 2>&1 && ok || fail "resume"
cmp -s "$tmp/a/metrics.csv" "$tmp/b/metrics.csv" && ok || fail "resumed metrics differ"

# 4. A corrupt piece is recomputed, not trusted.
piece=$(find "$tmp/b/cache" -name '*.bin' | head -1)
printf 'garbage' >"$piece"
"$lamina" study "${tiny[@]}" --out "$tmp/b" >/dev/null 2>&1 && ok || fail "corrupt rerun"
cmp -s "$tmp/a/metrics.csv" "$tmp/b/metrics.csv" && ok || fail "metrics after corrupt piece"

# 5. compare on one stack file.
"$lamina" compare "$src/examples/metallic-paint.json" --theta-i 30 --particles 2e4 --grid 18x18 \
    --models ww-prime,bel18-symmetric --out "$tmp/c" >/dev/null 2>&1 && ok || fail "compare"
[ -s "$tmp/c/configs/metallic-paint/tables.npy" ] && ok || fail "compare tables"
[ "$(wc -l <"$tmp/c/metrics.csv")" -eq 7 ] && ok || fail "compare rows"

# 6. Bad arguments: a clear message and a non-zero exit.
expect_error() {  # expect_error TEXT ARGS...
    local text=$1
    shift
    if "$lamina" "$@" >"$tmp/err" 2>&1; then fail "accepted: $*"; return; fi
    grep -qF -- "$text" "$tmp/err" && ok || { fail "message for $*:"; cat "$tmp/err"; }
}
expect_error "--preset: 'huge' is not a preset" study --preset huge --out "$tmp/x"
expect_error "--only: 'nothing' matches no configuration" study --only nothing --out "$tmp/x"
expect_error "unknown model" study --models ww-prime,nope --only 'plastic-P1-a0.05' --out "$tmp/x"
expect_error "--theta-i: 95 is outside" study --theta-i 95 --out "$tmp/x"
echo '{"configurations": [{"id": "a b", "stack": {}}]}' >"$tmp/bad.json"
expect_error "/configurations/0/id" study --configs "$tmp/bad.json" --out "$tmp/x"

expect_error "--microsurface: multiple scattering on the microsurfaces runs on the scalar kernel" \
    study --microsurface multiple --only 'plastic-P1-a0.05' --out "$tmp/x"
expect_error "--microsurface: 'double' is not a microsurface model" \
    study --microsurface double --kernel scalar --only 'plastic-P1-a0.05' --out "$tmp/x"

expect_error "--transmission-masking: 'walter' is not a transmission masking" \
    study --transmission-masking walter --only 'plastic-P1-a0.05' --out "$tmp/x"

# 7. A multiple-scattering reference: its own cache pieces (the key says so), nothing lost to the
#    microsurfaces in the budgets, and study.json and summary.json say which reference it is.
ms=(--only 'plastic-P1-a0.05' --models ww-prime --theta-i 60 --particles 2e4 --grid 18x18
    --no-figures --kernel scalar)
"$lamina" study "${ms[@]}" --out "$tmp/m" >/dev/null 2>&1 && ok || fail "single-scattering study"
"$lamina" study "${ms[@]}" --microsurface multiple --out "$tmp/m" >/dev/null 2>&1 \
    && ok || fail "multiple-scattering study"
[ "$(find "$tmp/m/cache" -name '*.bin' | wc -l)" -eq 2 ] && ok || fail "one cache piece per model"
python3 - "$tmp/m" <<'PY' && ok || fail "multiple-scattering outputs"
import json, sys
d = sys.argv[1]
assert json.load(open(d + "/study.json"))["microsurface"] == "multiple"
assert json.load(open(d + "/summary.json"))["microsurface"] == "multiple"
for e in json.load(open(d + "/configs/plastic-P1-a0.05/config.json"))["energy"]:
    assert e["lost_microsurface"] == [0, 0, 0], e
PY

# 8. The refraction masking: a pbrt reference of a rough-coated configuration is a cache piece of
#    its own (a cache made before the option, with that form, stays valid for it; one made with
#    the Smith form is never reused as pbrt), and study.json says which.
"$lamina" study "${ms[@]}" --transmission-masking pbrt --out "$tmp/m" >/dev/null 2>&1 \
    && ok || fail "pbrt-masking study"
[ "$(find "$tmp/m/cache" -name '*.bin' | wc -l)" -eq 3 ] && ok || fail "one cache piece per masking"
python3 -c "import json,sys; assert json.load(open(sys.argv[1]))['transmission_masking'] == 'pbrt'" \
    "$tmp/m/study.json" && ok || fail "study.json transmission_masking"

echo "$pass passed, $fails failed"
[ "$fails" -eq 0 ]
