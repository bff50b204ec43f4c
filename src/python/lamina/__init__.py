"""lamina from Python: stacks, the virtual goniophotometer, the layered models and the study.

Directions follow lamina's conventions (docs/notation.md): z is the macro-surface normal, wi the
light direction (wi.z > 0), wo the viewer (wo.z < 0 for transmission); the light of incidence
theta_i sits at phi = 0, so the mirror direction is at phi = 180 degrees; f is in 1/sr without the
cosine. Binned arrays are [incidence, side, theta bin, phi bin, channel]. Bad input raises
lamina.InputError (a ValueError) with .file, .field and .problem, as the CLI reports it.

See docs/python.md.
"""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path
from typing import Any, Optional

import numpy as np

from ._lamina import (  # noqa: F401  (re-exported)
    InputError,
    Model,
    SimulationResult,
    Stack,
    Table,
    kernel_description,
    models,
)
from . import _lamina
from . import arrays as _arrays
from .plugins import (MAX_NODES, MAX_PEAK_NODES, bin_model, input_error, model_name,
                      node_count)

__all__ = [
    "InputError",
    "Model",
    "SimulationResult",
    "Stack",
    "Table",
    "bin_model",
    "read_array",
    "compare",
    "export",
    "Study",
    "load_study",
    "models",
    "simulate",
    "study",
]

# The incidences lamina uses when none are given (one owner: src/core/incidences.h).
DEFAULT_THETA_I = tuple(_lamina.DEFAULT_THETA_I)


# The goniophotometer's settings by name, with their defaults (one owner: the SimulationSettings of
# src/simulator/goniophotometer.h): simulate, compare and study take any of them as keywords.
SIMULATION_SETTINGS = dict(_lamina.SIMULATION_SETTINGS)


# The named references and the settings each one sets (one owner: ReferencePhysics in
# src/layers/transport_settings.h): "exact" (the defaults) and "bpb19" (the 2019 study's).
REFERENCE_PHYSICS = {k: dict(v) for k, v in _lamina.REFERENCE_PHYSICS.items()}


def _reference_settings(settings):
    """The settings given, checked by name; their values are checked by lamina itself.
    physics="exact"|"bpb19" stands for the settings it names; one given beside it wins."""
    settings = dict(settings)
    physics = settings.pop("physics", None)
    for name in settings:
        if name not in SIMULATION_SETTINGS:
            raise input_error("arguments", name,
                              f"is not a setting; the settings are physics, "
                              f"{', '.join(SIMULATION_SETTINGS)}")
    if physics is not None:
        if physics not in REFERENCE_PHYSICS:
            raise input_error("arguments", "physics",
                              f"{physics!r} is not a reference; use one of "
                              f"{', '.join(REFERENCE_PHYSICS)}")
        settings = dict(REFERENCE_PHYSICS[physics], **settings)
    return settings


def _grid_pair(grid):
    """(n_theta, n_phi) of a grid given as a pair, "90x90" or {"n_theta", "n_phi"}."""
    if isinstance(grid, dict):
        return int(grid["n_theta"]), int(grid["n_phi"])
    if isinstance(grid, str):
        n_theta, n_phi = grid.split("x")
        return int(n_theta), int(n_phi)
    return int(grid[0]), int(grid[1])


def simulate(stack, progress: Optional[bool] = None, **settings: Any) -> SimulationResult:
    """Runs the goniophotometer (`lamina simulate`) and returns a SimulationResult.

    stack: a Stack, a dict in the stack format or a path. settings: any of SIMULATION_SETTINGS by
    name, as `lamina simulate` takes them (theta_i: degrees in [0, 90), one or a list; particles:
    per incidence; seed, threads, grid=(n_theta, n_phi), kernel, microsurface, polarization,
    transmission_masking, max_events, ...; docs/python.md), or physics="bpb19" for the 2019
    study's reference (REFERENCE_PHYSICS); the others keep their defaults. The
    tables are bitwise those of `lamina simulate` with the same inputs (for the same kernel on the
    same machine) and do not depend on `threads`. The GIL is released while particles are traced;
    Ctrl-C stops the run between chunks of particles and raises KeyboardInterrupt. progress: draw a
    progress line on stderr (default: when it is a terminal).
    """
    if progress is None:
        progress = _stderr_is_terminal()
    return _lamina._simulate(stack, _reference_settings(settings), bool(progress))


