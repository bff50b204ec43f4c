#!/usr/bin/env bash
# `mpirun -n 2 lamina simulate|study` against one process (docs/scaling.md): the outputs must be
# bitwise identical (timing fields aside), whatever the thread counts; an error on a rank must end
# the run with a message, not hang it. Usage: mpi_test.sh LAMINA SRC_DIR WITH_MPI
# Exits 77 (ctest: skipped) when mpirun is absent or lamina was built without MPI.
set -u
lamina=$1
src=$2
with_mpi=$3
case "$with_mpi" in
    1 | ON | TRUE | true) ;;
    *) echo "SKIP: lamina was built without MPI (LAMINA_MPI; make deps installs libopenmpi-dev)"; exit 77 ;;
esac
if ! command -v mpirun >/dev/null 2>&1; then
    echo "SKIP: mpirun not found (make deps installs openmpi-bin)"
    exit 77
fi
. "$(dirname "$0")/../support/script_lib.sh"
# As CI needs: root in a container, more processes than cores. `timeout`: a hang is a failure.
mpi() { timeout 120 mpirun -n 2 --allow-run-as-root --oversubscribe "$@"; }

same_files() {  # same_files NAME DIR_A DIR_B FILE...: byte for byte
    local name=$1 a=$2 b=$3
    shift 3
    for f in "$@"; do
        if [ ! -s "$a/$f" ]; then fail "$name: $a/$f missing"; continue; fi
        cmp -s "$a/$f" "$b/$f" && ok || fail "$name: $f differs between $a and $b"
    done
}

# 1. simulate: particle counts that are not multiples of 2 · 4096 (rank 0 gets 6 blocks of 50001's
#    13, rank 1 the other 7, the last one partial), and 3000 (one block: rank 1 traces nothing);
#    a reflecting stack and a transmitting one; one process with 2 threads and with 1.
for stack in plastic slab; do
    for n in 50001 3000; do
        args=("$src/examples/$stack.json" --theta-i 0,45,80 --particles "$n" --grid 18x18 --seed 7)
        one=$tmp/sim-$stack-$n-one
        "$lamina" simulate "${args[@]}" --threads 2 --out "$one" >"$one.log" 2>&1 \
            || { fail "one-process simulate $stack $n"; cat "$one.log"; }
        for mode in default threads1 threads2; do
            extra=()
            [ "$mode" = threads1 ] && extra=(--threads 1)
            [ "$mode" = threads2 ] && extra=(--threads 2)
            out=$tmp/sim-$stack-$n-$mode
            if mpi "$lamina" simulate "${args[@]}" "${extra[@]}" --out "$out" >"$out.log" 2>&1; then
                ok
            else
                fail "mpirun simulate $stack $n $mode"; cat "$out.log"
            fi
            same_files "simulate $stack n=$n $mode" "$one" "$out" brdf.csv energy.csv
            grep -q '"processes": 2' "$out/result.json" && ok || fail "$stack $n $mode: processes"
            # The summary lines once (rank 0 only).
            [ "$(grep -c 'particles/s on 2 processes' "$out.log")" -eq 1 ] && ok \
                || { fail "$stack $n $mode: summary not printed once"; cat "$out.log"; }
        done
        grep -q '"processes": 1' "$one/result.json" && ok || fail "$stack $n: processes 1"
    done
done
# one_and_two NAME "FILES" ARGS...: `simulate ARGS` in one process (2 threads) and on 2 ranks
# (1 thread each); FILES (space-separated) must be byte for byte the same.
one_and_two() {
    local name=$1 files=$2
    shift 2
    local one=$tmp/$name-one out=$tmp/$name-two
    "$lamina" simulate "$@" --threads 2 --out "$one" >"$one.log" 2>&1 \
        || { fail "one-process simulate $name"; cat "$one.log"; }
    mpi "$lamina" simulate "$@" --threads 1 --out "$out" >"$out.log" 2>&1 && ok \
        || { fail "mpirun simulate $name"; cat "$out.log"; }
    # shellcheck disable=SC2086  # FILES is a list
    same_files "simulate $name" "$one" "$out" $files
}
# The same with multiple scattering on the microsurfaces (the SIMD kernel's walk), on a rough slab
# and a rough conductor under a coat.
for stack in slab frosted-gold; do
    one_and_two "ms-$stack" "brdf.csv energy.csv" "$src/examples/$stack.json" --theta-i 0,60 \
        --particles 50001 --grid 18x18 --seed 7 --microsurface multiple
done
# An anisotropic stack and light from an azimuth: the unfolded grid (twice the φ bins), also on
# the rank that traces nothing (3000 particles: one block) and with the Mueller tables.
for n in 50001 3000; do
    one_and_two "aniso-$n" "brdf.csv energy.csv mueller.npy mueller_se.npy" \
        "$src/examples/brushed-aluminium-lacquer.json" --theta-i 30 --phi-i 40 --particles "$n" \
        --grid 9x12 --seed 7 --mueller
done
# The transmitting stack has a transmission lobe in its table.
grep -q ',T,' "$tmp/sim-slab-50001-one/brdf.csv" && ok || fail "slab: no transmission rows"

