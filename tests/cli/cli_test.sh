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
check version 0 "$lamina" --version
check help 0 "$lamina" --help
check no-subcommand 106 "$lamina"
rm -f /tmp/lamina-cli-out.$$
echo "$pass passed, $fails failed"
[ "$fails" -eq 0 ]