def _stderr_is_terminal():
    try:
        return os.isatty(2)
    except OSError:
        return False


def export(source, path, format: Optional[str] = None, theta_i=None, resolution=None,
           description: str = "", azimuths=None) -> None:
    """Writes a Model, a Table or a SimulationResult (its reflection side) as an RGL .bsdf
    (pbrt-v4, Mitsuba 3) or a MERL .binary file, as `lamina export` does (docs/formats.md).

    format: "bsdf" or "merl" (default: from the path's extension). theta_i: a model's .bsdf
    incidences in degrees (default: lamina export's, denser towards grazing; a table's are its
    own). resolution: the .bsdf's sample nodes a side (default: lamina export's). azimuths: the
    φi intervals of an anisotropic stack's .bsdf over [-180°, 180°] (default: lamina export's
    --azimuths).
    """
    path = Path(path)
    if format is None:
        format = {".bsdf": "bsdf", ".binary": "merl"}.get(path.suffix)
        if format is None:
            raise input_error("arguments", "format",
                              "give format='bsdf' or 'merl', or a path ending in .bsdf or .binary")
    if isinstance(source, SimulationResult):
        source = source.table
    # One angle or a list of them; 0 is an incidence, not "the default".
    if theta_i is None:
        theta_i = []
    elif isinstance(theta_i, str) or np.ndim(theta_i) == 0:
        theta_i = [theta_i]
    try:
        theta_i = [float(t) for t in theta_i]
    except (TypeError, ValueError):
        raise input_error("arguments", "theta_i",
                          f"{theta_i!r} is not a list of angles in degrees") from None
    _lamina._export(source, str(path), format, theta_i,
                    None if resolution is None else int(resolution), str(description),
                    None if azimuths is None else int(azimuths))


# ---- study directories ------------------------------------------------------------------------

_METRIC_TEXT = ("config", "category", "model", "side", "channel")
_METRIC_FLOATS = ("theta_i", "misplaced_energy", "albedo_ref", "albedo_model", "albedo_error",
                  "rmse", "log_rmse", "noise_floor")


def _read_metrics(path: Path) -> np.ndarray:
    """metrics.csv as a structured array of every column it has, in its order (text columns as
    text, `supported` as a truth value, every other one a number: empty is NaN, anything else
    that is not a number is refused)."""
    text = _arrays.read_bytes_bounded(path).decode("utf-8")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    rows = list(reader)
    header = reader.fieldnames or list(_METRIC_TEXT + _METRIC_FLOATS + ("supported",))
    missing = [n for n in _METRIC_TEXT + _METRIC_FLOATS + ("supported",) if n not in header]
    if missing:
        raise KeyError(", ".join(missing))
    width = {n: max([1] + [len(r[n]) for r in rows]) for n in _METRIC_TEXT}
    dtype = [(n, f"U{width[n]}") if n in _METRIC_TEXT else (n, "?") if n == "supported"
             else (n, "f8") for n in header]
    def number(text):  # a finite number, as lamina writes (explorer refuses the same)
        x = float(text)
        if not np.isfinite(x):
            raise ValueError(f"{text!r} is not a finite number")
        return x

    out = np.zeros(len(rows), dtype=dtype)
    for k, r in enumerate(rows):
        out[k] = tuple(r[n] if n in _METRIC_TEXT else (r[n] == "true") if n == "supported"
                       else (number(r[n]) if r[n] != "" else np.nan) for n in header)
    return out


