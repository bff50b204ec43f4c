#!/usr/bin/env bash
# The command line on extreme and broken stack files (docs/robustness.md): every command either
# succeeds with finite, non-negative numbers or refuses with one "lamina: FILE: FIELD: ..." line and
# exit code 1; nothing crashes (exit codes ≥ 128) or prints NaN/inf. Usage: fuzz_cli_test.sh LAMINA
set -u
lamina=$1
. "$(dirname "$0")/../support/script_lib.sh"
fail() { echo "FAIL $1"; cat "$tmp/out"; fails=$((fails + 1)); }

run() {  # run NAME COMMAND...: exit 0 or 1, no NaN/inf, no negative BSDF value on success
    local name=$1
    shift
    "$@" >"$tmp/out" 2>&1
    local rc=$?
    if [ "$rc" -ne 0 ] && [ "$rc" -ne 1 ]; then fail "$name: exit $rc"; return; fi
    if grep -qiE '(^|[^a-z])(-?nan|-?inf)([^a-z]|$)' "$tmp/out"; then fail "$name: NaN or inf"; return; fi
    if [ "$rc" -eq 1 ] && ! grep -q '^lamina: ' "$tmp/out"; then fail "$name: refusal without a message"; return; fi
    for f in "$tmp"/eval.csv; do
        [ -f "$f" ] && [ "$rc" -eq 0 ] && tail -n +2 "$f" | cut -d, -f5- | grep -qE '(^|,)-' &&
            { fail "$name: negative value in $f"; return; }
    done
    # A point evaluation prints f_r f_g f_b: none may be negative.
    if [ "$rc" -eq 0 ] && [[ "$name" == eval-[0-9]* ]] && grep -qE '(^| )-[0-9]' "$tmp/out"; then
        fail "$name: negative value"; return
    fi
    pass=$((pass + 1))
}

printf 'theta_i,theta_o,phi_o,side\n0,0,0,R\n89.999999,90,0,R\n60,60,180,R\n30,90,180,R\n45,0,0,T\n45,89,180,T\n' >"$tmp/dirs.csv"
i=0
while IFS= read -r stack; do
    i=$((i + 1))
    printf '%s\n' "$stack" >"$tmp/s$i.json"
    run "validate-$i" "$lamina" validate "$tmp/s$i.json"
    "$lamina" validate "$tmp/s$i.json" >/dev/null 2>&1 || continue
    for model in $("$lamina" models 2>/dev/null | awk '/^[^ ]/ {print $1}' | grep -v '^random-walk$'); do
        rm -f "$tmp/eval.csv"
        run "eval-$i-$model" "$lamina" eval --model "$model" --stack "$tmp/s$i.json" --theta-i 89.999 --theta-o 90 --phi-o 180
        run "eval-batch-$i-$model" "$lamina" eval --model "$model" --stack "$tmp/s$i.json" --directions "$tmp/dirs.csv" --out "$tmp/eval.csv"
        rm -f "$tmp/eval.csv"
        run "eval-binned-$i-$model" "$lamina" eval --model "$model" --stack "$tmp/s$i.json" --binned --grid 3x4 --theta-i 0,89.9 --out "$tmp/eval.csv"
    done
    run "simulate-$i" "$lamina" simulate "$tmp/s$i.json" --particles 4096 --grid 3x4 --theta-i 0,89.999 --threads 1 --out "$tmp/sim$i"
    if [ -f "$tmp/sim$i/brdf.csv" ] && tail -n +2 "$tmp/sim$i/brdf.csv" | cut -d, -f7- | grep -qE '(^|,)-|nan|inf'; then
        fail "simulate-$i: negative or non-finite table value"
    fi
done <<'STACKS'
{"ambient_eta": 5, "layers": [{"interface": {"type": "dielectric", "eta": 1, "alpha": 0.0001}, "medium": {"tau_a": [100, 5e-324, 0], "tau_s": [0, 100, 5e-324], "g": [0.99, -0.99, 5e-324]}}, {"interface": {"type": "conductor", "eta": [0.01, 10, 1], "k": [10, 0, 1e-20], "alpha": 1}}]}
{"layers": [{"interface": {"type": "dielectric", "eta": 5, "alpha": 0}}, {"interface": {"type": "dielectric", "eta": 1, "alpha": 1}}]}
{"ambient_eta": 1, "layers": [{"interface": {"type": "conductor", "eta": 1, "k": 1e-20, "alpha": 0.0001}}]}
{"layers": [{"interface": {"type": "dielectric", "eta": 1e308, "alpha": 0.2}}, {"interface": {"type": "conductor", "eta": 0.2, "k": 3, "alpha": 0.3}}]}
{"ambient_eta": 1e-320, "layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}}, {"interface": {"type": "lambertian", "albedo": 0.8}}]}
{"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 1e-300}}, {"interface": {"type": "lambertian", "albedo": [1, 0, 5e-324]}}]}
{"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}, "medium": {"tau_s": 1e308}}, {"interface": {"type": "lambertian", "albedo": 1}}]}
{"layers": [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}
{"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}
1e999
STACKS
finish
