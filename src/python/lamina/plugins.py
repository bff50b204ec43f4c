"""Your own model in lamina's study: a Python class with a vectorized eval (docs/python.md).

A model is a class (instantiated with the stack: ``Model(stack)``) or an object with

- ``eval(wi, wo)``: f in 1/sr (no cosine), wi and wo float64 arrays [N, 3] of unit vectors in
  lamina's frame (wi.z > 0; wo.z < 0 is transmission), returning [N, 3] RGB (required);
- ``name``: its name in the study (default: the class name);
- ``supports(stack)``: (brdf, btdf) booleans, or a dict {"brdf", "btdf", "reason"} (default: the
  BRDF only);
- ``delta_lobes(wi)``: [(direction, energy RGB)] for one wi (smooth interfaces; default none);
- ``peak_directions(wi)``: directions where narrow lobes peak (default: the mirror direction).

lamina averages it over its bins with its own quadrature, in large batches: each bin gets the
``nodes`` x ``nodes`` Gauss-Legendre product rule in (theta, phi) with the weight
sin(theta) cos(theta) (normalized by the same rule, so that constants are exact), and the bins
holding a peak direction get ``peak_nodes`` x ``peak_nodes``. The bins are the goniophotometer's:
for an isotropic stack lit from phi_i = 0 they fold phi and -phi together (the model is evaluated
on phi in [0, 180] degrees); an anisotropic stack, or light from an azimuth phi_i != 0, gets the
unfolded grid (phi in [0, 360) degrees), where the model sees wi and wo in the stack's frame over
the full azimuth (its tangents are in the stack it was made with).
"""

from __future__ import annotations

import inspect

import numpy as np

from . import _lamina

_BATCH = 1 << 18  # directions per eval call


def input_error(file, field, problem):
    """A lamina.InputError with .file, .field and .problem, as the CLI's errors have."""
    e = _lamina.InputError(f"{file}: {field}: {problem}" if field else f"{file}: {problem}")
    e.file, e.field, e.problem = file, field, problem
    return e


# The most Gauss–Legendre nodes a side of a bin: every bin's nodes are evaluated in one array of
# bins × nodes² directions, 0.2 GB at 32 on the default grid; peak bins are a few.
MAX_NODES, MAX_PEAK_NODES = 32, 256


def node_count(field, n, most):
    """A quadrature's nodes a side: an integer in [1, most] (a truth value is not one)."""
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or \
            not 1 <= n <= most:
        raise input_error("arguments", field, f"an integer in [1, {most}], got {n!r}")
    return int(n)


def model_name(obj) -> str:
    name = getattr(obj, "name", None)
    if isinstance(name, str) and name:
        return name
    cls = obj if isinstance(obj, type) else type(obj)
    return cls.__name__


def instantiate(obj, stack):
    """The model object for one stack (a class is called with the stack, or with nothing when its
    constructor takes no argument)."""
    if not isinstance(obj, type):
        return obj
    try:
        inspect.signature(obj).bind(stack)
    except TypeError:
        return obj()
    return obj(stack)


def support(model, stack, name=None):
    fn = getattr(model, "supports", None)
    if fn is None:
        return {"brdf": True, "btdf": False, "reason": ""}
    s = fn(stack)
    if isinstance(s, dict):
        return {"brdf": bool(s.get("brdf", False)), "btdf": bool(s.get("btdf", False)),
                "reason": str(s.get("reason", ""))}
    if not isinstance(s, (tuple, list)) or len(s) != 2:
        raise input_error(f"Python model '{name or model_name(model)}'", "supports",
                          f"returned {s!r}: expected (brdf, btdf) or "
                          '{"brdf": ..., "btdf": ..., "reason": ...}')
    brdf, btdf = s
    return {"brdf": bool(brdf), "btdf": bool(btdf), "reason": ""}


def _directions(name, what, value):
    """A model's directions (peak_directions, delta_lobes): finite non-zero 3-vectors."""
    try:
        d = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        d = None
    if d is None or d.shape != (3,) or not np.all(np.isfinite(d)) or not np.any(d):
        raise input_error(f"Python model '{name}'", what,
                          f"returned the direction {value!r}: expected three finite numbers")
    return d


def _listed(name, what, value):
    """A model's list (of directions, of lobes): any iterable that is not text."""
    if value is None or isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise input_error(f"Python model '{name}'", what, f"returned {value!r}: expected a list")
    return list(value)