def read_array(path):
    """Reads a packed-array file (.lza; docs/formats.md) into a numpy array, a .npy path with
    numpy.load; a missing, damaged or truncated file is an InputError naming it."""
    try:
        return _arrays.read_array(path)
    except _arrays.ArrayError as e:
        raise input_error(e.where, "", e.problem) from None
    except OSError as e:
        raise input_error(str(path), "", f"cannot read it: {e.strerror or e}") from None
    except ValueError as e:  # numpy.load of a damaged .npy
        raise input_error(str(path), "", f"not a readable array ({e}): damaged?") from None


# The largest study description or config.json read (a configuration's state and stack are
# tens of kB; the bound only keeps a device or a runaway file from being read without end).
_MAX_JSON_BYTES = 256 << 20


def _read_json_object(path: Path) -> dict:
    """A JSON object read from path; a damaged or truncated file is an InputError naming it."""
    try:
        value = json.loads(_arrays.read_bytes_bounded(path, _MAX_JSON_BYTES).decode("utf-8"))
    except _arrays.ArrayError as e:
        raise input_error(e.where, "", e.problem) from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise input_error(str(path), "", f"not valid JSON ({e}): damaged or truncated?") from None
    except OSError as e:
        raise input_error(str(path), "", f"cannot read it: {e.strerror or e}") from None
    if not isinstance(value, dict):
        raise input_error(str(path), "", "not a JSON object: damaged, or not lamina's file?")
    return value


