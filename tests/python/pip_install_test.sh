#!/usr/bin/env bash
# `pip install .` (pyproject.toml, setup.py) into a fresh virtual environment, with Debian's
# setuptools and no index (--no-build-isolation --no-deps --no-index: nothing is downloaded), the
# compiled module built in this build tree (LAMINA_CMAKE_BUILD_DIR); then `import lamina` from
# outside the repository with no PYTHONPATH is the installed package, and it evaluates a model.
# usage: pip_install_test.sh PYTHON REPO_ROOT BUILD_DIR
set -u
python=$1 root=$(cd "$2" && pwd) build=$(cd "$3" && pwd)
. "$root/tests/support/script_lib.sh"

# The venv sees the system's numpy (Debian's python3-numpy) and nothing else of lamina.
if "$python" -m venv --system-site-packages "$tmp/venv" > "$tmp/venv.log" 2>&1; then ok; else
    fail "venv: $(cat "$tmp/venv.log")"; finish; exit; fi
if env -u PYTHONPATH LAMINA_CMAKE_BUILD_DIR="$build" PIP_DISABLE_PIP_VERSION_CHECK=1 \
    "$tmp/venv/bin/python" -m pip install --no-build-isolation --no-deps --no-index "$root" \
    > "$tmp/pip.log" 2>&1; then ok; else fail "pip install: $(tail -20 "$tmp/pip.log")"; fi

cd "$tmp" || exit 1
out=$(env -u PYTHONPATH "$tmp/venv/bin/python" - "$tmp/venv" "$root" <<'PY' 2>&1
import sys, os
import lamina
venv, root = sys.argv[1], sys.argv[2]
assert os.path.realpath(lamina.__file__).startswith(os.path.realpath(venv)), lamina.__file__
# The type information ships with the package (PEP 561: py.typed beside the stubs).
pkg = os.path.dirname(lamina.__file__)
assert all(os.path.isfile(os.path.join(pkg, n)) for n in ("py.typed", "_lamina.pyi")), os.listdir(pkg)
s = lamina.Stack(os.path.join(root, "examples", "plastic.json"))
m = lamina.Model("lamina-1", s)
f = m.eval([0, 0, 1], [0, 0, 1])
assert f.shape[-1] == 3 and 0 < float(f[..., 1]) < 1, f
print("ok")
PY
)
if [ "$out" = ok ]; then ok; else fail "import lamina from the venv: $out"; fi
# `python3 -m lamina` is the command line, from the installed package.
out=$(env -u PYTHONPATH "$tmp/venv/bin/python" -m lamina validate "$root/examples/plastic.json" 2>&1)
case "$out" in plastic:*) ok ;; *) fail "python -m lamina validate: $out" ;; esac
finish
