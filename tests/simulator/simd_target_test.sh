#!/usr/bin/env bash
# ctest `simd_<TARGET>`: the SIMD kernel's tests again with the dispatch capped at TARGET
# (LAMINA_SIMD_TARGET), so that every instruction set a machine may take is tested on this one.
# Where TARGET is already the one this machine takes (`lamina --version`), the `unit` and `stat`
# runs have tested it: skipped (exit 77, ctest's SKIP_RETURN_CODE) rather than run twice.
# Usage: simd_target_test.sh LAMINA LAMINA_TESTS TARGET GTEST_FILTER
set -euo pipefail
lamina=$1 tests=$2 target=$3 filter=$4
native=$(env -u LAMINA_SIMD_TARGET "$lamina" --version | sed -n 's/^SIMD kernel: //p')
if [ -z "$native" ]; then
    echo "FAIL \`lamina --version\` names no SIMD kernel"; exit 1
fi
if [ "$native" = "$target" ]; then
    echo "skipped: $target is what this machine dispatches to; the unit and stat runs tested it"
    exit 77
fi
LAMINA_SIMD_TARGET=$target exec "$tests" --gtest_filter="$filter"