class Study:
    """A study directory (`lamina study`, `lamina compare`; docs/formats.md), read from disk.

    .info: study.json; .metrics: metrics.csv as a numpy structured array (empty fields are NaN),
    or a pandas DataFrame when pandas is installed and load_study(..., pandas=True);
    .configs: the configuration ids; .config(id): its config.json; .tables(id): {source: array
    [incidence, side, theta bin, phi bin, channel]} (float16 or float32 as stored, --tables; NaN
    on a side a model does not support); .reference_se(id): the reference's standard errors, same
    axes; .reference_stokes(id): the polarized reference's Stokes components S1, S2, S3 for
    unpolarized light and their standard errors, [2, incidence, side, 3, theta bin, phi bin,
    channel] (a study run with --reference-stokes on).
    """

    def __init__(self, path, pandas=None):
        self.path = Path(path)
        info = self.path / "study.json"
        if not info.exists():
            raise input_error(str(self.path), "study.json",
                             "not a study directory: no study.json (run lamina study or compare)")
        self.info = _read_json_object(info)
        metrics = self.path / "metrics.csv"
        if not metrics.exists():
            raise input_error(str(metrics), "", "missing: every study directory has one")
        try:
            self.metrics = _read_metrics(metrics)
        except _arrays.ArrayError as e:
            raise input_error(e.where, "", e.problem) from None
        except (KeyError, ValueError, TypeError, csv.Error, UnicodeDecodeError) as e:
            raise input_error(str(metrics), "",
                              f"not lamina's metrics table ({type(e).__name__}: {e}): "
                              "damaged or truncated?") from None
        if pandas is None or pandas:
            try:
                import pandas as pd
                self.metrics = pd.read_csv(self.path / "metrics.csv")
            except ImportError:
                if pandas:
                    raise
        try:
            self.configs = [str(c["id"]) for c in self.info.get("configurations", [])]
            self.theta_i = [float(t) for t in self.info.get("theta_i", [])]
            self.models = [str(m) for m in self.info.get("models", [])]
        except (KeyError, ValueError, TypeError) as e:
            raise input_error(str(info), "configurations",
                              f"not lamina's study description ({type(e).__name__}: {e}): "
                              "damaged?") from None

    def config(self, config_id):
        return _read_json_object(self._dir(config_id) / "config.json")

    def tables(self, config_id):
        cfg = self.config(config_id)
        t = self._array(config_id, "tables")
        sources = cfg.get("sources")
        path = str(self._dir(config_id) / "config.json")
        if not isinstance(sources, list) or not all(isinstance(s, str) for s in sources):
            raise input_error(path, "sources", "missing or not a list of names: damaged?")
        if len(sources) != t.shape[0]:
            raise input_error(path, "sources",
                              f"{len(sources)} names for the {t.shape[0]} tables of tables.lza: "
                              "the folder mixes two runs, or is damaged")
        self._check_shape(config_id, cfg, "tables", t.shape[1:])
        return {name: t[k] for k, name in enumerate(sources)}

    def reference_se(self, config_id):
        se = self._array(config_id, "reference_se")
        self._check_shape(config_id, self.config(config_id), "reference_se", se.shape)
        return se

    def _check_shape(self, config_id, cfg, stem, shape):
        """[incidence, side, theta bin, phi bin, 3] as config.json and study.json say (an unfolded
        configuration, one with phi_i, has twice the phi bins), as lamina's own readers check."""
        try:
            grid = self.info["grid"]
            n_phi = int(grid["n_phi"]) * (2 if "phi_i" in cfg else 1)
            want = (len(cfg["theta_i"]), len(cfg["sides"]), int(grid["n_theta"]), n_phi, 3)
        except (KeyError, TypeError, ValueError) as e:
            raise input_error(str(self._dir(config_id) / "config.json"), "",
                              f"not lamina's configuration ({type(e).__name__}: {e}): "
                              "damaged?") from None
        if tuple(shape) != want:
            raise input_error(str(self._dir(config_id) / f"{stem}.lza"), "shape",
                              f"{list(shape)} does not match config.json and study.json "
                              f"({list(want)}): the folder mixes two runs, or is damaged")

    def reference_stokes(self, config_id):
        path = self._dir(config_id) / "reference_stokes.lza"
        if not path.exists():
            raise input_error(str(path), "reference_stokes",
                             "missing: the study stores the Stokes vectors of a polarized "
                             "reference when run with --reference-stokes on")
        return read_array(path)

    def _array(self, config_id, stem):
        # configs/<id>/<stem>.lza (a packed array), or .npy from a study written before them.
        d = self._dir(config_id)
        if not (d / f"{stem}.lza").exists() and (d / f"{stem}.npy").exists():
            return read_array(d / f"{stem}.npy")
        if not (d / f"{stem}.lza").exists():
            raise input_error(str(d / f"{stem}.lza"), "tables",
                              "missing (a study run with --tables none has no tables)")
        return read_array(d / f"{stem}.lza")

    def _dir(self, config_id):
        if config_id not in self.configs:
            raise input_error(str(self.path), "configurations",
                             f"no configuration '{config_id}'; the study has: "
                             + ", ".join(self.configs))
        return self.path / "configs" / config_id

    def __repr__(self):
        return (f"<lamina.Study {self.path}: {len(self.configs)} configurations, "
                f"models {', '.join(self.models)}>")


def load_study(path, pandas: Optional[bool] = None) -> Study:
    """Reads a study directory: metrics, configurations and tables (see Study)."""
    return Study(path, pandas=pandas)


# ---- the study with your own models ------------------------------------------------------------

def _split_models(models):
    """Registry names and Python models (docs/python.md, "Your own model")."""
    names, plugins = [], []
    if isinstance(models, str) or hasattr(models, "eval"):
        models = [models]  # one model, not the letters of its name
    for m in models or []:
        if isinstance(m, str):
            names.append(m)
        elif hasattr(m, "eval"):
            plugins.append(m)
        else:
            raise input_error("arguments", "models",
                              f"{m!r} is neither a model name nor an object with eval(wi, wo)")
    return names, plugins


