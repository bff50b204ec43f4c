#!/usr/bin/env bash
# --model-table NAME=FILE.csv (docs/formats.md): a built-in model's `eval --binned` table fed back as
# a table gives exactly the built-in's metrics; tables that do not match the study are refused with
# a message naming the file and what differs. Usage: model_table_test.sh LAMINA SRC_DIR
set -u
lamina=$1
src=$2
. "$(dirname "$0")/../support/script_lib.sh"
stack=$src/examples/plastic.json
common=(--theta-i 0,60 --particles 4e4 --grid 18x18 --no-figures)

"$lamina" eval --model ww-prime --stack "$stack" --binned --theta-i 0,60 --grid 18x18 \
    --out "$tmp/ww.csv" >/dev/null 2>&1 && ok || fail "eval --binned"

# 1. The table joins like a model; its metrics are the built-in's, bit for bit.
if "$lamina" compare "$stack" "${common[@]}" --models ww-prime --model-table "mine=$tmp/ww.csv" \
    --out "$tmp/c" >"$tmp/c.log" 2>&1; then ok; else fail "compare with a table"; cat "$tmp/c.log"; fi
grep ',ww-prime,' "$tmp/c/metrics.csv" | cut -d, -f4- >"$tmp/builtin"
grep ',mine,' "$tmp/c/metrics.csv" | cut -d, -f4- >"$tmp/table"
[ -s "$tmp/builtin" ] && cmp -s "$tmp/builtin" "$tmp/table" && ok || fail "table metrics differ from the built-in's"
grep -q '"mine"' "$tmp/c/study.json" && ok || fail "study.json lists the table"
grep -q 'mine' "$tmp/c/summary.md" && ok || fail "summary.md shows the table"
grep -q '"mine"' "$tmp/c/configs/plastic/config.json" && ok || fail "config.json sources"
[ -s "$tmp/c/index.html" ] && ok || fail "explorer page"

# 2. Mismatches are refused, naming the file and what differs; nothing is written.
expect_error() {  # expect_error NAME PATTERN ARGS...
    local name=$1 pattern=$2
    shift 2
    if "$lamina" "$@" >"$tmp/e.log" 2>&1; then fail "$name: accepted"; return; fi
    grep -q -- "$pattern" "$tmp/e.log" && ok || { fail "$name: message"; cat "$tmp/e.log"; }
}
expect_error grid "ww.csv: grid: the table's grid is 18x18 but the study's is 9x9" \
    compare "$stack" --theta-i 0,60 --particles 4e4 --grid 9x9 --no-figures \
    --model-table "mine=$tmp/ww.csv" --out "$tmp/g"
[ ! -e "$tmp/g/metrics.csv" ] && ok || fail "grid mismatch wrote metrics"
expect_error incidences "theta_i: the table's incidences are 0,60 but the study's are 0,30" \
    compare "$stack" --theta-i 0,30 --particles 4e4 --grid 18x18 --no-figures \
    --model-table "mine=$tmp/ww.csv" --out "$tmp/i"
head -n 100 "$tmp/ww.csv" >"$tmp/short.csv"
expect_error truncated "short.csv" compare "$stack" "${common[@]}" \
    --model-table "mine=$tmp/short.csv" --out "$tmp/s"
sed '5s/,R,/,R,x/' "$tmp/ww.csv" >"$tmp/bad.csv"
expect_error malformed "bad.csv: line 5" compare "$stack" "${common[@]}" \
    --model-table "mine=$tmp/bad.csv" --out "$tmp/b"
sed '3s/^\([^,]*,[^,]*\),[^,]*,/\1,-3,/' "$tmp/ww.csv" >"$tmp/edges.csv"
expect_error edges "edges.csv: line 3" compare "$stack" "${common[@]}" \
    --model-table "mine=$tmp/edges.csv" --out "$tmp/x"
expect_error missing "nope.csv" compare "$stack" "${common[@]}" \
    --model-table "mine=$tmp/nope.csv" --out "$tmp/m"
expect_error syntax "is not NAME=FILE.csv" compare "$stack" "${common[@]}" \
    --model-table "$tmp/ww.csv" --out "$tmp/n"
expect_error taken "cannot name a model table" compare "$stack" "${common[@]}" --models ww-prime \
    --model-table "ww-prime=$tmp/ww.csv" --out "$tmp/t"

# 3. In a study, a table is per configuration: FILE with {id}; without it several configurations
#    are refused; a configuration without a file is "not supported".
only=(--only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --models ww-prime "${common[@]}")
expect_error pattern "write FILE with {id}" study "${only[@]}" --model-table "mine=$tmp/ww.csv" \
    --out "$tmp/p"
mkdir -p "$tmp/tables"
"$lamina" study "${only[@]}" --out "$tmp/st0" >/dev/null 2>&1 && ok || fail "study without tables"
if "$lamina" study "${only[@]}" --model-table "mine=$tmp/tables/{id}.csv" --out "$tmp/st" \
    >"$tmp/st.log" 2>&1; then ok; else fail "study with a table pattern"; cat "$tmp/st.log"; fi
grep -q '^slab-a0.1-a1.3-clear,slab,mine,0,R,r,,,,,,,,,,false$' "$tmp/st/metrics.csv" \
    && ok || fail "configuration without a table is not supported"

finish
