#!/usr/bin/env bash
# The command-line errors docs/robustness.md quotes ("The command line.") are what lamina prints:
# each command below must print the quoted line of the same rank, word for word, and exit 1.
# Usage: cli_messages_test.sh LAMINA SOURCE_DIR
set -uo pipefail
lamina=$(realpath "$1")
src=$(realpath "$2")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
. "$src/tests/docs/quoted_lib.sh"

stack=$src/examples/plastic.json
commands=(
    "simulate $stack --bogus"
    "eval --model ww-prime --stack $stack --theta-i 30 --theta-o abc --phi-o 0"
    "eval --model random-walk --stack $stack --samples -5"
    "render $stack --size 5 --out never.png"
    "eval --model ww-prime --theta-i 30"
)

# The quoted block: the indented lines starting "lamina:" after "**The command line.**".
awk '/\*\*The command line\.\*\*/ { seen = 1; next }
     seen && /^      lamina: / { sub(/^      /, ""); print; quoted = 1; next }
     seen && quoted { exit }' "$src/docs/robustness.md" >quoted.txt

: >printed.txt
for command in "${commands[@]}"; do
    # shellcheck disable=SC2086  # the commands are words
    "$lamina" $command >out.txt 2>&1
    rc=$?
    if [ "$rc" -ne 1 ]; then
        echo "FAIL: exit $rc, wanted 1: lamina $command"
        cat out.txt
        exit 1
    fi
    head -n 1 out.txt >>printed.txt
done

same_as_quoted docs/robustness.md "${#commands[@]}"
