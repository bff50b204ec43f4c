"""The type stubs of the compiled module (src/python/lamina/_lamina.pyi) against the module itself.

pybind11 writes each function's signature as the first line of its docstring; these tests read
those signatures and the stub's (with Python's own parser) and require the same names, the same
parameters in the same order and the same defaulted parameters, in both directions: a function,
property or parameter added to, renamed in or removed from module.cpp and not in the stub fails
here. When mypy is installed (make deps installs it) the stub and a small typed user script are
also type-checked.
"""

import ast
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

import lamina
from lamina import _lamina

STUB = Path(lamina.__file__).with_name("_lamina.pyi")


def split_top_level(text):
    """Splits a parameter list at the commas outside brackets and quotes."""
    parts, depth, quote, cur = [], 0, None, ""
    for ch in text:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(cur.strip())
            cur = ""
            continue
        cur += ch
    if cur.strip():
        parts.append(cur.strip())
    return parts


def runtime_params(func, name):
    """[(parameter name, has default)] from pybind11's docstring signature, self dropped."""
    doc = (func.__doc__ or "").lstrip()
    m = re.match(re.escape(name) + r"\((.*)\) ->", doc.split("\n")[0])
    assert m, f"{name}: no pybind11 signature in its docstring: {doc[:80]!r}"
    out = []
    for p in split_top_level(m.group(1)):
        pname = p.split(":")[0].split("=")[0].strip()
        if pname == "self":
            continue
        out.append((pname, "=" in p))
    return out


def stub_params(fn):
    a = fn.args
    named = [*a.posonlyargs, *a.args]
    n_defaults = len(a.defaults)
    out = [(p.arg, i >= len(named) - n_defaults) for i, p in enumerate(named)]
    out += [(p.arg, d is not None) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    if a.vararg:
        out.append(("*" + a.vararg.arg, False))
    if a.kwarg:
        out.append(("**" + a.kwarg.arg, False))
    return [p for p in out if p[0] != "self"]


def parse_stub():
    """{name: params} for functions, {class: {member: params or "property"}} for classes."""
    tree = ast.parse(STUB.read_text())
    functions, classes, bodies = {}, {}, {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            functions[node.name] = stub_params(node)
        elif isinstance(node, ast.ClassDef):
            # A class's members: its own and those of its bases written in the stub (the stub's
            # private bases only share declarations; the module's classes have no bases).
            members = {}
            for base in node.bases:
                members.update(bodies.get(getattr(base, "id", ""), {}))
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    decorators = {getattr(d, "id", None) for d in item.decorator_list}
                    members[item.name] = "property" if "property" in decorators else stub_params(
                        item)
                elif isinstance(item, ast.AnnAssign):
                    members[item.target.id] = "attribute"
            bodies[node.name] = members
            if not node.name.startswith("_"):
                classes[node.name] = members
    return functions, classes


def runtime_members(cls):
    """The members a user reaches: methods and properties, __init__ where pybind11 defines it."""
    out = {}
    for k, v in vars(cls).items():
        if k.startswith("__") and k != "__init__":
            continue
        if k.startswith("_") and not k.startswith("__"):
            continue
        if isinstance(v, property):
            out[k] = "property"
        elif isinstance(v, staticmethod):
            out[k] = runtime_params(v.__func__, k)
        elif k == "__init__" and not (v.__doc__ or "").startswith("__init__("):
            continue  # no constructor from Python (pybind11's default __init__ raises)
        else:
            out[k] = runtime_params(v, k)
    return out


def strip_star(params):
    """pybind11 writes **kwargs as `**kwargs`; the stub parser marks it the same way."""
    return [(p.lstrip("*") if p.startswith("**") else p, d) for p, d in params]


def test_module_functions_match_the_stub():
    functions, classes = parse_stub()
    runtime = {}
    for name in dir(_lamina):
        obj = getattr(_lamina, name)
        if name.startswith("__") or isinstance(obj, type):
            continue
        if callable(obj):
            runtime[name] = obj
    assert sorted(runtime) == sorted(functions)
    for name, fn in runtime.items():
        if name == "kernel_description":  # a cpp_function attribute: pybind11 names it arg0
            continue
        assert runtime_params(fn, name) == functions[name], name


def test_module_constants_are_in_the_stub():
    tree = ast.parse(STUB.read_text())
    annotated = {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    constants = {n for n in dir(_lamina) if n.isupper()}
    assert constants == annotated


def test_classes_match_the_stub():
    _, classes = parse_stub()
    runtime_classes = {n for n in dir(_lamina) if isinstance(getattr(_lamina, n), type)}
    assert runtime_classes == set(classes)
    for name in runtime_classes - {"InputError"}:
        runtime = runtime_members(getattr(_lamina, name))
        stub = {k: v for k, v in classes[name].items()}
        assert sorted(runtime) == sorted(stub), name
        for member, params in runtime.items():
            if params == "property":
                assert stub[member] == "property", f"{name}.{member}"
            else:
                assert strip_star(params) == strip_star(stub[member]), f"{name}.{member}"


def test_input_error_attributes_are_in_the_stub():
    _, classes = parse_stub()
    with pytest.raises(lamina.InputError) as e:
        lamina.Stack({"layers": "not a list"})
    for attr in ("file", "field", "problem"):
        assert hasattr(e.value, attr) and classes["InputError"][attr] == "attribute"


def test_the_checker_sees_a_renamed_parameter():
    # The comparison itself must fail on a stub that drifted: rename one parameter.
    fn = ast.parse("def pdf(self, wi, wx): ...").body[0]
    assert stub_params(fn) != runtime_params(_lamina.Model.pdf, "pdf")


@pytest.mark.skipif(importlib.util.find_spec("mypy") is None, reason="mypy not installed")
def test_stub_and_a_typed_script_type_check(tmp_path):
    script = tmp_path / "user.py"
    script.write_text(
        "import numpy as np\n"
        "import lamina\n"
        "stack = lamina.Stack({'name': 'p', 'layers': []})\n"
        "model = lamina.Model('lamina-1', stack, leaves='exact')\n"
        "f: np.ndarray = model.eval([0, 0, 1], [0, 0, 1])\n"
        "table: lamina.Table = model.binned([0.0, 30.0], (9, 9))\n"
        "edges = table.theta_edges\n"
        "ok: bool = model.support['brdf']\n"
        "code: int = lamina._lamina.cli(['lamina', '--version'])\n"
        "run: lamina.SimulationResult = lamina.simulate(stack, theta_i=0, particles=10)\n"
        "study: lamina.Study = lamina.load_study('somewhere')\n")
    env_path = str(Path(lamina.__file__).parents[1])
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--ignore-missing-imports", "--no-incremental",
         "--cache-dir", str(tmp_path / "cache"), str(STUB), str(script)],
        capture_output=True, text=True, env={"MYPYPATH": env_path, "PATH": "/usr/bin:/bin"},
        cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    # A wrong use must be reported: the stub says what eval returns.
    script.write_text("import lamina\nx: str = lamina.Model('lamina-1', {}).eval([0, 0, 1], "
                      "[0, 0, 1])\n")
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--ignore-missing-imports", "--no-incremental",
         "--cache-dir", str(tmp_path / "cache"), str(script)],
        capture_output=True, text=True, env={"MYPYPATH": env_path, "PATH": "/usr/bin:/bin"},
        cwd=tmp_path)
    assert r.returncode != 0 and "Incompatible types" in r.stdout, r.stdout + r.stderr
