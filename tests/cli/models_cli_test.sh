#!/usr/bin/env bash
# End-to-end checks of `lamina models` and `lamina eval`. Usage: models_cli_test.sh LAMINA
set -u
lamina=$1
. "$(dirname "$0")/../support/script_lib.sh"
check() {  # check NAME EXPECTED_RC COMMAND...
    local name=$1 want=$2
    shift 2
    "$@" >"$tmp/out" 2>&1
    local rc=$?
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL $name: exit $rc, wanted $want"; cat "$tmp/out"; fails=$((fails + 1))
    else
        pass=$((pass + 1))
    fi
}
expect_output() {  # expect_output NAME PATTERN: the last command's output matches PATTERN
    if grep -q -- "$2" "$tmp/out"; then pass=$((pass + 1)); else
        echo "FAIL $1: output lacks '$2'"; cat "$tmp/out"; fails=$((fails + 1)); fi
}

check models 0 "$lamina" models --options
for m in ww09 ele10 ww-prime bel18-forward bel18-symmetric bel-prime wb20 tm2; do expect_output "models $m" "^$m "; done
for m in openpbr openpbr-adobe standard-surface enterprise-pbr filament gltf-clearcoat \
    blender-principled kulla-conty; do expect_output "models $m" "^$m "; done
expect_output "models groups" "^\[production\]"
expect_output "models production flags" "--option darkening={on,off} (default on)"
expect_output "models leaves flag" "--option leaves={shipped,exact} (default shipped)"
check unknown-model 1 "$lamina" eval --model ww10 --stack x.json --theta-i 30 --theta-o 45 --phi-o 180
expect_output unknown-model-lists "known models: ww09"
check theta-i-range 1 "$lamina" eval --model ww09 --stack x.json --theta-i 90 --theta-o 45 --phi-o 180
expect_output theta-i-range-says "theta-i"
check theta-o-range 1 "$lamina" eval --model ww09 --stack x.json --theta-i 30 --theta-o 91 --phi-o 180
check bad-option 1 "$lamina" eval --model ww09 --stack x.json --theta-i 30 --theta-o 45 --phi-o 180 --option tir=on
expect_output bad-option-lists "its options"
check bad-option-value 1 "$lamina" eval --model bel-prime --stack x.json --theta-i 30 --theta-o 45 --phi-o 180 --option tir=maybe
check binned-needs-out 1 "$lamina" eval --model ww09 --stack x.json --binned

cat >"$tmp/gold.json" <<'JSON'
{"name": "coated gold", "layers": [
  {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.1}, "medium": {"tau_a": 0.1}},
  {"interface": {"type": "conductor", "eta": [0.18, 0.42, 1.37], "k": [3.4, 2.35, 1.85], "alpha": 0.2}}]}
JSON
cat >"$tmp/plastic.json" <<'JSON'
{"name": "plastic", "layers": [
  {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}},
  {"interface": {"type": "lambertian", "albedo": 0.8}}]}
