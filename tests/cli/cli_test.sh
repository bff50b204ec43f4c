#!/usr/bin/env bash
# End-to-end checks of the command line: exit codes and messages. Usage: cli_test.sh LAMINA SRC_DIR
set -u
lamina=$1
src=$2
fails=0
pass=0
check() {  # check NAME EXPECTED_RC COMMAND...
    local name=$1 want=$2
    shift 2
    "$@" >/tmp/lamina-cli-out.$$ 2>&1
    local rc=$?
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL $name: exit $rc, wanted $want"; cat /tmp/lamina-cli-out.$$; fails=$((fails + 1))
    else
        pass=$((pass + 1))
    fi
}
check_says() {  # check_says NAME EXPECTED_RC TEXT COMMAND...: exit code and TEXT in the output
    local name=$1 want=$2 text=$3
    shift 3
    "$@" >/tmp/lamina-cli-out.$$ 2>&1
    local rc=$?
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL $name: exit $rc, wanted $want"; cat /tmp/lamina-cli-out.$$; fails=$((fails + 1))
    elif ! grep -qF -- "$text" /tmp/lamina-cli-out.$$; then
        echo "FAIL $name: output lacks '$text':"; cat /tmp/lamina-cli-out.$$; fails=$((fails + 1))
    else
        pass=$((pass + 1))
    fi
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp" /tmp/lamina-cli-out.$$' EXIT

check version 0 "$lamina" --version
# --version names the SIMD kernel's instruction set, after LAMINA_SIMD_TARGET's cap; a name that
# is not one of the build's is refused by name.
if [ "$(uname -m)" = x86_64 ]; then  # SSE4 is compiled into every x86-64 build
    check_says version-simd 0 "SIMD kernel: SSE4" env LAMINA_SIMD_TARGET=SSE4 "$lamina" --version
fi
check_says version-simd-unknown 1 "LAMINA_SIMD_TARGET" env LAMINA_SIMD_TARGET=MMX "$lamina" --version
check help 0 "$lamina" --help
check_says no-subcommand 1 "lamina: command line: a subcommand is required, one of: validate," "$lamina"
# CLI11's own errors exit like lamina's: one "lamina: command line: OPTION: ..." line, exit code 1.
check_says cli11-unknown-subcommand 1 "lamina: command line: unknown subcommand 'frobnicate'; known: validate" \
    "$lamina" frobnicate
check_says cli11-unknown-option 1 "lamina: command line: --bogus: unknown option; see \`lamina simulate --help\`" \
    "$lamina" simulate "$src/examples/plastic.json" --bogus --out "$tmp/never"
check_says cli11-unknown-option-first 1 "lamina: command line: --bogus: unknown option" \
    "$lamina" simulate --bogus
check_says compare-one-particle 1 "lamina: command line: --particles: 1 is too few: a study simulates each incidence in two halves" \
    "$lamina" compare "$src/examples/plastic.json" --particles 1 --out "$tmp/never"
check_says out-empty 1 "lamina: command line: --out: the output folder is an empty path" \
    "$lamina" simulate "$src/examples/plastic.json" --particles 100 --out ''
check_says cli11-missing-value 1 "lamina: command line: --model: expects a value (text) after it" \
    "$lamina" eval --model
check_says cli11-given-twice 1 "lamina: command line: --particles: given 2 times; it takes one value, given once" \
    "$lamina" simulate "$src/examples/plastic.json" --particles 1e3 --particles 2e3 --out "$tmp/never"
check_says cli11-not-a-number 1 "lamina: command line: --theta-o: 'abc' is not a number" \
    "$lamina" eval --model ww09 --stack "$src/examples/plastic.json" --theta-i 30 --theta-o abc --phi-o 0
# OMP_NUM_THREADS far past the 1024 threads lamina runs crashed OpenMP's runtime (a segmentation
# fault); it is capped, with a warning, and the tables are those of any other thread count.
check_says omp-threads-capped 0 "OpenMP asked for 100000 threads (OMP_NUM_THREADS); running at most 1024" \
    env OMP_NUM_THREADS=100000 "$lamina" simulate "$src/examples/plastic.json" --particles 1e3 \
    --theta-i 0 --grid 9x9 --out "$tmp/omp-many"
check omp-threads-one 0 env OMP_NUM_THREADS=1 "$lamina" simulate "$src/examples/plastic.json" \
    --particles 1e3 --theta-i 0 --grid 9x9 --out "$tmp/omp-one"
check omp-threads-same-table 0 cmp "$tmp/omp-many/brdf.csv" "$tmp/omp-one/brdf.csv"
# One walk has no standard error (it printed 0).
check_says eval-one-walk 1 "--samples: '1' is not allowed: expected a whole number in [2, 1000000000]" \
    "$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --theta-i 30 \
    --theta-o 30 --phi-o 0 --samples 1
# Counts and seeds are read as the settings' whole numbers: a negative one is refused (not wrapped
# modulo 2^64), and one beyond the type names the range.
check_says cli11-negative-count 1 "lamina: command line: --samples: '-5' is not allowed: expected a whole number in [2, 1000000000]" \
    "$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --samples -5
check_says eval-seed-beyond-uint64 1 "lamina: command line: --seed: '18446744073709551616' is not allowed: expected a whole number in [1, 18446744073709551615]" \
    "$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --seed 18446744073709551616
check_says cli11-zero-seed 1 "lamina: command line: --seed: '0' is not allowed: expected a whole number ≥ 1" \
    "$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --seed 0
check_says cli11-fraction 1 "lamina: command line: --seed: '1.5' is not allowed: expected a whole number in [1, 1000000000000000]" \
    "$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --seed 1.5
check_says render-negative-seed 1 "lamina: command line: --seed: '-1' is not allowed: expected a whole number in [0, 18446744073709551615]" \
    "$lamina" render "$src/examples/plastic.json" --seed -1 --out "$tmp/never.png"
check_says cli11-range 1 "lamina: command line: --size: '5' is not allowed: expected a whole number in [8, 8192]" \
    "$lamina" render "$src/examples/plastic.json" --size 5 --out "$tmp/never.png"
check_says cli11-required 1 "lamina: command line: --stack: required; see \`lamina eval --help\`" \
    "$lamina" eval --model ww09
check_says cli11-extra 1 "lamina: command line: b.json: unexpected argument" \
    "$lamina" simulate a.json b.json --out "$tmp/never"
check_says particles-negative 1 "lamina: command line: --particles: '-5' is not allowed" \
    "$lamina" simulate "$src/examples/plastic.json" --particles -5 --out "$tmp/never"
check_says theta-not-a-number 1 "lamina: command line: --theta-i: 'abc' is not a number" \
    "$lamina" simulate "$src/examples/plastic.json" --theta-i abc --out "$tmp/never"
check no-output-on-error 1 test -e "$tmp/never"
check help-still-works 0 "$lamina" eval --help
# Angles and values past their ranges are refused by name, never evaluated into NaN or infinity.
P="$src/examples/plastic.json"
check_says eval-phi-o-huge 1 "--phi-o: 1e+308 degrees is outside [-360, 360]" \
    "$lamina" eval --model ww09 --stack "$P" --theta-i 30 --theta-o 30 --phi-o 1e308
check_says eval-theta-o-nan 1 "--theta-o: 'nan' is not a number" \
    "$lamina" eval --model ww09 --stack "$P" --theta-i 30 --theta-o nan --phi-o 0
printf 'theta_i,theta_o,phi_o,side\n30,30,1e308,R\n' >"$tmp/far.csv"
check_says eval-directions-phi-o 1 "line 2, phi_o: 1e+308 degrees is outside [-360, 360]" \
    "$lamina" eval --model ww09 --stack "$P" --directions "$tmp/far.csv" --out "$tmp/far-out.csv"
check eval-directions-writes-nothing 1 test -e "$tmp/far-out.csv"
check_says eval-binned-theta-o 1 "--theta-o: --binned covers every outgoing direction" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30 --theta-o 30 --out "$tmp/b.csv"
check_says eval-point-out 1 "--out: a point evaluation prints its value" \
    "$lamina" eval --model ww09 --stack "$P" --theta-i 30 --theta-o 30 --phi-o 0 --out "$tmp/p.csv"
check_says eval-option-twice 1 "option 'refraction-normal' of model 'ww09' given twice (n, then h)" \
    "$lamina" eval --model ww09:refraction-normal=n --option refraction-normal=h --stack "$P" \
    --theta-i 30 --theta-o 30 --phi-o 0
# An option the mode has no use for is refused, not ignored.
check_says eval-binned-side 1 "--side: --binned tabulates every side the model supports" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30 --side T --out "$tmp/b.csv"
check_says eval-directions-side 1 "--side: the directions file gives each row's side" \
    "$lamina" eval --model ww09 --stack "$P" --directions "$tmp/far.csv" --side R --out "$tmp/d.csv"
check_says eval-point-grid 1 "--grid: the bins are for --binned" \
    "$lamina" eval --model ww09 --stack "$P" --theta-i 30 --theta-o 30 --phi-o 0 --grid 9x9
check_says render-exposure-nan 1 "--exposure: nan stops is outside [-40, 40]" \
    "$lamina" render "$P" --size 8 --spp 1 --exposure nan --out "$tmp/never.png"
check_says render-light-huge 1 "--light: irradiance must be in [0, 1e+06]" \
    "$lamina" render "$P" --size 8 --spp 1 --light 0,0,1,1e40 --out "$tmp/never.png"
check no-render-on-error 1 test -e "$tmp/never.png"
# A far direction is only scaled: the light is the same as from (0, 0, 1), bit for bit.
check render-light-far 0 "$lamina" render "$P" --size 8 --spp 1 --threads 1 --env dark \
    --light 0,0,1e200,2 --out "$tmp/far.png"
check render-light-near 0 "$lamina" render "$P" --size 8 --spp 1 --threads 1 --env dark \
    --light 0,0,1,2 --out "$tmp/near.png"
check render-light-scaled 0 cmp "$tmp/far.exr" "$tmp/near.exr"
# At most 1024 threads (OpenMP creates them at once: 65 536 crashed its runtime).
check_says simulate-threads-huge 1 "--threads" \
    "$lamina" simulate "$P" --threads 65536 --particles 1000 --out "$tmp/threads"
check simulate-threads-writes-nothing 1 test -e "$tmp/threads"
check_says render-threads-huge 1 "--threads" \
    "$lamina" render "$P" --size 8 --spp 1 --threads 65536 --out "$tmp/never.png"
# Each incidence once (a table holds one block per incidence), in every command; no empty item.
check_says simulate-theta-twice 1 "--theta-i: 30 degrees is given twice" \
    "$lamina" simulate "$P" --theta-i 30,30 --particles 1000 --out "$tmp/twice"
check simulate-theta-twice-writes-nothing 1 test -e "$tmp/twice"
check_says eval-theta-twice 1 "--theta-i: 30 degrees is given twice" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30,30 --out "$tmp/twice.csv"
check_says simulate-theta-trailing-comma 1 "--theta-i: the list ends with a comma" \
    "$lamina" simulate "$P" --theta-i 30, --particles 1000 --out "$tmp/twice"
# --mueller's refusals come before the output folder is made.
check_says mueller-unpolarized 1 "--mueller: needs --polarization on" \
    "$lamina" simulate "$P" --mueller --polarization off --particles 1000 --out "$tmp/mueller-off"
check mueller-unpolarized-writes-nothing 1 test -e "$tmp/mueller-off"
check_says mueller-spectral 1 "Mueller tables are tabulated per RGB channel" \
    "$lamina" simulate "$P" --mueller --spectral on --particles 1000 --out "$tmp/mueller-spectral"
check mueller-spectral-writes-nothing 1 test -e "$tmp/mueller-spectral"
# Tallies that cannot fit in memory are refused before any work (a bad_alloc among the threads
# aborted the process), and the folder the run made is gone again.
check_says grid-beyond-memory 1 "--grid: 3600x3600 unfolded: its tallies need about" \
    "$lamina" simulate "$P" --theta-i 30 --phi-i 10 --particles 1 --threads 1024 --grid 3600x3600 \
    --out "$tmp/huge"
check grid-beyond-memory-writes-nothing 1 test -e "$tmp/huge"
# A NUL byte ended the JSON text for the parser: what followed it was ignored. Refused, in a stack
# file and in a study's configurations; so is a configuration's duplicate key, as in a stack.
printf '{"layers":[{"interface":{"type":"lambertian","albedo":0.5}}]}\0garbage{{' >"$tmp/nul.json"
check_says stack-nul 1 "nul.json: malformed JSON: a NUL byte at offset 61" "$lamina" validate "$tmp/nul.json"
printf '{"configurations":[{"id":"a","id":"b","stack":{"layers":[{"interface":{"type":"lambertian","albedo":0.5}}]}}]}' \
    >"$tmp/dupkey.json"
check_says configs-duplicate-key 1 '/configurations/0/id: duplicate key "id"' \
    "$lamina" study --configs "$tmp/dupkey.json" --particles 1000 --theta-i 30 --grid 6x6 \
    --models ww09 --out "$tmp/dupkey-study"
check configs-duplicate-key-writes-nothing 1 test -e "$tmp/dupkey-study"
# An id names folders and cache files (a file name holds 255 bytes): a longer one is refused
# before the reference is simulated.
long_id=$(printf 'a%.0s' $(seq 1 300))
printf '{"configurations":[{"id":"%s","stack":{"layers":[{"interface":{"type":"lambertian","albedo":0.5}}]}}]}' \
    "$long_id" >"$tmp/longid.json"
check_says configs-long-id 1 "is 300 bytes long; allowed: at most 128" \
    "$lamina" study --configs "$tmp/longid.json" --particles 1000 --theta-i 30 --grid 6x6 \
    --models ww09 --out "$tmp/longid-study"
check configs-long-id-writes-nothing 1 test -e "$tmp/longid-study"
# The configurations file is read as a stack file is: bounded, and a stream without end refused.
check_says configs-stream-refused 1 "the configurations file holds more than 16 MiB (it is not a regular file)" \
    "$lamina" study --configs /dev/zero --particles 1000 --theta-i 30 --grid 6x6 --models ww09 \
    --out "$tmp/zero-study"
check_says configs-folder-refused 1 "cannot read the configurations file: it is a directory" \
    "$lamina" study --configs "$tmp" --particles 1000 --theta-i 30 --grid 6x6 --models ww09 \
    --out "$tmp/folder-study"
# An interrupted run (Ctrl-C, a kill) leaves no staging folder, nor the output folder it made, nor
# the parents of it that it made.
timeout -s INT 1 "$lamina" simulate "$src/examples/milky-coat.json" --theta-i 0,20,40,60,80 \
    --particles 2e6 --threads 1 --kernel scalar --out "$tmp/interrupted/a/b" >/dev/null 2>&1
check interrupted-leaves-nothing 1 test -e "$tmp/interrupted"
timeout -s TERM 2 "$lamina" render "$src/examples/plastic.json" --compare --size 256 --spp 256 \
    --threads 1 --out "$tmp/interrupted-compare/sheet" >/dev/null 2>&1
check interrupted-compare-leaves-nothing 1 test -e "$tmp/interrupted-compare"
mkdir -p "$tmp/interrupted-kept"
timeout -s TERM 1 "$lamina" simulate "$src/examples/milky-coat.json" --theta-i 0,20,40,60,80 \
    --particles 2e6 --threads 1 --kernel scalar --out "$tmp/interrupted-kept" >/dev/null 2>&1
check interrupted-keeps-its-folder-empty 0 test -z "$(ls -A "$tmp/interrupted-kept")"
# The particle count is at most 10^15 however it is written.
check_says particles-beyond-limit 1 "expected a whole number in [1, 1000000000000000]" \
    "$lamina" simulate "$P" --particles 9223372036854775808 --theta-i 30 --out "$tmp/many"
# Control characters from the input (a NUL or a line break in a key) are escaped: one whole line.
printf '%s' '{"layers\u0000": [], "layers": [{"interface": {"type": "lambertian", "albedo": 1}}]}' \
    >"$tmp/nul-key.json"
check_says nul-key-escaped 1 'unknown key "layers\u0000" in the stack; did you mean "layers"?' \
    "$lamina" validate "$tmp/nul-key.json"
printf '%s' '{"alp\nha": 1, "layers": [{"interface": {"type": "lambertian", "albedo": 1}}]}' \
    >"$tmp/newline-key.json"
check_says newline-key-escaped 1 '/alp\nha: unknown key "alp\nha" in the stack' \
    "$lamina" validate "$tmp/newline-key.json"
# A film beside an anisotropic interface is refused by the stack format itself.
printf '%s' '{"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": [0.1, 0.2],
  "film": {"thickness_nm": 100, "eta": 1.4}}}, {"interface": {"type": "lambertian", "albedo": 1}}]}' \
    >"$tmp/film-aniso.json"
