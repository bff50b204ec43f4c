#!/usr/bin/env bash
# ctest `browser`: the explorer page of a small synthetic study in headless Chromium.
# Usage: browser_test.sh LAMINA SRC_DIR BUILD_DIR
set -euo pipefail
lamina=$1 src=$2 build=$3
study="$build/report-fixture"
rm -rf "$study"
python3 "$src/tests/report/make_fixture.py" "$study"
"$lamina" explorer "$study"
if [ ! -d "$src/node_modules/playwright-core" ]; then
    echo "FAIL playwright-core is not installed: run \`make deps\` (npm ci)"; exit 1
fi
node "$src/tests/report/browser_test.js" "$study" "$build/screenshots"