def _run(configs, models, preset, out, figures, quiet, nodes, peak_nodes, tables, settings):
    # Checked here too: a study of built-in models only does not reach bin_model.
    nodes = node_count("nodes", nodes, MAX_NODES)
    peak_nodes = node_count("peak_nodes", peak_nodes, MAX_PEAK_NODES)
    names, plugins = _split_models(models)
    reference = _reference_settings(settings)
    effective = dict(SIMULATION_SETTINGS, **reference)
    grid = _grid_pair(effective["grid"])
    run = {
        "reference": reference, "study": {"tables": str(tables)}, "preset": preset,
        "models": names, "quiet": bool(quiet),
        # models=None: every built-in model; a list: exactly the models it names.
        "registry_models": models is None,
    }
    externals = []
    for p in plugins:
        def table(config_id, stack, theta_i, phi_i, p=p):
            # The configuration's incidences (θi, φi): an anisotropic one is lit from several
            # azimuths, on the unfolded grid.
            return bin_model(p, stack, theta_i, grid, nodes, peak_nodes, phi_i)
        externals.append((model_name(p), table))
    if not names and not externals and models is not None:
        raise input_error("arguments", "models", "no model to compare")
    _lamina._run_study(configs, run, externals, str(out), bool(figures))
    return load_study(out)


def compare(stack, models=None, out=None, figures=False, quiet=True, config_id=None, nodes=4,
            peak_nodes=32, tables="half", **settings: Any) -> Study:
    """`lamina compare` from Python: the reference for one stack and every model on its bins.

    models: registry names and Python models (classes or objects with eval(wi, wo); see
    lamina.plugins), default every built-in model. settings: the reference's, any of
    SIMULATION_SETTINGS by name (theta_i, particles, seed, grid, kernel, microsurface, ...).
    Writes the study directory `out` (metrics, summary, explorer, and figures when figures=True)
    and returns it as a lamina.Study. tables: how configs/<id>/tables.lza is stored, "half"
    (float16), "full" or "none" (the CLI's --tables).
    """
    if out is None:
        raise input_error("arguments", "out", "give the output folder (out=...)")
    st = Stack(stack)
    cid = config_id or (Path(os.fspath(stack)).stem if isinstance(stack, (str, os.PathLike))
                        else (st.name or "stack"))
    configs = [{"id": cid, "category": "custom", "stack": st}]
    return _run(configs, models, "custom", out, figures, quiet, nodes, peak_nodes, tables,
                settings)


def study(models=None, preset="quick", only=None, configs=None, out=None, figures=False,
          quiet=True, nodes=4, peak_nodes=32, tables="half", **settings: Any) -> Study:
    """`lamina study` from Python, with Python models beside the built-in ones.

    configs: None for the study's configurations at the preset (the 60 and three iridescent ones
    at the quick preset; the iridescent, brushed and dispersive categories whole at the larger
    ones), or a list of {"id", "category", "stack"};
    only: the CLI's --only globs. settings: the reference's, any of SIMULATION_SETTINGS by name;
    particles, when given, replaces the preset's budget. Returns the study directory `out` as a
    lamina.Study.
    """
    if out is None:
        raise input_error("arguments", "out", "give the output folder (out=...)")
    label = preset
    if "particles" in settings:
        _lamina._preset_particles(preset)  # the preset is checked even when not used
        label = "custom"
    else:
        settings = dict(settings, particles=_lamina._preset_particles(preset))
    cs = _lamina._builtin_configurations(preset) if configs is None else [
        {"id": c["id"], "category": c.get("category", "custom"), "stack": Stack(c["stack"])}
        for c in configs]
    if only is not None and not str(only).strip(", "):
        raise input_error("arguments", "only",
                          f"{only!r} names no configuration: give id globs (plastic-*, "
                          "slab-*-clear), or leave it out for every configuration")
    if only:
        keep = set(_lamina._filter_configurations(cs, only))
        cs = [c for c in cs if c["id"] in keep]
    return _run(cs, models, label, out, figures, quiet, nodes, peak_nodes, tables, settings)


