#!/usr/bin/env python3
"""The folders of src/ include only what docs/architecture.md lets them include.

usage: layering_test.py REPO_ROOT

Reads the two tables of docs/architecture.md whose last column is "may include" (the folders, and
the folders inside models/), then checks every #include "..." of every .h and .cpp file under src/:
an include of the file's own folder is always allowed, lamina/version.h (generated) too; any other
must start with a token its row lists ("core" allows "core/...", "models/model.h" exactly that
file). A folder of src/ without a row fails too. Exit status 0 when all hold.
"""

import re
import sys
from pathlib import Path


def read_rules(doc_text):
    """{folder: [allowed tokens]} from the tables with a 'may include' column."""
    rules = {}
    in_table = False
    for line in doc_text.splitlines():
        if line.startswith("|") and line.rstrip().endswith("| may include |"):
            in_table = True
            continue
        if in_table and line.startswith("|---"):
            continue
        if in_table and line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            folder = re.sub(r"\(.*?\)", "", cells[0]).replace("`", "").strip()
            allowed = cells[-1].replace("`", "").strip()
            rules[folder] = [] if allowed in ("—", "-", "") else allowed.split()
            continue
        in_table = False
    return rules


def folder_of(rel_path, rules):
    """The row a file under src/ belongs to: models/<family> where such a row exists."""
    parts = rel_path.parts
    if len(parts) > 2 and f"{parts[0]}/{parts[1]}" in rules:
        return f"{parts[0]}/{parts[1]}"
    return parts[0]


def own(include, folder):
    if folder == "models":  # the files directly in models/, not its sub-folders
        return include.startswith("models/") and include.count("/") == 1
    return include.startswith(folder + "/")


def allowed(include, tokens):
    return any(include == t or include.startswith(t + "/") for t in tokens)


def violations(files, rules):
    """[(file, line number, include, folder)] for each include a row does not allow."""
    bad = []
    for rel_path, text in files:
        folder = folder_of(rel_path, rules)
        if folder not in rules:
            bad.append((rel_path, 0, "(no row in docs/architecture.md)", folder))
            continue
        for n, line in enumerate(text.splitlines(), 1):
            m = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
            if not m or "/" not in m.group(1):
                continue
            inc = m.group(1)
            if inc == "lamina/version.h" or own(inc, folder) or allowed(inc, rules[folder]):
                continue
            bad.append((rel_path, n, inc, folder))
    return bad


def self_check(rules):
    """The checker itself finds a wrong-way include and accepts a right one."""
    fake = [(Path("physics/x.h"), '#include "core/vec.h"\n#include "simulator/tally.h"\n'),
            (Path("models/belcour/y.cpp"), '#include "models/model.h"\n#include "models/lamina1/z.h"\n')]
    found = {(str(f), inc) for f, _, inc, _ in violations(fake, rules)}
    expected = {("physics/x.h", "simulator/tally.h"), ("models/belcour/y.cpp", "models/lamina1/z.h")}
    return found == expected


def main():
    root = Path(sys.argv[1])
    rules = read_rules((root / "docs/architecture.md").read_text())
    if "core" not in rules or "models/belcour" not in rules:
        print("FAIL: docs/architecture.md has no tables of what each folder may include")
        return 1
    if not self_check(rules):
        print("FAIL: the checker does not flag a wrong-way include")
        return 1
    src = root / "src"
    files = [(p.relative_to(src), p.read_text(errors="replace"))
             for p in sorted(src.rglob("*")) if p.suffix in (".h", ".cpp")]
    bad = violations(files, rules)
    for rel_path, n, inc, folder in bad:
        print(f"src/{rel_path}:{n}: includes {inc}, which docs/architecture.md does not let "
              f"'{folder}' include")
    if bad:
        print(f"FAIL: {len(bad)} include(s) against docs/architecture.md")
        return 1
    # include/lamina1/, the header library a renderer takes alone: only its own headers (quoted)
    # and the standard library's (angle brackets, no folder: nothing installed beside it).
    header_bad = []
    headers = sorted((root / "include/lamina1").glob("*.h"))
    for p in headers:
        for n, line in enumerate(p.read_text(errors="replace").splitlines(), 1):
            m = re.match(r'\s*#\s*include\s+([<"])([^>"]+)[>"]', line)
            if not m:
                continue
            quoted, inc = m.group(1) == '"', m.group(2)
            if (quoted and not inc.startswith("lamina1/")) or (not quoted and "/" in inc):
                header_bad.append(f"include/lamina1/{p.name}:{n}: includes {inc}")
    for b in header_bad:
        print(b + ", but lamina-1's headers may include only each other and the standard library")
    if header_bad or not headers:
        print("FAIL: include/lamina1/ is not self-contained" if headers else
              "FAIL: include/lamina1/ has no headers")
        return 1
    print(f"ok: {len(files)} files of {len(rules)} folders include only what their rows allow; "
          f"{len(headers)} headers of include/lamina1/ only each other and the standard library")
    return 0


if __name__ == "__main__":
    sys.exit(main())