def _gauss(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) / 2, w / 2


def _eval(model, name, wi, wo):
    out = np.empty((len(wo), 3))
    for a in range(0, len(wo), _BATCH):
        b = min(len(wo), a + _BATCH)
        f = np.asarray(model.eval(np.broadcast_to(wi, (b - a, 3)), wo[a:b]), dtype=np.float64)
        if f.shape != (b - a, 3):
            raise input_error(f"Python model '{name}'", "eval",
                              f"returned shape {f.shape}, expected ({b - a}, 3)")
        if not np.all(np.isfinite(f)):
            raise input_error(f"Python model '{name}'", "eval", "returned a non-finite value")
        out[a:b] = f
    return out


def _average(model, name, wi, t0, t1, p0, p1, n, lower):
    """Cos-weighted averages over the rectangles [t0, t1] x [p0, p1] (arrays, radians)."""
    x, w = _gauss(n)
    theta = t0[:, None] + (t1 - t0)[:, None] * x[None, :]          # [bins, n]
    phi = p0[:, None] + (p1 - p0)[:, None] * x[None, :]            # [bins, n]
    st, ct = np.sin(theta), np.cos(theta)
    wo = np.stack(np.broadcast_arrays(
        st[:, :, None] * np.cos(phi)[:, None, :], st[:, :, None] * np.sin(phi)[:, None, :],
        (-ct if lower else ct)[:, :, None]), axis=-1)              # [bins, n, n, 3]
    f = _eval(model, name, wi, wo.reshape(-1, 3)).reshape(wo.shape)
    weight = (w[None, :] * st * ct)[:, :, None] * w[None, None, :]  # [bins, n, n]
    return np.einsum("bij,bijc->bc", weight, f) / weight.sum(axis=(1, 2))[:, None]