check_says validate-film-anisotropic 1 "/layers/0/interface/film: a thin film on a stack with an anisotropic interface" \
    "$lamina" validate "$tmp/film-aniso.json"
# A whole number given as an integer takes its type's whole range, and beyond it says that range
# (not the 1e15 of the decimal notation, which 2^64 - 1 itself exceeds).
check_says seed-beyond-uint64 1 "expected a whole number in [0, 18446744073709551615]" \
    "$lamina" simulate "$P" --seed 18446744073709551616 --particles 100 --theta-i 30 --out "$tmp/seed"
# An --out that cannot be written is named, with the reason, before any work.
: >"$tmp/afile"
check_says render-out-under-file 1 "afile: --out: cannot create the output folder" \
    "$lamina" render "$P" --size 8 --spp 1 --out "$tmp/afile/x.png"
check_says eval-out-under-file 1 "$tmp/afile/x.csv: cannot write it: $tmp/afile is not a folder" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30 --grid 9x9 --out "$tmp/afile/x.csv"
mkdir -p "$tmp/adir.csv"
check_says eval-out-is-folder 1 "adir.csv: cannot write it: a folder of that name is there" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30 --grid 9x9 --out "$tmp/adir.csv"
# A pipe, device or link at --out would be replaced by the finished file: refused.
mkfifo "$tmp/fifo.csv"
check_says eval-out-is-fifo 1 "fifo.csv: cannot write it: it is not a regular file" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30 --grid 9x9 --out "$tmp/fifo.csv"
check eval-out-fifo-kept 0 test -p "$tmp/fifo.csv"
ln -s "$tmp/elsewhere.csv" "$tmp/link.csv"
check_says eval-out-is-link 1 "link.csv: cannot write it: it is not a regular file" \
    "$lamina" eval --model ww09 --stack "$P" --binned --theta-i 30 --grid 9x9 --out "$tmp/link.csv"
