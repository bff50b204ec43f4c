#!/usr/bin/env bash
# Throughput of `lamina simulate` on the benchmark plastic (bench/bench-plastic.json) against
# threads and MPI processes (docs/scaling.md). Prints one Markdown table row per set-up: the best
# of REPEATS runs of particles_per_second (result.json: wall time of the simulation on rank 0,
# the sum over processes included) and that rate per core used.
# Usage: scripts/scaling.sh [BUILD_DIR] [PARTICLES] [REPEATS] [-- EXTRA lamina simulate ARGS]
set -euo pipefail
build=${1:-build}
particles=${2:-2e7}
repeats=${3:-3}
shift $(($# < 3 ? $# : 3))
[ "${1:-}" = "--" ] && shift
extra=("$@")
lamina=$build/lamina
src=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mpi=(mpirun --allow-run-as-root --oversubscribe --bind-to none)

measure() {  # measure LABEL PROCESSES THREADS COMMAND...
    local label=$1 processes=$2 threads=$3 best=0
    shift 3
    for _ in $(seq 1 "$repeats"); do
        rm -rf "$tmp/out"
        "$@" "$src/bench/bench-plastic.json" --theta-i 30 --particles "$particles" \
            --threads "$threads" "${extra[@]}" --out "$tmp/out" >/dev/null
        best=$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1]))["particles_per_second"]; print(max(r, float(sys.argv[2])))' \
            "$tmp/out/result.json" "$best")
    done
    python3 -c 'import sys; rate=float(sys.argv[2]); cores=int(sys.argv[3])*int(sys.argv[4]);
print(f"| {sys.argv[1]} | {sys.argv[3]} | {sys.argv[4]} | {rate/1e6:.2f} | {rate/cores/1e6:.2f} |")' \
        "$label" "$best" "$processes" "$threads"
}

echo "| set-up | processes | threads each | M particles/s | M particles/s per core |"
echo "|---|---|---|---|---|"
measure "lamina simulate --threads 1" 1 1 "$lamina" simulate
measure "lamina simulate --threads 2" 1 2 "$lamina" simulate
if command -v mpirun >/dev/null 2>&1; then
    measure "mpirun -n 1 … --threads 2" 1 2 "${mpi[@]}" -n 1 "$lamina" simulate
    measure "mpirun -n 2 … --threads 1" 2 1 "${mpi[@]}" -n 2 "$lamina" simulate
fi
