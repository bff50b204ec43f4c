#!/usr/bin/env bash
# The repository stands alone (docs/style.md, "Also"): no tracked file may point outside it, and
# every document it cites must exist in docs/. Usage: links_test.sh SOURCE_DIR
#
# A tracked text file fails, with file:line, when it
#   - mentions a parent directory's shared notes (the text `..` + `/shared`, or /work + `/shared`);
#   - cites docs/<name>.md and SOURCE_DIR/docs/<name>.md does not exist;
#   - names a document bare (physics, style, study, models, models-on-trial, notation, or any
#     docs/ page, followed by .md, with no docs/ before it): outside docs/ that is ambiguous (a
#     reader of a clone cannot tell where it is), so it must be written docs/<name>.md; inside docs/
#     it is a sibling page and must exist there;
#   - is Markdown and links (`](target.md)`) to a relative .md file that does not exist.
# Before checking the repository, the script checks itself on a planted tree with known bad lines,
# so it cannot pass by finding nothing. (The planted lines are assembled at run time, so that this
# file itself holds none of them.)
set -u
src=${1:?usage: links_test.sh SOURCE_DIR}
src=$(cd "$src" && pwd -P)

# Names that are documents wherever they appear bare (besides every page of docs/).
extra_names="physics style study models models-on-trial notation"

# The files to check, relative to ROOT: git's tracked files when ROOT is a work tree's top,
# otherwise every file outside build/, .git and node_modules.
list_files() {
    local root=$1
    if [ "$(git -C "$root" rev-parse --show-toplevel 2>/dev/null)" = "$root" ]; then
        git -C "$root" ls-files
    else
        (cd "$root" && find . \( -path ./build -o -path ./.git -o -path ./node_modules \) -prune \
            -o -type f -print | sed 's#^\./##')
    fi
}

# check_tree ROOT: prints one "file:line: problem" per problem found, and "#refs N" (the number of
# document citations it resolved) last.
check_tree() {
    local root=$1
    local names=$extra_names f
    for f in "$root"/docs/*.md; do
        [ -f "$f" ] && names="$names $(basename "$f" .md)"
    done
    local alternation
    alternation=$(printf '%s\n' $names | sort -u | sed 's/[.]/\\./g' | paste -sd '|')
    local refs=0 file line text name target dir
    while IFS= read -r file; do
        [ -f "$root/$file" ] && [ ! -L "$root/$file" ] || continue
        grep -qI . "$root/$file" 2>/dev/null || continue  # binary or empty
        # Outside the repository.
        grep -nIE '\.\./shared|/work/share[d]' "$root/$file" | cut -d: -f1 | while read -r line; do
            echo "$file:$line: points outside the repository (shared notes are not in a clone)"
        done
        # docs/<name>.md must exist.
        while IFS=: read -r line text; do
            refs=$((refs + 1))
            [ -f "$root/$text" ] || echo "$file:$line: cites $text, which does not exist"
        done < <(grep -noIP '(?<![A-Za-z0-9_-])docs/[A-Za-z0-9_.-]+\.md' "$root/$file")
        # Bare document names.
        while IFS=: read -r line text; do
            name=${text%.md}
            if [[ $file == docs/* ]]; then
                refs=$((refs + 1))
                [ -f "$root/docs/$text" ] ||
                    echo "$file:$line: cites $text, which is not a page of docs/"
            else
                echo "$file:$line: cites $text bare: write docs/$text (and check it exists)"
            fi
        done < <(grep -noIP "(?<![A-Za-z0-9_./-])($alternation)\.md(?![A-Za-z0-9_-])" "$root/$file")
        # Markdown links to relative .md files.
        if [[ $file == *.md ]]; then
            dir=$(dirname "$file")
            while IFS=: read -r line target; do
                refs=$((refs + 1))
                [ -f "$root/$dir/$target" ] ||
                    echo "$file:$line: links to $target, which does not exist"
            done < <(grep -noP '\]\(\K[^)#:[:space:]]+\.md(?=[)#])' "$root/$file")
        fi
    done < <(list_files "$root")
    echo "#refs $refs"
}

# ---- Self-check on a planted tree ---------------------------------------------------------------
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/tree/docs" "$tmp/tree/src"
m=md up=.. # assembled: the planted references must not appear in this file
printf '# Physics\n' >"$tmp/tree/docs/physics.$m"
printf '# Models\n' >"$tmp/tree/docs/models.$m"
printf '// docs/physics.%s §3, docs/models.%s; writes summary.%s and README.%s\n' $m $m $m $m \
    >"$tmp/tree/src/good.cpp"
printf 'See [the physics](physics.%s) §1 and models.%s.\n' $m $m >"$tmp/tree/docs/guide.$m"
printf '// fine\n// from %s/shared/physics.%s\n' $up $m >"$tmp/tree/src/bad1.cpp"
printf '// physics.%s §4\n' $m >"$tmp/tree/src/bad2.h"
printf 'a\nb\nsee docs/missing.%s\n' $m >"$tmp/tree/bad3.$m"
printf '[s](style.%s)\n' $m >"$tmp/tree/docs/bad4.$m"
printf 'models-on-trial.%s\n' $m >"$tmp/tree/bad5.txt"
printf 'bad1.cpp:2\nbad2.h:1\nbad3.md:3\nbad4.md:1\nbad5.txt:1\n' >"$tmp/want"
check_tree "$tmp/tree" >"$tmp/planted"
grep -v '^#refs' "$tmp/planted" | cut -d: -f1,2 | sed 's#^.*/##' | sort -u >"$tmp/got"
if ! diff -u "$tmp/want" "$tmp/got"; then
    echo "FAIL self-check: the planted tree's problems (want, left) were not found (got, right):"
    cat "$tmp/planted"
    exit 1
fi

# ---- The repository ------------------------------------------------------------------------------
check_tree "$src" >"$tmp/repo"
refs=$(sed -n 's/^#refs //p' "$tmp/repo")
problems=$(grep -vc '^#refs' "$tmp/repo")
if [ "$problems" -gt 0 ]; then
    grep -v '^#refs' "$tmp/repo"
    echo "FAIL: $problems reference(s) above point outside the repository or to a missing document"
    exit 1
fi
if [ "${refs:-0}" -lt 1 ]; then
    echo "FAIL: no document citation found in $src (wrong directory?)"
    exit 1
fi
echo "PASS: $refs document citations resolved, nothing points outside the repository"