# A directions file without end is refused without being read into memory; one with a NUL byte
# (whose rows after it were dropped) is no CSV.
check_says eval-directions-endless 1 "/dev/zero: the directions file holds more than 16 MiB" \
    "$lamina" eval --model ww09 --stack "$P" --directions /dev/zero --out "$tmp/dz.csv"
printf 'theta_i,theta_o,phi_o,side\n30,30,180,R\n\0\n' >"$tmp/dnul.csv"
check_says eval-directions-nul 1 "dnul.csv: a NUL byte at offset" \
    "$lamina" eval --model ww09 --stack "$P" --directions "$tmp/dnul.csv" --out "$tmp/dnul-out.csv"
# A row with a trailing comma has an empty fifth cell: refused, not written with its columns
# shifted.
printf 'theta_i,theta_o,phi_o,side\n30,30,180,R,\n' >"$tmp/dcomma.csv"
check_says eval-directions-trailing-comma 1 "dcomma.csv: line 2: expected 4 columns, found 5" \
    "$lamina" eval --model ww09 --stack "$P" --directions "$tmp/dcomma.csv" --out "$tmp/dc-out.csv"
# The random walk is not tabulated by quadrature (its noise would drive the adaptive rule without
# end): eval --binned, compare, export say so.
check_says eval-binned-random-walk 1 "--model: random-walk is a stochastic estimator" \
    "$lamina" eval --model random-walk --stack "$P" --binned --theta-i 30 --grid 1x1 --out "$tmp/rw.csv"
check_says compare-random-walk 1 "--models: random-walk is a stochastic estimator" \
    "$lamina" compare "$P" --models random-walk --theta-i 30 --particles 100 --grid 3x4 \
    --tables none --no-figures --out "$tmp/crw"
check_says export-random-walk 1 "--model: random-walk is a stochastic estimator" \
    "$lamina" export --model random-walk --stack "$P" --grid 2x2 --theta-i 30 --out "$tmp/rw.npz"
# The random walk on a stack it does not represent (a film) says that, whatever else is asked.
printf 'theta_i,theta_o,phi_o,side\n30,30,180,R\n' >"$tmp/d1.csv"
check_says eval-random-walk-unsupported 1 "not supported" \
    "$lamina" eval --model random-walk --stack "$src/examples/filmed-plastic.json" \
    --directions "$tmp/d1.csv" --out "$tmp/d1-out.csv" --samples 64
check_says eval-samples-bound 1 "--samples: '18446744073709551615' is not allowed" \
    "$lamina" eval --model random-walk --stack "$P" --theta-i 30 --theta-o 30 --phi-o 180 \
    --samples 18446744073709551615
# A stack's default name is its file's: a line break in the file name is shown as '_'.
printf '{"layers": [{"interface": {"type": "lambertian", "albedo": 0.5}}]}' >"$tmp/two
lines.json"
check_says validate-name-from-file 0 "two_lines" "$lamina" validate "$tmp/two
lines.json"
# Two sources of one name are refused; a pipe in place of a study's file is refused by name, not
# opened (opening it would wait for a writer).
check_says compare-model-twice 1 "--models: 'ww09' is given twice" \
    "$lamina" compare "$P" --models ww09,ww09 --theta-i 30 --particles 100 --out "$tmp/cdup"