def bin_model(obj, stack, theta_i, grid=None, nodes=4, peak_nodes=32, phi_i=0.0):
    """A Python model on lamina's bins: a lamina.Table (the brdf.csv format), or None when the
    model supports neither side of this stack. grid: (n_theta, n_phi), default the
    goniophotometer's. phi_i: the light's azimuth in degrees, one for every incidence or one per
    incidence (wi = (sin θi cos φi, sin θi sin φi, cos θi)). The bins are those the
    goniophotometer tabulates: folded (φ over [0°, 180°], each bin both halves ±φ) for an
    isotropic stack lit from φi = 0, unfolded otherwise (an anisotropic stack, or some φi ≠ 0:
    2 n_phi bins over [0°, 360°), each one patch), where the model gets wo over the full azimuth
    in the stack's frame."""
    nodes = node_count("nodes", nodes, MAX_NODES)
    peak_nodes = node_count("peak_nodes", peak_nodes, MAX_PEAK_NODES)
    stack = _lamina.Stack(stack)
    model = instantiate(obj, stack)
    name = model_name(obj)
    sup = support(model, stack, name)
    sides = (["R"] if sup["brdf"] else []) + (["T"] if sup["btdf"] and stack.transmits else [])
    if not sides:
        return None
    if np.asarray(theta_i).dtype.kind == "b":
        raise input_error("arguments", "theta_i", f"expected degrees, got {theta_i!r}")
    theta_i = [float(t) for t in np.atleast_1d(theta_i)]
    if not theta_i:
        raise input_error("arguments", "theta_i", "at least one incidence is needed")
    for t in theta_i:  # checked before the model is asked anything
        if not 0 <= t < 90:  # NaN too
            raise input_error("arguments", "theta_i", f"{t} degrees is outside [0, 90)")
    if np.asarray(phi_i).dtype.kind == "b":
        raise input_error("arguments", "phi_i", f"expected degrees, got {phi_i!r}")
    phi = np.atleast_1d(np.asarray(phi_i, dtype=np.float64))
    if phi.ndim == 1 and len(phi) == 1:
        phi = np.full(len(theta_i), phi[0])
    if phi.ndim != 1 or len(phi) != len(theta_i) or not np.all((phi >= 0) & (phi <= 360)):
        raise input_error("arguments", "phi_i",
                          "one azimuth in [0, 360] degrees, or one per incidence")  # NaN too
    phi_i = [float(p) for p in phi]
    if grid is None:
        default = _lamina.SIMULATION_SETTINGS["grid"]
        grid = (default["n_theta"], default["n_phi"])
    if isinstance(grid, dict):  # as simulate takes it
        grid = (grid.get("n_theta"), grid.get("n_phi"))
    try:
        counts = [int(g) for g in grid]
        if len(counts) != 2 or any(c != g for c, g in zip(counts, grid)):
            raise ValueError
    except (TypeError, ValueError, OverflowError):
        raise input_error("arguments", "grid", f"expected (n_theta, n_phi), got {grid!r}")
    if not all(1 <= c <= _lamina.GRID_MAX_COUNT for c in counts):  # as --grid
        raise input_error("arguments", "grid", f"{counts[0]} × {counts[1]} bins: allowed counts "
                          f"in [1, {_lamina.GRID_MAX_COUNT}] along θ and φ")
    unfolded = _lamina._unfolded(stack, phi_i)
    n_theta = counts[0]
    n_phi = counts[1] * (2 if unfolded else 1)      # φ bins of the table
    span = 2 * np.pi if unfolded else np.pi
    t_edges = np.linspace(0, np.pi / 2, n_theta + 1)
    p_edges = np.linspace(0, span, n_phi + 1)
    tt, pp = np.meshgrid(np.arange(n_theta), np.arange(n_phi), indexing="ij")
    t0, t1 = t_edges[tt.ravel()], t_edges[tt.ravel() + 1]
    p0, p1 = p_edges[pp.ravel()], p_edges[pp.ravel() + 1]
    # Ω⊥: both folded halves, or one patch of the unfolded grid.
    omega = (p1 - p0) * (np.sin(t1) ** 2 - np.sin(t0) ** 2) / (2 if unfolded else 1)
    f = np.zeros((len(theta_i), len(sides), n_theta * n_phi, 3))

    def bin_of(d):
        d = np.asarray(d, dtype=np.float64)
        theta = np.arccos(min(1.0, abs(d[2])))
        phi = np.arctan2(d[1], d[0]) % (2 * np.pi) if unfolded else np.arctan2(abs(d[1]), d[0])
        return (min(n_theta - 1, int(theta / (np.pi / 2) * n_theta)) * n_phi
                + min(n_phi - 1, int(phi / span * n_phi)))

    for i, (ti, pi) in enumerate(zip(theta_i, phi_i)):
        a, b = np.radians(ti), np.radians(pi)
        wi = np.array([np.sin(a) * np.cos(b), np.sin(a) * np.sin(b), np.cos(a)])
        peaks_fn = getattr(model, "peak_directions", None)
        peaks = [_directions(name, "peak_directions", p) for p in _listed(
            name, "peak_directions", peaks_fn(wi))] if peaks_fn else \
            [np.array([-wi[0], -wi[1], wi[2]])]
        for k, side in enumerate(sides):
            lower = side == "T"
            f[i, k] = _average(model, name, wi, t0, t1, p0, p1, nodes, lower)
            fine = sorted({bin_of(p) for p in peaks if (p[2] < 0) == lower})
            if fine:
                fine = np.array(fine)
                f[i, k, fine] = _average(model, name, wi, t0[fine], t1[fine], p0[fine],
                                         p1[fine], peak_nodes, lower)
        lobes = getattr(model, "delta_lobes", None)
        for lobe in (_listed(name, "delta_lobes", lobes(wi)) if lobes else []):
            if not isinstance(lobe, (tuple, list)) or len(lobe) != 2:
                raise input_error(f"Python model '{name}'", "delta_lobes",
                                  f"returned {lobe!r}: expected (direction, energy) pairs")
            direction = _directions(name, "delta_lobes", lobe[0])
            try:
                energy = np.broadcast_to(np.asarray(lobe[1], dtype=np.float64), (3,))
            except (TypeError, ValueError):
                energy = np.array([np.nan])
            if energy.shape != (3,) or not np.all(np.isfinite(energy)):
                raise input_error(f"Python model '{name}'", "delta_lobes",
                                  f"returned the energy {lobe[1]!r}: expected a finite number "
                                  "or three (RGB)")
            side = "T" if direction[2] < 0 else "R"
            if side in sides:
                j = bin_of(direction)
                f[i, sides.index(side), j] += energy / omega[j]
    f = f.reshape(len(theta_i), len(sides), n_theta, n_phi, 3)
    return _lamina._table_from_arrays(f, theta_i, sides, unfolded)
