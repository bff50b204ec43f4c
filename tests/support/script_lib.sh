# Sourced by the end-to-end test scripts: the pass and fail counters, a temporary folder ($tmp)
# removed on exit, ok/fail, and `finish`, which prints the counts and exits non-zero on a failure.
pass=0
fails=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ok() { pass=$((pass + 1)); }
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
finish() {
    echo "$pass passed, $fails failed"
    [ "$fails" -eq 0 ]
}