mkdir -p "$tmp/fifo-study" && mkfifo "$tmp/fifo-study/study.json"
check_says explorer-pipe 1 "study.json: cannot read the study's description: it is not a regular file" \
    timeout 60 "$lamina" explorer "$tmp/fifo-study"
# A --configs category may not take a summary group's name, nor differ from another in case only.
printf '{"configurations": [{"id": "a", "category": "all BTDF", "stack": {"layers": [{"interface": {"type": "lambertian", "albedo": 0.5}}]}}]}' >"$tmp/cat-group.json"
check_says study-category-group 1 "/configurations/0/category: 'all BTDF' is one of the summary's group names" \
    "$lamina" study --configs "$tmp/cat-group.json" --out "$tmp/cat-group"
printf '{"configurations": [{"id": "a", "category": "x", "stack": {"layers": [{"interface": {"type": "lambertian", "albedo": 0.5}}]}}, {"id": "b", "category": "X", "stack": {"layers": [{"interface": {"type": "lambertian", "albedo": 0.5}}]}}]}' >"$tmp/cat-case.json"
check_says study-category-case 1 "/configurations/1/category: 'X' differs from the category 'x' in case only" \
    "$lamina" study --configs "$tmp/cat-case.json" --out "$tmp/cat-case"
# A stack file without end, or past 16 MiB, is refused without being read to its end.
check_says validate-endless 1 "/dev/zero: the stack file holds more than 16 MiB" "$lamina" validate /dev/zero
check_says export-check-endless 1 "/dev/zero: the file holds more than 16 MiB (it is not a regular file)" \
    "$lamina" export --check /dev/zero
# A table read back (--model-table) holds BSDF values: ≥ 0 and below 1e12 (1/sr).
"$lamina" eval --model ww09 --stack "$P" --binned --grid 9x9 --theta-i 30 --out "$tmp/mt.csv"
awk -F, 'BEGIN { OFS = "," } NR == 2 { $7 = "1e308" } { print }' "$tmp/mt.csv" >"$tmp/mt-huge.csv"
check_says model-table-huge 1 "line 2, column 7: the value 1e+308 is outside [-1e+12, 1e+12]" \
    "$lamina" compare "$P" --particles 1000 --theta-i 30 --grid 9x9 --models ww09 \
    --model-table "fit=$tmp/mt-huge.csv" --out "$tmp/mt-compare"
# A model table that does not fit the comparison is refused before the reference is simulated
# (10¹⁰ particles would take far past the timeout).
check_says model-table-before-work 1 "the table's incidences are 30 but the study's are 30,45" \
    timeout 60 "$lamina" compare "$P" --particles 1e10 --theta-i 30,45 --grid 9x9 --models ww09 \
    --model-table "fit=$tmp/mt.csv" --out "$tmp/mt-compare-early"
# A configuration's id and category become folder names and CSV cells: no commas or quotes.
printf '{"configurations": [{"id": "a", "category": "x,y", "stack": {"layers": [{"interface": {"type": "lambertian", "albedo": 0.5}}]}}]}' >"$tmp/comma.json"
check_says configs-category-comma 1 "/configurations/0/category: 'x,y' is not usable as a category" \
    "$lamina" study --configs "$tmp/comma.json" --particles 1000 --theta-i 30 --grid 9x9 --out "$tmp/comma"
check configs-category-writes-nothing 1 test -e "$tmp/comma"
# A category names the figures' files (albedo-<category>.png): a path in it would write outside
# the study folder. An id may not be the explorer's `index`, nor differ from another in case only.
lambert='{"layers": [{"interface": {"type": "lambertian", "albedo": 0.5}}]}'
for bad in '../../escaped' 'a/b' ' ' '.hidden'; do
    printf '{"configurations": [{"id": "a", "category": "%s", "stack": %s}]}' "$bad" "$lambert" >"$tmp/cat.json"
    check_says "configs-category-path '$bad'" 1 "/configurations/0/category: '$bad' is not usable as a category" \
        "$lamina" study --configs "$tmp/cat.json" --particles 1000 --theta-i 30 --grid 9x9 --out "$tmp/cat"
done
printf '{"configurations": [{"id": "Index", "stack": %s}]}' "$lambert" >"$tmp/index.json"
check_says configs-id-index 1 "/configurations/0/id: 'Index' is reserved" \
    "$lamina" study --configs "$tmp/index.json" --particles 1000 --theta-i 30 --grid 9x9 --out "$tmp/cat"
printf '{"configurations": [{"id": "a", "stack": %s}, {"id": "A", "stack": %s}]}' "$lambert" "$lambert" >"$tmp/case.json"
check_says configs-id-case 1 "/configurations/1/id: 'A' appears twice (ids that differ only in case" \
    "$lamina" study --configs "$tmp/case.json" --particles 1000 --theta-i 30 --grid 9x9 --out "$tmp/cat"
check configs-category-path-writes-nothing 1 test -e "$tmp/cat"