JSON
if "$lamina" validate "$tmp/gold.json" >/dev/null 2>&1; then
    check point 0 "$lamina" eval --model bel-prime --stack "$tmp/gold.json" --theta-i 30 --theta-o 45 --phi-o 180
    expect_output point-three-numbers "^[0-9.e+-]* [0-9.e+-]* [0-9.e+-]*$"
    check not-supported 1 "$lamina" eval --model bel18-forward --stack "$tmp/plastic.json" --theta-i 30 --theta-o 45 --phi-o 180
    expect_output not-supported-says "not supported: bel18-forward has no Lambertian base"
    check no-btdf 1 "$lamina" eval --model ww09 --stack "$tmp/gold.json" --theta-i 30 --theta-o 45 --phi-o 180 --side T
    # An opaque stack's BTDF is refused with the reason, naming the option or the file's line
    # (the models leave their support reason empty for a side an opaque stack does not have).
    expect_output no-btdf-says "lamina: command line: --side: side T: the stack is opaque"
    printf 'theta_i,theta_o,phi_o,side\n30,45,180,R\n45,0,0,T\n' >"$tmp/dirs-t.csv"
    check batch-no-btdf 1 "$lamina" eval --model ww-prime --stack "$tmp/plastic.json" --directions "$tmp/dirs-t.csv" --out "$tmp/t.csv"
    expect_output batch-no-btdf-says "dirs-t.csv: line 3, side: side T: the stack is opaque"
    check batch-no-btdf-writes-nothing 1 test -e "$tmp/t.csv"
    printf 'theta_i,theta_o,phi_o,side\n30,45,180,R\n0,10,0,R\n' >"$tmp/dirs.csv"
    check batch 0 "$lamina" eval --model ww-prime --stack "$tmp/plastic.json" --directions "$tmp/dirs.csv" --out "$tmp/f.csv"
    if head -1 "$tmp/f.csv" | grep -q '^theta_i,theta_o,phi_o,side,f_r,f_g,f_b$' && [ "$(wc -l <"$tmp/f.csv")" -eq 3 ]; then
        pass=$((pass + 1)); else echo "FAIL batch output"; cat "$tmp/f.csv"; fails=$((fails + 1)); fi
    printf 'theta_i,theta_o\n30,45\n' >"$tmp/bad.csv"
    check batch-bad-header 1 "$lamina" eval --model ww-prime --stack "$tmp/plastic.json" --directions "$tmp/bad.csv" --out "$tmp/g.csv"
    check binned 0 "$lamina" eval --model bel18-symmetric --stack "$tmp/gold.json" --theta-i 0,30,60 --binned --grid 9x6 --out "$tmp/b.csv"
    if head -1 "$tmp/b.csv" | grep -q '^theta_i,side,theta_lo,theta_hi,phi_lo,phi_hi,f_r,f_g,f_b,se_r,se_g,se_b$' && [ "$(wc -l <"$tmp/b.csv")" -eq $((1 + 3 * 54)) ]; then
        pass=$((pass + 1)); else echo "FAIL binned output"; head -3 "$tmp/b.csv"; fails=$((fails + 1)); fi
    # A production coat with a flag, and a flag it does not have.
    check production 0 "$lamina" eval --model openpbr --stack "$tmp/gold.json" --theta-i 30 --theta-o 45 --phi-o 180 --option darkening=off --option leaves=exact
    expect_output production-three-numbers "^[0-9.e+-]* [0-9.e+-]* [0-9.e+-]*$"
    # The study's ablation names work too, and give the same value as --option.
    "$lamina" eval --model openpbr --stack "$tmp/gold.json" --theta-i 30 --theta-o 45 --phi-o 180 --option darkening=off >"$tmp/a1" 2>&1
    "$lamina" eval --model openpbr:darkening=off --stack "$tmp/gold.json" --theta-i 30 --theta-o 45 --phi-o 180 >"$tmp/a2" 2>&1
    if cmp -s "$tmp/a1" "$tmp/a2" && grep -q "^[0-9]" "$tmp/a1"; then pass=$((pass + 1)); else
        echo "FAIL spec name: '$(cat "$tmp/a2")' vs '$(cat "$tmp/a1")'"; fails=$((fails + 1)); fi
    check production-bad-flag 1 "$lamina" eval --model filament --stack "$tmp/gold.json" --theta-i 30 --theta-o 45 --phi-o 180 --option darkening=off
    expect_output production-bad-flag-lists "its options: attenuation, roughening, f0-conversion, energy-compensation, leaves"
    # An anisotropic stack: the models that represent it bin it on the unfolded grid (φ over
    # [0°, 360°): twice the φ bins), as does φi ≠ 0; the others say why they do not.
    cat >"$tmp/brushed.json" <<'JSON'
{"name": "brushed gold", "layers": [
  {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.1}},
  {"interface": {"type": "conductor", "eta": [0.18, 0.42, 1.37], "k": [3.4, 2.35, 1.85], "alpha": [0.3, 0.05], "tangent_deg": 30}}]}
