#!/usr/bin/env bash
# lamina-1's header library as a renderer takes it (docs/lamina1.md): the data file written by
# `lamina export --lamina1-tables`, the worked pbrt-v4 integration run on it (integration/standalone.cpp),
# a damaged data file refused with a reason, and the docs' listing of the integration equal to the
# file the test compiles.
# usage: header_test.sh LAMINA STANDALONE_TEST REPO_ROOT
set -u
lamina=$1 standalone=$2 root=$3
. "$root/tests/support/script_lib.sh"

if "$lamina" export --lamina1-tables "$tmp/lamina1.tables" > "$tmp/export.log" 2>&1; then ok; else
    fail "export --lamina1-tables: $(cat "$tmp/export.log")"; fi
out=$("$standalone" "$tmp/lamina1.tables" 2>&1)
if [ "$out" = ok ]; then ok; else fail "standalone test: $out"; fi

# A truncated file and a file of another kind are refused, naming the file.
head -c 100000 "$tmp/lamina1.tables" > "$tmp/short.tables"
out=$("$standalone" "$tmp/short.tables" 2>&1)
if [[ "$out" == *"short.tables: truncated"* ]]; then ok; else fail "truncated file: $out"; fi
echo '{"not": "tables"}' > "$tmp/other.tables"
out=$("$standalone" "$tmp/other.tables" 2>&1)
if [[ "$out" == *"other.tables: not a lamina-1 tables file"* ]]; then ok; else fail "other file: $out"; fi

# docs/lamina1.md lists pbrt_bxdf.h between its marker lines, unchanged.
awk '/<!-- begin pbrt_bxdf.h -->/{on=1; next} /<!-- end pbrt_bxdf.h -->/{on=0} on' \
    "$root/docs/lamina1.md" | sed '1d;$d' > "$tmp/listing.h"
if diff -q "$tmp/listing.h" "$root/tests/lamina1/integration/pbrt_bxdf.h" > /dev/null; then ok; else
    fail "docs/lamina1.md's listing differs from tests/lamina1/integration/pbrt_bxdf.h"; fi
finish