# validate: every example is valid and described on one line.
for example in "$src"/examples/*.json; do
    check_says "validate $(basename "$example")" 0 " | " \
        "$lamina" validate "$example"
done
check_says validate-describes 0 "plastic: air | dielectric η=1.5 α=0.2 | medium τa=(0.1, 0, 0.9)" \
    "$lamina" validate "$src/examples/plastic.json"
check_says validate-slab 0 "transmits" "$lamina" validate "$src/examples/slab.json"
check_says validate-scattering 0 "τs=0.5 g=0.3" "$lamina" validate "$src/examples/milky-coat.json"
# A τs spectrum that is 0 at the channels' wavelengths still scatters (at 400 nm): it is described.
printf '{"layers": [{"interface": {"type": "dielectric", "eta": 1, "alpha": 0}, "medium": {"tau_s": {"spectrum": [[360, 0], [400, 5], [440, 0], [830, 0]]}}}, {"interface": {"type": "lambertian", "albedo": 0}}]}' >"$tmp/ts-spectrum.json"
check_says validate-scattering-spectrum 0 "medium τa=0 τs=" "$lamina" validate "$tmp/ts-spectrum.json"
check_says validate-no-file 1 "lamina: command line: STACK: required" "$lamina" validate

# validate: each kind of bad input fails and the message names the field.
bad() {  # bad NAME FIELD_TEXT JSON: validate must fail and say FIELD_TEXT
    printf '%s\n' "$3" >"$tmp/$1.json"
    check_says "validate-bad-$1" 1 "$tmp/$1.json: $2" "$lamina" validate "$tmp/$1.json"
}
coat='{"type": "dielectric", "eta": 1.5, "alpha": 0.1}'
base='{"interface": {"type": "lambertian", "albedo": 0.8}}'
bad malformed 'malformed JSON: parse error at line 2' '{"layers": [
  {"interface" {"type": "lambertian"}}]}'
bad not-object 'a stack file must hold a JSON object' '[1, 2, 3]'
bad unknown-key '/layers/0/interface/alpah: unknown key "alpah"' \
    '{"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpah": 0.1}}]}'
bad unknown-top-key '/layer: unknown key "layer" in the stack; did you mean "layers"?' \
    "{\"layer\": [$base]}"
bad unknown-medium-key '/layers/0/medium/tau: unknown key' \
    "{\"layers\": [{\"interface\": $coat, \"medium\": {\"tau\": 1}}, $base]}"
bad duplicate-key '/layers/0/interface/albedo: duplicate key' \
    '{"layers": [{"interface": {"type": "lambertian", "albedo": 0.8, "albedo": 0.5}}]}'
bad wrong-type '/layers/0/interface/eta: expected a number' \
    '{"layers": [{"interface": {"type": "dielectric", "eta": "1.5", "alpha": 0.1}}]}'
bad rgb-length '/layers/0/interface/albedo: expected a number or an array of 3 numbers' \
    '{"layers": [{"interface": {"type": "lambertian", "albedo": [0.8, 0.2]}}]}'
bad overflow '/layers/0/medium/tau_a/1: number overflow parsing '"'"'1e999'"'" \
    "{\"layers\": [{\"interface\": $coat, \"medium\": {\"tau_a\": [0, 1e999, 0]}}, $base]}"
bad eta '/layers/0/interface/eta: got -1.5; allowed: [1, 5]' \
    '{"layers": [{"interface": {"type": "dielectric", "eta": -1.5, "alpha": 0.1}}]}'
bad eta-rgb '/layers/0/interface/eta: a dielectric'"'"'s eta must be a single number' \
    '{"layers": [{"interface": {"type": "dielectric", "eta": [1.5, 1.5, 1.5], "alpha": 0.1}}]}'
bad ambient-eta '/ambient_eta: got 0; allowed: [1, 5]' "{\"ambient_eta\": 0, \"layers\": [$base]}"
bad alpha '/layers/0/interface/alpha: got 1.5; allowed: 0 (smooth) or [0.0001, 1]' \
    '{"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 1.5}}]}'
bad alpha-missing '/layers/0/interface/alpha: missing required key "alpha"' \
    '{"layers": [{"interface": {"type": "conductor", "eta": 0.2, "k": 3}}]}'
bad tau '/layers/0/medium/tau_s: got -0.5; allowed: [0, 10000]' \
    "{\"layers\": [{\"interface\": $coat, \"medium\": {\"tau_s\": -0.5}}, $base]}"
bad g '/layers/0/medium/g: got 1; allowed: [-0.99, 0.99]' \
    "{\"layers\": [{\"interface\": $coat, \"medium\": {\"g\": 1}}, $base]}"
bad albedo '/layers/0/interface/albedo/0: got 1.2; allowed: [0, 1]' \
    '{"layers": [{"interface": {"type": "lambertian", "albedo": [1.2, 0.2, 0.1]}}]}'
bad k '/layers/0/interface/k/2: got -3; allowed: [0, 10]' \
    '{"layers": [{"interface": {"type": "conductor", "eta": 0.2, "k": [3, 3, -3], "alpha": 0}}]}'
bad interface-type '/layers/0/interface/type: unknown interface type "metal"' \
    '{"layers": [{"interface": {"type": "metal", "eta": 0.2, "k": 3, "alpha": 0}}]}'
bad opaque-not-last '/layers/0/interface/type: a lambertian interface is opaque and must be the last' \
    "{\"layers\": [$base, {\"interface\": $coat}]}"
bad medium-under-base '/layers/1/medium: the last interface (the base) cannot have a medium' \
    "{\"layers\": [{\"interface\": $coat}, {\"interface\": $coat, \"medium\": {}}]}"
bad empty-layers '/layers: the stack has no layers' '{"layers": []}'
bad missing-layers '/layers: missing required key "layers"' '{"name": "nothing"}'
check_says validate-missing-file 1 "$tmp/no-such.json: cannot read the stack file: no such file" \
    "$lamina" validate "$tmp/no-such.json"

# validate: one line per valid file on stdout, one error per bad file on stderr, exit 1 if any failed.
"$lamina" validate "$src/examples/plastic.json" "$tmp/alpha.json" "$src/examples/slab.json" \
    "$tmp/no-such.json" >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ "$rc" -eq 1 ] && [ "$(wc -l <"$tmp/out")" -eq 2 ] && [ "$(wc -l <"$tmp/err")" -eq 2 ]; then
    pass=$((pass + 1))
else
    echo "FAIL validate-mixed: exit $rc, stdout and stderr:"; cat "$tmp/out" "$tmp/err"
    fails=$((fails + 1))
fi

# simulate: a small run writes the three documented files, with their headers.
check simulate-runs 0 "$lamina" simulate "$src/examples/slab.json" --theta-i 0,45 --particles 2e4 \
    --grid 9x9 --seed 3 --out "$tmp/sim"
for f in result.json brdf.csv energy.csv; do
    if [ -s "$tmp/sim/$f" ]; then pass=$((pass + 1)); else echo "FAIL simulate: no $f"; fails=$((fails + 1)); fi
done
check_says simulate-brdf-header 0 "theta_i,side,theta_lo,theta_hi,phi_lo,phi_hi,f_r,f_g,f_b,se_r,se_g,se_b" \
    head -1 "$tmp/sim/brdf.csv"
check_says simulate-energy-header 0 \
    "theta_i,channel,reflected,transmitted,absorbed_medium,absorbed_base,lost_microsurface,cut_off" \
    head -1 "$tmp/sim/energy.csv"
# 2 incidences × 2 sides × 81 bins + header; the slab transmits, so T rows are present.
check_says simulate-rows 0 "325" sh -c "wc -l <'$tmp/sim/brdf.csv'"
check_says simulate-has-T 0 "45,T,0,10,0,20" grep -m1 "^45,T," "$tmp/sim/brdf.csv"
# Thin films on dielectrics: the scalar kernel traces them; the SIMD kernel refuses, writing
# nothing; the default kernel (auto) picks the scalar one; a model says "not supported".
check simulate-film 0 "$lamina" simulate "$src/examples/coated-lens.json" --kernel scalar \
    --theta-i 0,60 --particles 2e4 --grid 9x9 --out "$tmp/film"
check_says simulate-film-wavelengths 0 '"wavelengths_nm"' cat "$tmp/film/result.json"
check_says simulate-film-simd 1 "has a thin film on a dielectric interface (/layers/0/interface/film), which the SIMD kernel does not trace (it traces films on conductors); give --kernel scalar" \
    "$lamina" simulate "$src/examples/soap-film.json" --kernel simd --theta-i 0 --particles 1000 \
    --out "$tmp/film-simd"
check film-simd-writes-nothing 1 test -e "$tmp/film-simd"
check simulate-film-auto 0 "$lamina" simulate "$src/examples/coated-lens.json" \
    --theta-i 0,60 --particles 2e4 --grid 9x9 --out "$tmp/film-auto"
check simulate-film-auto-is-scalar 0 cmp "$tmp/film/brdf.csv" "$tmp/film-auto/brdf.csv"
check_says simulate-film-auto-ran-scalar 0 '"kernel_description": "scalar"' cat "$tmp/film-auto/result.json"
# A folder holds one run: a later run of another kind removes the spectral and Mueller tables it
# does not write (an RGB run's brdf.csv beside an earlier spectral run's spectral.npy read as one).
check reuse-spectral 0 "$lamina" simulate "$src/examples/gold-under-coat.json" --theta-i 30 \
    --particles 2000 --grid 5x6 --out "$tmp/reuse"
check reuse-spectral-wrote 0 test -e "$tmp/reuse/spectral_energy.csv"
check reuse-mueller 0 "$lamina" simulate "$src/examples/gold-under-coat.json" --theta-i 30 \
    --particles 2000 --grid 5x6 --spectral off --mueller --out "$tmp/reuse"
check reuse-mueller-removed-spectral 1 test -e "$tmp/reuse/spectral.npy"
check reuse-mueller-removed-xyz 1 test -e "$tmp/reuse/xyz_se.npy"
check reuse-mueller-wrote 0 test -e "$tmp/reuse/mueller_se.npy"
check reuse-rgb 0 "$lamina" simulate "$src/examples/gold-under-coat.json" --theta-i 30 \
    --particles 2000 --grid 5x6 --spectral off --out "$tmp/reuse"
check reuse-rgb-removed-mueller 1 test -e "$tmp/reuse/mueller.npy"
check reuse-rgb-kept-its-own 0 test -e "$tmp/reuse/brdf.csv"
# A film beside an anisotropic interface is not traced yet: simulate and compare refuse it naming
# the file and the film's JSON pointer, before they make the output folder.
printf '%s\n' '{"name": "n", "layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.1}},
  {"interface": {"type": "conductor", "eta": 0.2, "k": 3, "alpha": [0.1, 0.3], "film": {"thickness_nm": 300, "eta": 1.5}}}]}' \
    >"$tmp/film-brushed.json"
check_says simulate-film-anisotropic 1 "lamina: $tmp/film-brushed.json: /layers/1/interface/film: a thin film on a stack with an anisotropic interface (/layers/1/interface/alpha)" \
    "$lamina" simulate "$tmp/film-brushed.json" --theta-i 30 --particles 1000 --out "$tmp/film-brushed"
check_says compare-film-anisotropic 1 "lamina: $tmp/film-brushed.json: /layers/1/interface/film: a thin film" \
    "$lamina" compare "$tmp/film-brushed.json" --theta-i 30 --particles 1000 --models openpbr --out "$tmp/film-brushed"
check film-anisotropic-writes-nothing 1 test -e "$tmp/film-brushed"
check simulate-phi-i 0 "$lamina" simulate "$src/examples/plastic.json" --phi-i 30 --theta-i 40 \
    --particles 2e4 --grid 9x9 --out "$tmp/phi-i"
check_says export-unfolded 1 "an unfolded table" \
    "$lamina" export --simulation "$tmp/phi-i" --out "$tmp/phi-i.bsdf"
check export-unfolded-writes-nothing 1 test -e "$tmp/phi-i.bsdf"
check export-unfolded-npz 0 "$lamina" export --simulation "$tmp/phi-i" --out "$tmp/phi-i.npz"
# A result.json that is not a simulation's (not an object; an azimuth that is not one) is refused.
mkdir -p "$tmp/bad-result" && cp "$tmp/phi-i/brdf.csv" "$tmp/bad-result/"
echo '[]' >"$tmp/bad-result/result.json"
check_says export-result-not-object 1 "result.json: not a simulation's result.json" \
    "$lamina" export --simulation "$tmp/bad-result" --out "$tmp/never.npz"
echo '{"phi_i": "x"}' >"$tmp/bad-result/result.json"
check_says export-result-phi-i 1 'result.json: /phi_i: "x": the light'"'"'s azimuth in degrees' \
    "$lamina" export --simulation "$tmp/bad-result" --out "$tmp/never.npz"
check_says export-lamina1-tables-out 1 "--out: --lamina1-tables writes lamina-1's tables" \
    "$lamina" export --lamina1-tables "$tmp/never.bin" --out "$tmp/never.npz"
# An option the export has no use for is refused, not ignored.
check_says export-table-grid 1 "--grid: a table's bins are the ones it was computed on" \
    "$lamina" export --simulation "$tmp/phi-i" --grid 18x18 --out "$tmp/never.npz"
check_says export-table-theta-i 1 "--theta-i: a table's incidences are the ones it was computed at" \
    "$lamina" export --simulation "$tmp/phi-i" --theta-i 10 --out "$tmp/never.npz"
check_says export-bsdf-grid 1 "--grid: the bins of a model's .npz" \
    "$lamina" export --model ww09 --stack "$src/examples/plastic.json" --grid 9x9 --out "$tmp/never.bsdf"
check_says export-gpu-model 1 "--model: --lamina1-gpu writes lamina-1's state of --stack" \
    "$lamina" export --lamina1-gpu "$tmp/never.bin" --stack "$src/examples/plastic.json" --model ww-prime
check export-refusals-write-nothing 1 test -e "$tmp/never.npz" -o -e "$tmp/never.bsdf" -o -e "$tmp/never.bin"
check_says export-phi-i-bsdf 1 "goes with --format npz" \
    "$lamina" export --model openpbr --stack "$src/examples/brushed-aluminium-lacquer.json" \
    --phi-i 30 --out "$tmp/brushed.bsdf"
check_says export-anisotropic-merl 1 "holds an isotropic BRDF" \
    "$lamina" export --model openpbr --stack "$src/examples/brushed-aluminium-lacquer.json" \
    --out "$tmp/brushed.binary"
check export-anisotropic-merl-writes-nothing 1 test -e "$tmp/brushed.binary"
check_says eval-film 1 "not supported: thin films are not supported by this model" \
    "$lamina" eval --model ww09 --stack "$src/examples/coated-lens.json" --theta-i 30 --theta-o 30 --phi-o 180
# Spectral runs (docs/physics.md §10): a spectral stack is traced spectrally (auto) and writes its
# wavelength tables; its stack reads back from result.json as it was given. The SIMD kernel
# traces spectral runs, scattering media included (auto picks it).
check simulate-spectral 0 "$lamina" simulate "$src/examples/gold-under-coat.json" --theta-i 0 \
    --particles 2e4 --grid 9x6 --out "$tmp/spectral"
for f in spectral.npy spectral_se.npy xyz.npy xyz_se.npy spectral_energy.csv; do
    check "simulate-spectral-writes-$f" 0 test -s "$tmp/spectral/$f"
done
check_says simulate-spectral-material 0 '"material": "Au"' cat "$tmp/spectral/result.json"
# A spectral run's linear sRGB may be negative in a bin (docs/formats.md): its table is read back and
# exported (one value made negative here, as few particles in a bin can make it).
awk -F, 'BEGIN { OFS = "," } NR == 2 { $7 = "-0.00112" } { print }' "$tmp/spectral/brdf.csv" \
    >"$tmp/spectral/brdf.csv.new" && mv "$tmp/spectral/brdf.csv.new" "$tmp/spectral/brdf.csv"
check export-spectral-negative 0 "$lamina" export --simulation "$tmp/spectral" --out "$tmp/spectral.npz"
check export-spectral-negative-merl 0 "$lamina" export --simulation "$tmp/spectral" --out "$tmp/spectral.binary"
check_says simulate-spectral-simd 0 '"kernel_description": "simd' \
    sh -c "'$lamina' simulate '$src/examples/dispersive-glass.json' --kernel simd --theta-i 0 \
    --particles 1000 --out '$tmp/spectral-simd' > /dev/null && cat '$tmp/spectral-simd/result.json'"
check_says simulate-spectral-scattering-simd 0 '"kernel_description": "simd' \
    sh -c "'$lamina' simulate '$src/examples/milky-coat.json' --spectral on --theta-i 0 \
    --particles 1000 --out '$tmp/spectral-scattering' > /dev/null && cat '$tmp/spectral-scattering/result.json'"
check_says simulate-spectral-bins 1 "multiple of 3" "$lamina" simulate "$src/examples/plastic.json" \
    --spectral on --spectral-bins 10 --theta-i 0 --particles 1000 --out "$tmp/spectral-bins"
check_says simulate-spectral-bins-option 1 "command line: --spectral-bins: got 31" \
    "$lamina" simulate "$src/examples/plastic.json" --spectral on --spectral-bins 31 --theta-i 0 \
    --particles 1000 --out "$tmp/spectral-bins"
check_says simulate-spectral-reversed 1 "--spectral-max-nm: 400 nm is not above the shortest wavelength (700 nm)" \
    "$lamina" simulate "$src/examples/plastic.json" --spectral on --spectral-min-nm 700 \
    --spectral-max-nm 400 --theta-i 0 --particles 1000 --out "$tmp/spectral-bins"
check spectral-refusals-write-nothing 1 test -e "$tmp/spectral-bins"
# A model on a spectral stack: its linear sRGB from per-wavelength models (--spectral auto, as
# simulate's); the random walk stays in the RGB mode and says so when asked for spectra.
check eval-spectral 0 "$lamina" eval --model openpbr --stack "$src/examples/gold-under-coat.json" \
    --theta-i 30 --theta-o 30 --phi-o 180 --side R
check eval-spectral-binned 0 "$lamina" eval --model openpbr --binned --theta-i 0 --grid 9x6 \
    --stack "$src/examples/gold-under-coat.json" --out "$tmp/eval-spectral.csv"
check_says eval-spectral-random-walk 1 "the random walk evaluates the RGB mode" "$lamina" eval \
    --model random-walk --stack "$src/examples/gold-under-coat.json" --spectral on --theta-i 30 \
    --theta-o 30 --phi-o 180 --side R
check_says eval-spectral-range 1 "at least 3 nm wide" "$lamina" eval --model openpbr \
    --stack "$src/examples/gold-under-coat.json" --spectral-min-nm 500 --spectral-max-nm 501 \
    --theta-i 30 --theta-o 30 --phi-o 180 --side R
check_says validate-spectral 0 "| dielectric η=BK7 α=0.05" "$lamina" validate \
    "$src/examples/dispersive-glass.json"
check_says validate-film 0 "| conductor η=(0.143, 0.374, 1.442) k=(3.983, 2.385, 1.603) α=0.15 film d=[55, 75] nm η=2.4" \
    "$lamina" validate "$src/examples/titania-on-gold.json"
# Same seed, different thread counts: identical tables.
check simulate-threads 0 "$lamina" simulate "$src/examples/slab.json" --theta-i 0,45 --particles 2e4 \
    --grid 9x9 --seed 3 --threads 1 --out "$tmp/sim1"
check simulate-reproducible 0 cmp "$tmp/sim/brdf.csv" "$tmp/sim1/brdf.csv"

# Multiple scattering on the microsurfaces: result.json says so, nothing is lost there.
check simulate-multiple 0 "$lamina" simulate "$src/examples/frosted-gold.json" --theta-i 60 \
    --particles 2e4 --grid 9x9 --kernel scalar --microsurface multiple --out "$tmp/ms"
check_says simulate-multiple-json 0 '"microsurface": "multiple"' cat "$tmp/ms/result.json"
check_says simulate-multiple-lost 0 "60,r" awk -F, '$1 == 60 && $7 == 0 {print $1 "," $2}' "$tmp/ms/energy.csv"
# ... and on the SIMD kernel (the default), the same walk.
check simulate-multiple-simd 0 "$lamina" simulate "$src/examples/frosted-gold.json" --theta-i 60 \
    --particles 2e4 --grid 9x9 --microsurface multiple --out "$tmp/ms-simd"
check_says simulate-multiple-simd-json 0 '"microsurface": "multiple"' cat "$tmp/ms-simd/result.json"
check_says simulate-multiple-simd-lost 0 "60,r" awk -F, '$1 == 60 && $7 == 0 {print $1 "," $2}' "$tmp/ms-simd/energy.csv"

# The refraction masking of rough dielectrics: result.json names it (smith by default), and the
# pbrt form keeps more of the light a rough slab transmits (B(1 + Λi, 1 + Λo) < 1/(1 + Λi + Λo)).
check simulate-masking-pbrt 0 "$lamina" simulate "$src/examples/slab.json" --theta-i 80 \
    --particles 2e4 --grid 9x9 --transmission-masking pbrt --out "$tmp/pbrt"
check_says simulate-masking-default 0 '"transmission_masking": "smith"' cat "$tmp/sim/result.json"
check_says simulate-masking-json 0 '"transmission_masking": "pbrt"' cat "$tmp/pbrt/result.json"
check_says simulate-bad-masking 1 "--transmission-masking: 'walter' is not a transmission masking" \
    "$lamina" simulate "$src/examples/plastic.json" --transmission-masking walter --out "$tmp/bad1"
# Polarized transport (docs/physics.md §8): on by default with multiple scattering on the
# microsurfaces (the exact reference), which result.json says; --physics bpb19 is the 2019 study's
# reference and an explicit setting beside it wins; --mueller writes the Mueller tables (numpy
# .npy) and needs --polarization on; a bad value is refused.
check_says simulate-polarization-default 0 '"polarization": true' cat "$tmp/sim/result.json"
check_says simulate-physics-default 0 '"physics": "exact"' cat "$tmp/sim/result.json"
check simulate-bpb19 0 "$lamina" simulate "$src/examples/plastic.json" --theta-i 30 \
    --particles 1e4 --grid 9x9 --physics bpb19 --out "$tmp/bpb19"
check_says simulate-bpb19-json 0 '"microsurface": "single"' cat "$tmp/bpb19/result.json"
check_says simulate-bpb19-pol 0 '"polarization": false' cat "$tmp/bpb19/result.json"
check simulate-custom 0 "$lamina" simulate "$src/examples/plastic.json" --theta-i 30 \
    --particles 1e4 --grid 9x9 --microsurface multiple --physics bpb19 --out "$tmp/custom"
check_says simulate-custom-json 0 '"physics": "custom"' cat "$tmp/custom/result.json"
check_says simulate-bad-physics 1 "--physics: 'bpb18' is not a reference physics" \
    "$lamina" simulate "$src/examples/plastic.json" --physics bpb18 --out "$tmp/bad-physics"
check simulate-polarized 0 "$lamina" simulate "$src/examples/slab.json" --theta-i 30 \
    --particles 2e4 --grid 9x9 --polarization on --mueller --out "$tmp/pol"
check_says simulate-polarized-json 0 '"polarization": true' cat "$tmp/pol/result.json"
for f in mueller.npy mueller_se.npy; do
    if [ -s "$tmp/pol/$f" ]; then pass=$((pass + 1)); else echo "FAIL simulate: no $f"; fails=$((fails + 1)); fi
done
check_says simulate-mueller-npy 0 "'shape': (1, 2, 9, 9, 3, 4, 4)" head -c 128 "$tmp/pol/mueller.npy"
check_says simulate-mueller-needs-polarization 1 "--mueller: needs --polarization on" \
    "$lamina" simulate "$src/examples/plastic.json" --polarization off --mueller --out "$tmp/bad-mueller"
check_says simulate-bad-polarization 1 "--polarization" \
    "$lamina" simulate "$src/examples/plastic.json" --polarization maybe --out "$tmp/bad-pol"
check_says render-bad-masking 1 "--transmission-masking: 'walter' is not a transmission masking" \
    "$lamina" render "$src/examples/plastic.json" --transmission-masking walter --size 8 --spp 1 \
    --out "$tmp/bad1/x.png"

# simulate: bad arguments fail clearly and leave nothing behind.
check_says simulate-theta-90 1 "--theta-i: 90 is outside the allowed range [0, 90)" \
    "$lamina" simulate "$src/examples/plastic.json" --theta-i 90 --out "$tmp/bad1"
check_says simulate-theta-text 1 "--theta-i: 'abc' is not a number" \
    "$lamina" simulate "$src/examples/plastic.json" --theta-i abc --out "$tmp/bad1"
check_says simulate-zero-particles 1 "--particles: '0' is not allowed" \
    "$lamina" simulate "$src/examples/plastic.json" --particles 0 --out "$tmp/bad1"
check_says simulate-bad-grid 1 "--grid: '90by90' is not a grid" \
    "$lamina" simulate "$src/examples/plastic.json" --grid 90by90 --out "$tmp/bad1"
check_says simulate-bad-microsurface 1 "--microsurface: 'many' is not a microsurface model" \
    "$lamina" simulate "$src/examples/plastic.json" --microsurface many --kernel scalar --out "$tmp/bad1"
check_says simulate-bad-stack 1 "no-such.json" \
    "$lamina" simulate "$tmp/no-such.json" --out "$tmp/bad1"
if [ -e "$tmp/bad1" ]; then echo "FAIL simulate: a failed run left $tmp/bad1"; fails=$((fails + 1)); else pass=$((pass + 1)); fi
touch "$tmp/a-file"
check_says simulate-unwritable 1 "--out" \
    "$lamina" simulate "$src/examples/plastic.json" --particles 100 --out "$tmp/a-file/sub"
# eval --model random-walk: six numbers (f and its standard error), reproducible for a seed.
check_says eval-rw-six 0 "six" sh -c "'$lamina' eval --model random-walk --stack '$src/examples/plastic.json' --theta-i 30 --theta-o 45 --phi-o 180 --samples 2000 --seed 3 | awk '{ if (NF == 6) print \"six\"; else print \"wrong\" }' | grep -x six"
"$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --theta-i 30 --theta-o 45 --phi-o 180 --samples 2000 --seed 3 >"$tmp/rw1"
"$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --theta-i 30 --theta-o 45 --phi-o 180 --samples 2000 --seed 3 >"$tmp/rw2"
check eval-rw-reproducible 0 cmp "$tmp/rw1" "$tmp/rw2"
# eval --pdf: two numbers (the exit density and its standard error); a Lambertian's is cos/π exactly.
check_says eval-rw-pdf 0 "two" sh -c "'$lamina' eval --model random-walk --stack '$src/examples/plastic.json' --theta-i 30 --theta-o 45 --phi-o 180 --samples 2000 --seed 3 --pdf | awk '{ if (NF == 2 && \$1 > 0) print \"two\"; else print \"wrong\" }' | grep -x two"
check_says eval-pdf-analytic 1 "only the stochastic model random-walk" \
    "$lamina" eval --model ww-prime --stack "$src/examples/plastic.json" --theta-i 30 --theta-o 45 --phi-o 180 --pdf
check_says eval-samples-analytic 1 "only the stochastic model random-walk" \
    "$lamina" eval --model ww-prime --stack "$src/examples/plastic.json" --theta-i 30 --theta-o 45 --phi-o 180 --samples 10

# render: a PNG and an EXR; the comparison sheet; identical images for any thread count.
check render-png 0 "$lamina" render "$src/examples/plastic.json" --size 24 --spp 2 --threads 1 --out "$tmp/r1.png"
check render-exr 0 test -s "$tmp/r1.exr"
check render-threads 0 "$lamina" render "$src/examples/plastic.json" --size 24 --spp 2 --threads 2 --out "$tmp/r2.png"
check render-reproducible 0 cmp "$tmp/r1.exr" "$tmp/r2.exr"
check render-compare 0 "$lamina" render "$src/examples/metallic-paint.json" --compare --size 24 --spp 2 --out "$tmp/cmp"
check render-sheet 0 test -s "$tmp/cmp/compare.png"
check_says render-errors 0 "ww-prime," cat "$tmp/cmp/errors.csv"
# A second comparison into the same folder removes the images of the models that do not support
# its stack (a clear coat over glass: ww09 reflects only).
check render-compare-first-ww09 0 test -e "$tmp/cmp/ww09.png"
check render-compare-again 0 "$lamina" render "$src/examples/coated-lens.json" --compare --size 8 --spp 1 --out "$tmp/cmp"
check_says render-compare-again-errors 0 "ww09,not supported" cat "$tmp/cmp/errors.csv"
check render-compare-stale-removed 1 test -e "$tmp/cmp/ww09.png"
# --out NAME.exr (any case) writes NAME.png and NAME.exr.
check render-out-exr 0 "$lamina" render "$src/examples/plastic.json" --size 8 --spp 1 --out "$tmp/named.EXR"
check render-out-exr-png 0 test -e "$tmp/named.png"
check render-out-exr-exr 0 test -e "$tmp/named.exr"
# Multiple scattering on the microsurfaces: reproducible across thread counts too; bad values and
# other models refused.
check render-ms1 0 "$lamina" render "$src/examples/frosted-gold.json" --microsurface multiple --size 16 --spp 2 --threads 1 --out "$tmp/ms1.png"
check render-ms2 0 "$lamina" render "$src/examples/frosted-gold.json" --microsurface multiple --size 16 --spp 2 --threads 2 --out "$tmp/ms2.png"
check render-ms-reproducible 0 cmp "$tmp/ms1.exr" "$tmp/ms2.exr"
check_says render-ms-bad 1 "--microsurface: 'lots' is not a microsurface model" \
    "$lamina" render "$src/examples/plastic.json" --microsurface lots --size 8 --spp 1 --out "$tmp/ms3.png"
check_says render-ms-model 1 "applies to the random-walk reference only" \
    "$lamina" render "$src/examples/plastic.json" --model ww-prime --microsurface single --size 8 --spp 1 --out "$tmp/ms4.png"
check_says eval-ms-bad 1 "allowed: single, multiple" \
    "$lamina" eval --model random-walk --stack "$src/examples/plastic.json" --theta-i 30 --theta-o 45 --option microsurface=lots
check_says render-bad-env 1 "unknown environment" \
    "$lamina" render "$src/examples/plastic.json" --env moon --out "$tmp/r3.png"
check study-render 0 "$lamina" study --only 'plastic-P2-a0.05*' --particles 2e4 --grid 9x9 --theta-i 30 \
    --render --render-size 24 --render-spp 2 --out "$tmp/study-r"
check study-render-sheet 0 test -s "$tmp/study-r/configs/plastic-P2-a0.05/renders/compare.png"
check_says study-render-index 0 "plastic-P2-a0.05,ww-prime," cat "$tmp/study-r/renders.csv"
echo "$pass passed, $fails failed"
[ "$fails" -eq 0 ]
