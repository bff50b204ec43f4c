"""`lamina study|compare --model-plugin NAME=FILE.py` calls this to bin a Python model.

    python3 -m lamina.plugin_table FILE.py --stack STACK.json --theta-i 0,60 [--phi-i 0,45] \
        --grid 90x90 --out T.csv

FILE.py defines MODEL: a class (called with the lamina.Stack) or an object with a vectorized
eval(wi, wo), as lamina.plugins describes. --phi-i: the light's azimuth per incidence (degrees,
default 0); the grid is unfolded for an anisotropic stack or an azimuth off 0 (--grid may say
"90x90 unfolded", as the study names such a grid). Writes the model's binned table (the brdf.csv format)
to --out, or the line "unsupported" when the model supports neither side of the stack; exit
status 0 when written, 1 on an error (printed as `lamina: FILE: FIELD: PROBLEM`), including a
model that calls sys.exit (lamina reads an exit without the file as a failure too: os._exit).
"""

import argparse
import importlib.util
import sys
from pathlib import Path

from . import InputError, Stack
from .plugins import bin_model, input_error


def load_model(path):
    path = Path(path)
    if not path.is_file():
        raise input_error(str(path), "", "cannot read the file")
    spec = importlib.util.spec_from_file_location(f"lamina_plugin_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    model = getattr(module, "MODEL", None)
    if model is None or not hasattr(model, "eval"):
        raise input_error(str(path), "MODEL",
                          "the file must define MODEL, a class or an object with eval(wi, wo)")
    return model


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m lamina.plugin_table")
    p.add_argument("plugin")
    p.add_argument("--stack", required=True)
    p.add_argument("--theta-i", required=True)
    p.add_argument("--phi-i", default=None)
    p.add_argument("--grid", required=True)
    p.add_argument("--nodes", type=int, default=4)
    p.add_argument("--out", required=True)
    a = p.parse_args(argv)
    try:
        model = load_model(a.plugin)
        n_theta, n_phi = (int(x) for x in a.grid.split()[0].split("x"))
        theta_i = [float(t) for t in a.theta_i.split(",")]
        phi_i = [float(p) for p in a.phi_i.split(",")] if a.phi_i else 0.0
        table = bin_model(model, Stack(a.stack), theta_i, (n_theta, n_phi), a.nodes,
                          phi_i=phi_i)
    except InputError as e:
        print(f"lamina: {e}", file=sys.stderr)
        return 1
    except SystemExit as e:
        print(f"lamina: {a.plugin}: the Python model called sys.exit({e.code!r})",
              file=sys.stderr)
        return 1
    Path(a.out).write_text("unsupported\n" if table is None else table.to_csv())
    return 0


if __name__ == "__main__":
    sys.exit(main())