JSON
    check aniso-binned 0 "$lamina" eval --model openpbr-adobe --stack "$tmp/brushed.json" --theta-i 30 --phi-i 45 --binned --grid 9x6 --out "$tmp/ab.csv"
    if [ "$(wc -l <"$tmp/ab.csv")" -eq $((1 + 9 * 12)) ] && awk -F, 'NR > 1 && $6 > 359 { n++ } END { exit !(n == 9) }' "$tmp/ab.csv"; then
        pass=$((pass + 1)); else echo "FAIL unfolded binned output"; head -3 "$tmp/ab.csv"; fails=$((fails + 1)); fi
    check phi-i-binned 0 "$lamina" eval --model bel-prime --stack "$tmp/gold.json" --theta-i 30 --phi-i 90 --binned --grid 9x6 --out "$tmp/pb.csv"
    [ "$(wc -l <"$tmp/pb.csv")" -eq $((1 + 9 * 12)) ] && pass=$((pass + 1)) || { echo "FAIL phi_i binned"; fails=$((fails + 1)); }
    check aniso-point 0 "$lamina" eval --model openpbr --stack "$tmp/brushed.json" --theta-i 30 --phi-i 200 --theta-o 45 --phi-o 20
    expect_output aniso-point-three-numbers "^[0-9.e+-]* [0-9.e+-]* [0-9.e+-]*$"
    check aniso-not-supported 1 "$lamina" eval --model tm2 --stack "$tmp/brushed.json" --theta-i 30 --theta-o 45 --phi-o 180
    expect_output aniso-not-supported-says "not supported: the stack has an anisotropic interface"
    # A batch with a phi_i column: each row lit from its own azimuth, as --phi-i lights a point
    # (the brushed stack's value changes with φi at fixed φo − φi, so a dropped column shows).
    printf 'theta_i,phi_i,theta_o,phi_o,side\n30,200,45,20,R\n30,0,45,180,R\n' >"$tmp/dirs-phi.csv"
    check batch-phi 0 "$lamina" eval --model openpbr --stack "$tmp/brushed.json" --directions "$tmp/dirs-phi.csv" --out "$tmp/fphi.csv"
    p1=$("$lamina" eval --model openpbr --stack "$tmp/brushed.json" --theta-i 30 --phi-i 200 --theta-o 45 --phi-o 20 | tr ' ' ',')
    p2=$("$lamina" eval --model openpbr --stack "$tmp/brushed.json" --theta-i 30 --theta-o 45 --phi-o 180 | tr ' ' ',')
    if head -1 "$tmp/fphi.csv" | grep -qx 'theta_i,phi_i,theta_o,phi_o,side,f_r,f_g,f_b' &&
        [ "$(sed -n 2p "$tmp/fphi.csv")" = "30,200,45,20,R,$p1" ] &&
        [ "$(sed -n 3p "$tmp/fphi.csv")" = "30,0,45,180,R,$p2" ] && [ "$p1" != "$p2" ]; then
        pass=$((pass + 1)); else echo "FAIL batch with phi_i: $p1 / $p2"; cat "$tmp/fphi.csv"; fails=$((fails + 1)); fi
    printf 'theta_i,phi_i,theta_o,phi_o,side\n30,400,45,20,R\n' >"$tmp/dirs-bad-phi.csv"
    check batch-phi-range 1 "$lamina" eval --model openpbr --stack "$tmp/brushed.json" --directions "$tmp/dirs-bad-phi.csv" --out "$tmp/g.csv"
    expect_output batch-phi-range-says "line 2, phi_i: 400 degrees is outside \[0, 360\]"
    check batch-phi-twice 1 "$lamina" eval --model openpbr --stack "$tmp/brushed.json" --phi-i 10 --directions "$tmp/dirs-phi.csv" --out "$tmp/g.csv"
    expect_output batch-phi-twice-says "has a phi_i column"
    check phi-i-range 1 "$lamina" eval --model ww09 --stack "$tmp/gold.json" --theta-i 30 --phi-i 400 --theta-o 45 --phi-o 180
    expect_output phi-i-range-says "phi-i"
    check phi-i-nan 1 "$lamina" eval --model ww09 --stack "$tmp/gold.json" --theta-i 30 --phi-i nan --theta-o 45 --phi-o 180
    # The study compares an anisotropic stack on the unfolded grid, lit from φi = 0°, 45° and 90°:
    # metrics.csv gets its phi_i column, and the models that do not represent anisotropy are
    # "not supported" (false rows), not failures.
    check compare-aniso 0 "$lamina" compare "$tmp/brushed.json" --particles 1000 --theta-i 30 --grid 9x6 \
        --models openpbr,bel-prime --no-figures --out "$tmp/cmp"
    if head -1 "$tmp/cmp/metrics.csv" | grep -q '^config,category,model,theta_i,phi_i,side,' &&
        grep -q ',openpbr,30,90,R,r,[0-9]' "$tmp/cmp/metrics.csv" &&
        grep -q ',bel-prime,30,45,R,g,,,,,,,,,,false$' "$tmp/cmp/metrics.csv"; then
        pass=$((pass + 1)); else echo "FAIL compare-aniso metrics.csv"; head -3 "$tmp/cmp/metrics.csv"; fails=$((fails + 1)); fi
else
    echo "FAIL validate: 'lamina validate' does not accept the test's stack"; fails=$((fails + 1))
fi

# `lamina tables` computes every table the models read into the cache; the build ran it for its
# own folder (<build>/tables), which a lamina built there reads after an empty cache: nothing is
# computed again, so nothing is written. Without that folder every table is computed and cached.
check tables 0 env LAMINA_CACHE_DIR="$tmp/cache" "$lamina" tables
for t in fgd ggx-albedo tir tir-lobe slope-sum coat-t ms-albedo; do expect_output "tables $t" "^$t "; done
built=$(dirname "$lamina")/tables
if [ -f "$built/computed.stamp" ]; then
    expect_output tables-names-the-build "then, read only: .*tables (the build's)"
    if [ -z "$(ls -A "$tmp/cache" 2>/dev/null)" ]; then pass=$((pass + 1)); else
        echo "FAIL tables: computed again with the build's folder present:"; ls "$tmp/cache"; fails=$((fails + 1)); fi
    if [ "$(ls "$built"/*.bin | wc -l)" -eq 8 ]; then pass=$((pass + 1)); else
        echo "FAIL tables: the build's folder lacks tables:"; ls "$built"; fails=$((fails + 1)); fi
    # Every table the models read is among them: every model on a plastic, a metallic paint, a
    # slab, a scattering coat and a frosted metal, with an empty cache, computes (and caches)
    # nothing. A table missing from models/tables/every_table.h would land in the cache here.
    for example in plastic metallic-paint slab milky-coat frosted-gold; do
        check "tables-$example" 0 env LAMINA_CACHE_DIR="$tmp/cache" "$lamina" compare \
            "$(dirname "$0")/../../examples/$example.json" --particles 1000 --theta-i 30 \
            --grid 9x6 --no-figures --out "$tmp/tables-$example"
    done
    if [ -z "$(ls -A "$tmp/cache" 2>/dev/null)" ]; then pass=$((pass + 1)); else
        echo "FAIL tables: the models computed tables the build's folder lacks:"; ls "$tmp/cache"
        fails=$((fails + 1)); fi
fi
finish
