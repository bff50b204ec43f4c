# Sourced by the tests that check a page's quoted messages against what lamina prints:
# same_as_quoted PAGE COUNT compares quoted.txt (the page's lines) with printed.txt (lamina's, in
# the same order, COUNT of them) in the current folder, and exits non-zero on a difference.
same_as_quoted() {
    local page=$1 count=$2
    if [ "$(wc -l <quoted.txt)" -ne "$count" ]; then
        echo "FAIL: $page quotes $(wc -l <quoted.txt) messages, the test has $count inputs"
        exit 1
    fi
    if ! diff -u quoted.txt printed.txt; then
        echo "FAIL: the messages $page quotes differ from what lamina prints (above)"
        exit 1
    fi
    echo "$count quoted messages match"
}