# 2. study: the reference pieces spread over 2 processes; rank 0 alone writes. Same folder name
#    in both runs (the explorer data names it). With the reference's Stokes vectors, which the
#    work list must ask the other rank for (reference_stokes.lza, the same bytes).
tiny=(--only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --models ww-prime,bel-prime
      --theta-i 0,60 --particles 5e4 --grid 18x18 --reference-stokes on --no-figures)
mkdir -p "$tmp/one" "$tmp/two"
"$lamina" study "${tiny[@]}" --out "$tmp/one/study" >"$tmp/study-one.log" 2>&1 \
    || { fail "one-process study"; cat "$tmp/study-one.log"; }
mpi "$lamina" study "${tiny[@]}" --out "$tmp/two/study" >"$tmp/study-two.log" 2>&1 \
    && ok || { fail "mpirun study"; cat "$tmp/study-two.log"; }
grep -q 'Reference: 4 pieces computed over 2 processes' "$tmp/study-two.log" && ok \
    || fail "study: reference not shared"
# What the run did counts the pieces the processes computed, as one process's run counts its own.
grep -q 'Work: 4 reference pieces simulated' "$tmp/study-one.log" \
    && grep -q 'Work: 4 reference pieces simulated' "$tmp/study-two.log" && ok \
    || { fail "study: the Work line misses the shared pieces"; grep Work "$tmp"/study-*.log; }
files=$(cd "$tmp/one/study" && find . -type f ! -name study.json ! -path './cache/*' | sort)
[ -n "$files" ] && ok || fail "study: no files"
echo "$files" | grep -q 'reference_stokes.lza' && ok || fail "study: no reference_stokes.lza"
# shellcheck disable=SC2086
same_files "study" "$tmp/one/study" "$tmp/two/study" $files
# study.json and the cached pieces differ only in their `seconds` (study.json: `reference_seconds`).
python3 - "$tmp/one/study" "$tmp/two/study" <<'EOF' && ok || fail "study.json or cached pieces"
import json, pathlib, sys
a, b = map(pathlib.Path, sys.argv[1:3])
def drop_seconds(j):
    j.pop("seconds", None)
    j.pop("reference_seconds", None)
    return j
assert drop_seconds(json.loads((a / "study.json").read_text())) == \
       drop_seconds(json.loads((b / "study.json").read_text()))
pieces = sorted(p.relative_to(a) for p in (a / "cache").rglob("*.bin"))
assert len(pieces) == 4, pieces
for p in pieces:
    ma, _, da = (a / p).read_bytes().partition(b"\n")[2].partition(b"\n")
    mb, _, db = (b / p).read_bytes().partition(b"\n")[2].partition(b"\n")
    assert da == db, f"{p}: tables differ"
    assert drop_seconds(json.loads(ma)) == drop_seconds(json.loads(mb)), f"{p}: header differs"
EOF
# A resumed distributed study finds every piece in rank 0's cache and computes none.
mpi "$lamina" study "${tiny[@]}" --out "$tmp/two/study" >"$tmp/study-again.log" 2>&1 \
    && grep -q 'Reference: 0 pieces computed' "$tmp/study-again.log" && ok \
    || { fail "resumed mpirun study"; cat "$tmp/study-again.log"; }
same_files "resumed study" "$tmp/one/study" "$tmp/two/study" metrics.csv

# A brushed configuration (anisotropic: unfolded, lit from φi = 0°, 45°, 90°): its pieces, keyed
# by φi, spread over the processes like any other; the outputs are one process's, byte for byte.
brushed=(--preset standard --only 'brushed-gold-a0.001-a1.05x.3-t30' --models openpbr
         --theta-i 0,45 --particles 2e4 --grid 18x18 --no-figures)
"$lamina" study "${brushed[@]}" --out "$tmp/one/brushed" >"$tmp/brushed-one.log" 2>&1 \
    || { fail "one-process brushed study"; cat "$tmp/brushed-one.log"; }
mpi "$lamina" study "${brushed[@]}" --out "$tmp/two/brushed" >"$tmp/brushed-two.log" 2>&1 \
    && grep -q 'Reference: 4 pieces computed over 2 processes' "$tmp/brushed-two.log" && ok \
    || { fail "mpirun brushed study"; cat "$tmp/brushed-two.log"; }
same_files "brushed study" "$tmp/one/brushed" "$tmp/two/brushed" metrics.csv \
    configs/brushed-gold-a0.001-a1.05x.3-t30/tables.lza configs/brushed-gold-a0.001-a1.05x.3-t30/config.json

# 3. Errors: rank 0 fails (missing stack) while rank 1 waits for it: a message and a non-zero exit,
#    no hang; a command that does not run over processes says so.
expect_error() {  # expect_error TEXT ARGS...
    local text=$1
    shift
    if mpi "$lamina" "$@" >"$tmp/err" 2>&1; then fail "accepted: $*"; return; fi
    grep -qF -- "$text" "$tmp/err" && ok || { fail "message for $*:"; cat "$tmp/err"; }
}
expect_error "cannot" simulate "$tmp/missing.json" --particles 1e4 --out "$tmp/x"
expect_error "--particles" simulate "$src/examples/plastic.json" --particles 0 --out "$tmp/x"
expect_error "only simulate and study" validate "$src/examples/plastic.json"
expect_error "--preset: 'huge' is not a preset" study --preset huge --out "$tmp/x"
[ ! -e "$tmp/x/brdf.csv" ] && ok || fail "a failed run wrote output"

finish
