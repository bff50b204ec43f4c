#!/usr/bin/env python3
"""Paper-ready figures of a lamina study directory (docs/explorer.md, "Figures").

    figures.py STUDY_DIR [--formats png,pdf,svg] [--only GLOB[,GLOB...]] [--jobs N] [--force]

Reads study.json, metrics.csv and configs/<id>/{config.json, tables.lza, reference_se.lza}
(docs/formats.md) and writes STUDY_DIR/figures/:

  slices/<id>-R.<fmt> (and -T for slabs)  incident-plane slices: rows = incidences, columns = RGB
                                          channels; reference with its ±2·se band, every model
  error-matrix-R.<fmt> (and -T)           configurations × models, mean misplaced energy with the 5%
                                          floor (misplaced_floor), log colours, the noise floor as
                                          the first column, models ranked (best first)
  albedo-<category>.<fmt>                 directional albedo against θi, one panel per configuration
  colour/<id>-R.<fmt> (and -T for slabs)  the colour (sRGB) of f along the incident plane, the
                                          reference and every model, one panel per incidence

Only the figures whose inputs changed are drawn again (their digests are in figures/.inputs.json;
--force redraws all), in parallel over the cores (--jobs, default every core).

`lamina figures` runs this script (embedded in the binary) with Debian's python3; it can also be run
directly. Exit code 3: matplotlib or numpy is missing (install python3-matplotlib: `make deps`).
"""
import argparse
import csv
import fnmatch
import glob
import hashlib
import json
import math
import os
import signal
import sys
import time

try:
    import numpy as np
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm, Normalize
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator
except ImportError as e:  # pragma: no cover - reported by `lamina figures`
    print(f"figures.py: {e}: install Debian's python3-matplotlib and python3-numpy (make deps)",
          file=sys.stderr)
    sys.exit(3)


def load_array_reader():
    """read_array of lamina's packed arrays (src/python/lamina/arrays.py, numpy only, the one
    reader of the format in Python). `lamina figures` passes its embedded copy in
    $LAMINA_ARRAYS_PY; run from the repository, the script reads the file."""
    text = os.environ.get("LAMINA_ARRAYS_PY")
    if not text:
        here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else ""
        with open(os.path.join(here, "..", "src", "python", "lamina", "arrays.py")) as f:
            text = f.read()
    namespace = {}
    exec(compile(text, "lamina/arrays.py", "exec"), namespace)
    return namespace["read_array"]


read_array = load_array_reader()


def read_palette():
    """The model colours: web/model-colors.json, the one table the explorer page reads too.
    `lamina figures` passes its embedded copy in $LAMINA_MODEL_COLORS; run from the repository,
    the script reads the file beside it."""
    text = os.environ.get("LAMINA_MODEL_COLORS")
    if not text:
        here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else ""
        path = os.path.join(here, "..", "web", "model-colors.json")
        if os.path.exists(path):
            with open(path) as f:
                text = f.read()
    palette = json.loads(text) if text else {}
    return (palette.get("models", {}), palette.get("extra", ["#555555"]),
            {m: (0, (4, 2)) for m in palette.get("dashed", [])})


MODEL_COLORS, EXTRA_COLORS, MODEL_DASH = read_palette()
CHANNELS = ["R", "G", "B"]
SIDE_NAME = {"R": "BRDF", "T": "BTDF"}

plt.rcParams.update({
    "font.family": "DejaVu Sans", "font.size": 8, "axes.titlesize": 8, "axes.labelsize": 8,
    "legend.fontsize": 7, "xtick.labelsize": 7, "ytick.labelsize": 7, "axes.linewidth": 0.6,
    "lines.linewidth": 1.1, "pdf.fonttype": 42, "svg.fonttype": "none", "savefig.dpi": 160,
    "figure.dpi": 100, "svg.hashsalt": "lamina",
})


def model_dash(name):
    """Variants dashed; an ablation ("openpbr:darkening=off") dashed in its model's colour."""
    return MODEL_DASH.get(name, (0, (4, 2)) if ":" in name else "-")


def model_color(name, models):
    if name in MODEL_COLORS:
        return MODEL_COLORS[name]
    if name.split(":")[0] in MODEL_COLORS:  # an ablation ("openpbr:darkening=off"): dashed
        return MODEL_COLORS[name.split(":")[0]]
    k = models.index(name) if name in models else 0
    return EXTRA_COLORS[k % len(EXTRA_COLORS)]


# The temporary files this process is writing: removed when it is stopped (end_on_signal).
WRITING = set()


def end_on_signal(signum, frame):
    """SIGTERM (lamina stopped, which stops this script) or, in a worker, SIGINT: no half-written
    file stays behind and no worker goes on drawing. The signal's exit status, without Python's
    traceback."""
    import multiprocessing
    for child in multiprocessing.active_children():
        child.terminate()
    for path in list(WRITING):
        try:
            os.unlink(path)
        except OSError:
            pass
    os._exit(128 + signum)


def save(fig, path_stem, formats, tight=True, box=None):
    """Writes each format, atomically (a temporary file renamed into place). `tight=False` for
    figures laid out by hand: matplotlib's tight boxes measure every tick label again, the bulk of
    the time for grids of log axes. `box`: the bounding box (inches) measured by the caller."""
    os.makedirs(os.path.dirname(path_stem), exist_ok=True)
    # No creation dates: the same study gives byte-identical PDF and SVG files.
    metadata = {"pdf": {"CreationDate": None}, "svg": {"Date": None}, "png": {}}
    for f in formats:
        tmp = f"{path_stem}.tmp-{os.getpid()}.{f}"
        bbox = box if box is not None else "tight" if tight else None
        WRITING.add(tmp)
        fig.savefig(tmp, bbox_inches=bbox, metadata=metadata[f])
        os.replace(tmp, f"{path_stem}.{f}")
        WRITING.discard(tmp)
    plt.close(fig)


def omega_perp(n_theta, n_phi):
    """Ω⊥ of the folded grid's bins (docs/formats.md), shape [n_theta, 1]: Δφ (sin²θ1 − sin²θ0).
    It mirrors lamina's one formula (HemisphereGrid::projected_solid_angle, src/core/grid.cpp);
    the study's CLI test checks that the albedo it gives from tables.lza is metrics.csv's
    albedo_ref, which lamina computes with its own."""
    edges = np.radians(np.linspace(0, 90, n_theta + 1))
    s2 = np.sin(edges) ** 2
    return ((s2[1:] - s2[:-1]) * math.pi / n_phi)[:, None]


class Study:
    def __init__(self, root):
        self.root = root
        path = os.path.join(root, "study.json")
        try:
            with open(path) as f:
                self.meta = json.load(f)
        except OSError as e:
            sys.exit(f"figures.py: {path}: {e.strerror}")
        self.theta_i = [float(t) for t in self.meta["theta_i"]]
        self.n_theta = int(self.meta["grid"]["n_theta"])
        self.n_phi = int(self.meta["grid"]["n_phi"])
        self.configs = self.meta["configurations"]
        self.models = list(self.meta.get("models") or [])
        # Each configuration's incidences [(θi, φi)]: an unfolded one's own (study.json
        # configurations[].incidences: an anisotropic stack, lit from several azimuths, on the
        # unfolded grid; docs/formats.md), else the study's θi at φi = 0.
        self.incidences = {c["id"]: [tuple(map(float, x)) for x in c["incidences"]]
                           if c.get("incidences") else [(t, 0.0) for t in self.theta_i]
                           for c in self.configs}
        self._unfolded = {c["id"] for c in self.configs if c.get("incidences")}
        self.metrics = self._read_metrics()

    def unfolded(self, cid):
        return cid in self._unfolded

    def n_phi_of(self, cid):
        """The φ bins of a configuration's tables: 2 · n_phi over [0°, 360°) when unfolded."""
        return 2 * self.n_phi if self.unfolded(cid) else self.n_phi

    def _read_metrics(self):
        """{(config, model, side): {'me': [I][3], 'nf': [I][3], 'mf': …, 'nf_mf': …}} with NaN for
        unsupported: misplaced energy (relative, 'me', and floored, 'mf') and their noise floors.
        A study written before misplaced_floor existed has its 'mf' and 'nf_mf' all NaN."""
        out = {}
        self.has_floored = False
        path = os.path.join(self.root, "metrics.csv")
        if not os.path.exists(path):
            return out
        columns = (("me", "misplaced_energy"), ("nf", "noise_floor"), ("mf", "misplaced_floor"),
                   ("nf_mf", "misplaced_floor_noise"))
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            self.has_floored = "misplaced_floor" in (reader.fieldnames or [])
            for row in reader:
                key = (row["config"], row["model"], row["side"])
                incs = self.incidences.get(row["config"], [(t, 0.0) for t in self.theta_i])
                cell = out.setdefault(key, {k: np.full((len(incs), 3), np.nan)
                                            for k, _ in columns})
                # The phi_i column: only in a study with light off φ = 0.
                inc = (float(row["theta_i"]), float(row.get("phi_i") or 0))
                try:
                    i = incs.index(inc)
                except ValueError:
                    continue
                c = "rgb".index(row["channel"])
                if row["supported"] == "true":
                    for k, col in columns:
                        if row.get(col):
                            cell[k][i, c] = float(row[col])
        return out

    def load(self, cid):
        d = os.path.join(self.root, "configs", cid)
        with open(os.path.join(d, "config.json")) as f:
            cfg = json.load(f)
        tables = read_array(table_path(d, "tables"))
        se_path = table_path(d, "reference_se")
        se = read_array(se_path) if os.path.exists(se_path) else None
        return cfg, tables, se

    def load_albedos(self, cid):
        """config.json (its per-source albedos: Σ f Ω⊥ of each table, in double, as the study
        summed them) and the reference's standard errors, without the tables themselves."""
        d = os.path.join(self.root, "configs", cid)
        with open(os.path.join(d, "config.json")) as f:
            cfg = json.load(f)
        se_path = table_path(d, "reference_se")
        se = read_array(se_path) if os.path.exists(se_path) else None
        return cfg, se


def supported(cfg, model, side):
    if model not in cfg["sources"]:
        return False
    s = (cfg.get("supported") or {}).get(model)
    return True if s is None else s.get(side, True) is not False


def pick_incidences(theta_i, wanted=(0, 45, 70)):
    """Up to three incidences closest to 0°, 45° and 70° (distinct), in order."""
    out = []
    for w in wanted:
        k = min(range(len(theta_i)), key=lambda i: abs(theta_i[i] - w))
        if k not in out:
            out.append(k)
    return sorted(out)


def plane_bins(n_phi, phi_deg):
    """The unfolded φ bins (n_phi over [0°, 360°)) the half-plane at azimuth phi_deg runs through:
    the bin it crosses, or the two it separates when it lies on an edge (equal Ω⊥: their mean is
    the plane's value), as the explorer takes them."""
    u = (phi_deg % 360.0) / (360.0 / n_phi)
    k = round(u)
    if abs(u - k) < 1e-9:
        return [(k - 1) % n_phi, k % n_phi]
    return [int(math.floor(u)) % n_phi]


# ---- Per-configuration incident-plane slices ----------------------------------------------------

def plane_incidences(study, cid):
    """The incidences a configuration's plane figures show, the φ bins of their planes (light's
    side, mirror side) and their labels."""
    incidences = study.incidences[cid]
    if study.unfolded(cid):
        # Lit from several azimuths: the incidence nearest θi = 45° at each, on its own plane of
        # incidence φ = φi (the light's side) and φi + 180° (the mirror's).
        P = study.n_phi_of(cid)
        thetas = sorted({t for t, _ in incidences})
        t45 = min(thetas, key=lambda t: abs(t - 45))
        incs = [k for k, (t, _) in enumerate(incidences) if t == t45]
        bins = {k: (plane_bins(P, incidences[k][1]), plane_bins(P, incidences[k][1] + 180))
                for k in incs}
    else:
        incs = pick_incidences(study.theta_i)
        bins = {k: ([0], [-1]) for k in incs}
    label = lambda i: (f"θi = {incidences[i][0]:g}°, φi = {incidences[i][1]:g}°"
                       if study.unfolded(cid) else f"θi = {incidences[i][0]:g}°")
    return incs, bins, label


def plane_values(tables, s, i, d, c, bins):
    """f of source s, incidence i, side d, channel c along the plane of incidence: the light's
    side (θ descending) then the mirror side, each the mean of its plane's φ bins."""
    light, mirror = bins
    half = lambda a, b: np.mean(np.asarray(a[..., b], dtype=np.float64), axis=-1)
    return np.concatenate([half(tables[s, i, d, ::-1, :, c], light),
                           half(tables[s, i, d, :, :, c], mirror)])


def slice_figure(study, cid, formats):
    root = study.root
    cfg, tables, se = study.load(cid)
    T = study.n_theta
    centres = (np.arange(T) + 0.5) * 90.0 / T
    x = np.concatenate([-centres[::-1], centres])  # negative: the light's side (φ bin 0)
    incs, bins, label = plane_incidences(study, cid)
    # Ablations (NAME:KEY=VALUE) stay in the error matrix; the slices show the models as shipped.
    models = [m for m in cfg["sources"][1:] if ":" not in m]
    for d, side in enumerate(cfg["sides"]):
        ns = [m for m in models if not supported(cfg, m, side)]
        top = 0.55 + (0.17 if ns else 0.0)  # inches above the panels: title, channel names
        height = 1.85 * len(incs) + 0.55 + top
        fig, axes = plt.subplots(len(incs), 3, figsize=(7.0, height), sharex=True, squeeze=False)
        # Fixed margins (inches) instead of tight_layout: a third of the time per figure.
        fig.subplots_adjust(left=0.85 / 7.0, right=1 - 0.1 / 7.0, bottom=0.85 / height,
                            top=1 - top / height, wspace=0.28, hspace=0.12)
        for r, i in enumerate(incs):
            for c in range(3):
                ax = axes[r][c]
                light, mirror = bins[i]
                # the mean of the plane's bins (one bin folded, or off an edge)
                half = lambda a, b: np.mean(np.asarray(a[..., b], dtype=np.float64), axis=-1)
                plane = lambda s: plane_values(tables, s, i, d, c, bins[i])
                ref = plane(0)
                if se is not None:
                    e = np.concatenate([half(se[i, d, ::-1, :, c], light),
                                        half(se[i, d, :, :, c], mirror)])
                    lo = np.where(ref - 2 * e > 0, ref - 2 * e, ref * 1e-3)
                    ax.fill_between(x, lo, ref + 2 * e, color="0.75", lw=0,
                                    label="reference ±2·se")
                ax.plot(x, ref, color="k", lw=1.4, label="reference")
                top = np.nanmax(ref) if np.any(ref > 0) else 0.0
                for m in models:
                    if supported(cfg, m, side):
                        f = plane(cfg["sources"].index(m))
                        ax.plot(x, f, color=model_color(m, study.models), label=m,
                                ls=model_dash(m))
                        if np.any(f > 0):
                            top = max(top, float(np.nanmax(f)))
                positive = ref[ref > 0]
                lo, hi = 1e-3, 1.0
                if positive.size:
                    lo, hi = max(positive.min(), top * 1e-5) * 0.5, top * 2
                # Limits before the log scale: a side with nothing on it (an opaque slab's
                # transmission) keeps the default decades instead of a warning.
                ax.set_ylim(lo, hi)
                ax.set_yscale("log")
                # Plain-number ticks: decades on a wide range, 1-2-5 on a short one.
                ax.yaxis.set_major_locator(LogLocator(10, subs=(1.0,) if hi / lo > 300 else (1.0, 2.0, 5.0)))
                ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                ax.yaxis.set_minor_locator(NullLocator())
                ax.set_xlim(-90, 90)
                ax.set_xticks([-90, -60, -30, 0, 30, 60, 90])
                ax.grid(True, lw=0.3, color="0.88")
                if r == 0:
                    ax.set_title(f"{CHANNELS[c]} channel", color=["#b8322f", "#2e8540", "#2c5aa0"][c])
                if c == 0:
                    ax.set_ylabel(f"{label(i)}\n{SIDE_NAME[side]} f (1/sr)")
                if r == len(incs) - 1:
                    ax.set_xlabel("θo (°), light's side negative")
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 8), frameon=False,
                   bbox_to_anchor=(0.5, 0.0), columnspacing=0.9, handlelength=1.3)
        title = f"{cid} — {SIDE_NAME[side]} on the incident plane" + (
            " (φ = φi, and φi + 180° on the mirror's side)" if study.unfolded(cid) else "")
        if ns:
            title += "\nnot supported: " + ", ".join(ns)
        fig.suptitle(title, fontsize=9, y=1 - 0.08 / height, va="top")
        save(fig, os.path.join(root, "figures", "slices", f"{cid}-{side}"), formats, tight=False)
    return cid


# ---- Per-configuration colour strips ------------------------------------------------------------

def srgb_encode(v):
    """The sRGB transfer curve (IEC 61966-2-1:1999 §5.2) of linear values in [0, 1]."""
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(np.maximum(v, 0.0031308), 1 / 2.4) - 0.055)


def shown_srgb(rgb):
    """The colour shown for linear RGB already times the exposure, [..., 3] → sRGB in [0, 1], as the
    explorer shows it (docs/explorer.md, "Colour"): negative channels (outside sRGB's gamut) as 0,
    a value whose largest channel exceeds 1 divided by it (its hue kept), then the transfer curve."""
    c = np.maximum(np.nan_to_num(rgb, nan=0.0), 0.0)
    m = c.max(axis=-1, keepdims=True)
    return srgb_encode(np.where(m > 1, c / np.where(m > 1, m, 1.0), c))


def colour_figure(study, cid, formats):
    """The colour of f along the plane of incidence, reference and models, one panel per incidence
    (those of the slices), at one exposure per panel: whole stops below the reference's largest
    channel on the plane (2^−⌈log2 m⌉), so that none of its bins clips."""
    cfg, tables, _ = study.load(cid)
    T = study.n_theta
    incs, bins, label = plane_incidences(study, cid)
    models = [m for m in cfg["sources"][1:] if ":" not in m]
    for d, side in enumerate(cfg["sides"]):
        rows = ["reference"] + [m for m in models if supported(cfg, m, side)]
        ns = [m for m in models if not supported(cfg, m, side)]
        panel = 0.32 * len(rows) + 0.75
        height = panel * len(incs) + 0.75 + (0.17 if ns else 0.0)
        fig, axes = plt.subplots(len(incs), 1, figsize=(7.0, height), squeeze=False)
        fig.subplots_adjust(left=1.6 / 7.0, right=1 - 0.15 / 7.0, bottom=0.5 / height,
                            top=1 - (0.5 + (0.17 if ns else 0.0)) / height, hspace=0.6)
        for r, i in enumerate(incs):
            ax = axes[r][0]
            rgb = np.stack([np.stack([plane_values(tables, cfg["sources"].index(s), i, d, c, bins[i])
                                      for c in range(3)], axis=-1) for s in rows])  # [row, 2T, 3]
            m = np.nanmax(rgb[0]) if np.any(rgb[0] > 0) else 1.0
            k = 2.0 ** -math.ceil(math.log2(m))
            image = shown_srgb(rgb * k)
            image[np.isnan(rgb).any(axis=-1)] = 1.0  # a bin without a value: white
            ax.imshow(image, extent=(-90, 90, len(rows), 0), aspect="auto", interpolation="nearest")
            ax.set_yticks(np.arange(len(rows)) + 0.5)
            ax.set_yticklabels(rows, fontsize=7)
            for tick, s in zip(ax.get_yticklabels(), rows):
                if s != "reference":
                    tick.set_color(model_color(s, study.models))
            ax.set_xlim(-90, 90)
            ax.set_xticks([-90, -60, -30, 0, 30, 60, 90])
            ax.tick_params(labelsize=7)
            ax.set_title(f"{label(i)} · exposure 2^{-math.ceil(math.log2(m)):d} sr", fontsize=8)
            if r == len(incs) - 1:
                ax.set_xlabel("θo (°), light's side negative", fontsize=8)
        title = (f"{cid} — colour of {SIDE_NAME[side]} f on the incident plane (linear RGB × "
                 "exposure, sRGB)")
        if ns:
            title += "\nnot supported: " + ", ".join(ns)
        fig.suptitle(title, fontsize=9, y=1 - 0.08 / height, va="top")
        save(fig, os.path.join(study.root, "figures", "colour", f"{cid}-{side}"), formats,
             tight=False)
    return cid


# ---- The configurations × models error matrix --------------------------------------------------

def error_matrix(study, formats, side):
    """The matrix of one side, by the floored misplaced energy (the study's ranking metric; the
    relative one for a study written before it existed)."""
    metric, floor_key = ("mf", "nf_mf") if study.has_floored else ("me", "nf")
    label = "misplaced energy, 5% floor" if study.has_floored else "misplaced energy"
    rows = [c for c in study.configs if side in c["sides"]]

    def mean_of(m):  # over the configurations the model supports: its rank
        v = [np.nanmean(c[metric]) for c in (study.metrics.get((cfg["id"], m, side))
                                               for cfg in rows)
             if c is not None and not np.all(np.isnan(c[metric]))]
        return float(np.mean(v)) if v else math.inf

    models = sorted(study.models, key=mean_of)  # stable: ties keep the study's order
    cols = ["noise floor"] + models
    z = np.full((len(rows), len(cols)), np.nan)
    ns = np.zeros_like(z, dtype=bool)
    for r, cfg in enumerate(rows):
        for k, m in enumerate(models):
            cell = study.metrics.get((cfg["id"], m, side))
            if cell is None or np.all(np.isnan(cell[metric])):
                ns[r, k + 1] = True
                continue
            z[r, k + 1] = np.nanmean(cell[metric])
            if np.isnan(z[r, 0]):
                z[r, 0] = np.nanmean(cell[floor_key])
    fig, ax = plt.subplots(figsize=(1.1 + 0.75 * len(cols), 0.8 + 0.16 * len(rows)))
    # The scale spans the cells' positive values above 1e-12 (a relative error, numerically 0
    # below it: a slab that transmits nothing has values of 1e-49, which matplotlib's float32
    # image rounds to 0 and its log scale then cannot take); none: an empty scale.
    finite = z[np.isfinite(z) & (z > 1e-12)]
    norm = (LogNorm(vmin=finite.min(), vmax=finite.max()) if finite.size
            else Normalize(vmin=0, vmax=1))
    im = ax.imshow(np.ma.masked_invalid(z), aspect="auto", cmap="YlOrRd", norm=norm,
                   interpolation="nearest")
    ax.set_facecolor("0.9")
    ax.set_xticks(range(len(cols)), cols, rotation=35, ha="left")
    ax.xaxis.tick_top()
    ax.set_yticks(range(len(rows)), [c["id"] for c in rows], fontsize=6)
    ax.axvline(0.5, color="k", lw=0.8)
    for r in range(1, len(rows)):  # a line between categories
        if rows[r]["category"] != rows[r - 1]["category"]:
            ax.axhline(r - 0.5, color="k", lw=0.8)
    cb = fig.colorbar(im, ax=ax, fraction=0.04, pad=0.02)
    cb.set_label(f"{label} (mean over θi and RGB)")
    ax.set_title(f"{SIDE_NAME[side]}: {label}, configurations × models, best first "
                 "(≈: within 2× the noise floor; n/s: not supported)", fontsize=8, pad=6)
    # The tight box of everything outside the cells, measured before the cells' values are
    # written (they lie inside the axes): measuring the one or two thousand cell texts for
    # savefig's bbox_inches="tight" cost as much as drawing them.
    box = fig.get_tightbbox(fig.canvas.get_renderer()).padded(0.1)
    for r in range(len(rows)):
        for k in range(len(cols)):
            if ns[r, k]:
                ax.text(k, r, "n/s", ha="center", va="center", fontsize=5.5, color="0.35")
            elif np.isfinite(z[r, k]):
                below = k > 0 and np.isfinite(z[r, 0]) and z[r, k] <= 2 * z[r, 0]
                v = z[r, k]
                dark = norm is not None and norm(v) > 0.6
                ax.text(k, r, f"{v:.2g}" + ("≈" if below else ""), ha="center", va="center",
                        fontsize=5.5, color="white" if dark else "black")
    save(fig, os.path.join(study.root, "figures", f"error-matrix-{side}"), formats, box=box)


# ---- Albedo against θi, per category -----------------------------------------------------------

def albedo_figure(study, cat, formats):
    # Ω⊥ per bin; an unfolded bin (half the width of φ of 2 · n_phi over [0°, 360°), one patch)
    # has the folded formula's value for 2 · n_phi bins.
    oms = {False: omega_perp(study.n_theta, study.n_phi),
           True: omega_perp(study.n_theta, 2 * study.n_phi)}
    cache = {c["id"]: study.load_albedos(c["id"]) for c in study.configs if c["category"] == cat}
    members = [c for c in study.configs if c["category"] == cat]
    ncol = min(5, len(members))
    nrow = math.ceil(len(members) / ncol)
    width = max(1.6 * ncol + 0.7, 3.6)
    # The legend: one entry per 1.2 inch of width, as many rows as that takes.
    entries = 2 + len(study.models)
    legend_cols = max(2, min(entries, int(width / 1.2)))
    legend_rows = math.ceil(entries / legend_cols)
    bottom = 0.55 + 0.2 * legend_rows
    height = 1.5 * nrow + 0.45 + bottom
    fig, axes = plt.subplots(nrow, ncol, figsize=(width, height), sharex=True, sharey=True,
                             squeeze=False)
    fig.subplots_adjust(left=0.6 / width, right=1 - 0.1 / width, bottom=bottom / height,
                        top=1 - 0.45 / height, wspace=0.08, hspace=0.3)
    for ax in axes.flat[len(members):]:
        ax.axis("off")
    for ax, meta in zip(axes.flat, members):
        cfg, se = cache[meta["id"]]
        unfolded = study.unfolded(meta["id"])
        om = oms[unfolded]
        # Against θi at φi = 0° (an unfolded configuration's other azimuths are in its slices).
        incidences = study.incidences[meta["id"]]
        ks = [k for k, (_, p) in enumerate(incidences) if p == incidences[0][1]]
        thetas = [incidences[k][0] for k in ks]
        for d, side in enumerate(cfg["sides"]):
            style = "-" if side == "R" else ":"
            # Σ f Ω⊥ per source and incidence (config.json), averaged over RGB; NaN where a
            # source does not support the side.
            def source_albedo(src):
                per_incidence = (cfg["albedo"].get(src) or {}).get(side) or [None] * len(incidences)
                return [np.nan if per_incidence[k] is None else float(np.mean(per_incidence[k]))
                        for k in ks]

            alb = np.array([source_albedo(src) for src in cfg["sources"]])
            err = None
            if se is not None:
                v = ((np.asarray(se[ks, d]) * om[None, :, :, None]) ** 2).sum(axis=(1, 2))
                err = 2 * np.sqrt(v.mean(axis=-1))
            ax.errorbar(thetas, alb[0], yerr=err, color="k", lw=1.3, ls=style,
                        capsize=1.5, elinewidth=0.6,
                        label="reference ±2·se" + (" (T dotted)" if side == "T" else ""))
            for k, m in enumerate(cfg["sources"][1:]):
                if supported(cfg, m, side) and ":" not in m:
                    ax.plot(thetas, alb[k + 1], color=model_color(m, study.models),
                            ls=model_dash(m) if side == "R" else ":", lw=0.9, label=m)
        # What the reference loses to its single-scattering microsurfaces (config.json energy):
        # on neither side, so a model that keeps it overshoots the albedo by as much.
        lost = [e.get("lost_microsurface") for e in cfg.get("energy", [])]
        if lost and len(lost) == len(incidences) and all(lost) and max(map(max, lost)) > 0:
            ax.plot(thetas, [sum(lost[k]) / 3 for k in ks], color="0.55", ls="--", lw=0.8,
                    marker="x", ms=2.5, label="reference: lost to microsurfaces")
        ax.set_title(meta["id"] + (f" (φi = {incidences[0][1]:g}°)" if unfolded else ""),
                     fontsize=6.5)
        ax.grid(True, lw=0.3, color="0.88")
        ax.set_xticks([0, 30, 60, 90])
    for ax in axes[-1]:
        ax.set_xlabel("θi (°)")
    for row in axes:
        row[0].set_ylabel("albedo (RGB mean)")
    seen = {}
    for ax in axes.flat:
        for h, l in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(l.replace(" (T dotted)", ""), h)
    order = sorted(seen, key=lambda l: (0 if l.startswith("reference ±") else
                                        1 if l.startswith("reference") else 2,
                                        study.models.index(l) if l in study.models else 0))
    fig.legend([seen[l] for l in order], order, loc="lower center", ncol=legend_cols,
               frameon=False, columnspacing=0.9, handlelength=1.5)
    fig.suptitle(f"{cat}: directional albedo against θi"
                 + (" (transmission dotted)" if any(
                     "T" in c["sides"] for c in members) else ""), fontsize=9,
                 y=1 - 0.08 / height, va="top")
    save(fig, os.path.join(study.root, "figures", f"albedo-{cat}"), formats, tight=False)


# ---- What to draw, and what is already drawn ----------------------------------------------------
#
# Each figure is a task with the digest of everything it is drawn from (the files it reads, the
# study's axes, the formats, the palette, this script). figures/.inputs.json keeps the digest of
# every figure drawn; a figure whose digest is unchanged and whose files are all there is not drawn
# again. The tasks run in parallel over the cores (one process each, forked).

_STUDY = None  # set before the worker processes fork, shared by them
_FILE_DIGESTS = {}


def file_digest(path):
    if path not in _FILE_DIGESTS:
        h = hashlib.sha1()
        try:
            with open(path, "rb") as f:
                for block in iter(lambda: f.read(1 << 20), b""):
                    h.update(block)
        except OSError:
            h.update(b"missing")
        _FILE_DIGESTS[path] = h.hexdigest()
    return _FILE_DIGESTS[path]


def table_path(d, stem):
    """configs/<id>/<stem>.lza, or .npy from a study written before packed arrays."""
    packed, npy = os.path.join(d, stem + ".lza"), os.path.join(d, stem + ".npy")
    return npy if not os.path.exists(packed) and os.path.exists(npy) else packed


def config_files(study, cid):
    d = os.path.join(study.root, "configs", cid)
    return [os.path.join(d, "config.json"), table_path(d, "tables"),
            table_path(d, "reference_se")]


def has_tables(study, cid):
    return os.path.exists(table_path(os.path.join(study.root, "configs", cid), "tables"))


def plan(study, ids, formats, script_id):
    """[(name, kind, argument, outputs, digest)] of every figure this study has."""
    common = json.dumps([script_id, formats, study.theta_i, study.n_theta, study.n_phi,
                         study.models, MODEL_COLORS, EXTRA_COLORS, sorted(MODEL_DASH)])
    fig_dir = os.path.join(study.root, "figures")
    outs = lambda stem: [os.path.join(fig_dir, f"{stem}.{f}") for f in formats]
    digest = lambda *parts: hashlib.sha1("\n".join((common,) + parts).encode()).hexdigest()
    tasks = []
    by_id = {c["id"]: c for c in study.configs}
    for cid in ids:
        if not has_tables(study, cid):
            continue
        sides = by_id[cid].get("sides") or ["R"]
        files = [file_digest(p) for p in config_files(study, cid)]
        tasks.append((f"slices/{cid}", "slice", cid,
                      sum((outs(f"slices/{cid}-{side}") for side in sides), []),
                      digest("slice", cid, *files)))
        tasks.append((f"colour/{cid}", "colour", cid,
                      sum((outs(f"colour/{cid}-{side}") for side in sides), []),
                      digest("colour", cid, *files)))
    metrics = file_digest(os.path.join(study.root, "metrics.csv"))
    configs = json.dumps(study.configs)
    for side in ["R"] + (["T"] if any("T" in c["sides"] for c in study.configs) else []):
        tasks.append((f"error-matrix-{side}", "matrix", side, outs(f"error-matrix-{side}"),
                      digest("matrix", side, metrics, configs)))
    cats = []
    for c in study.configs:
        if c["category"] not in cats:
            cats.append(c["category"])
    for cat in cats:
        members = [c for c in study.configs if c["category"] == cat]
        if not all(has_tables(study, c["id"]) for c in members):
            continue
        files = [file_digest(p) for c in members for p in config_files(study, c["id"])]
        tasks.append((f"albedo-{cat}", "albedo", cat, outs(f"albedo-{cat}"),
                      digest("albedo", cat, json.dumps(members), *files)))
    return tasks


class FigureError(Exception):
    """A figure that could not be drawn from the study's files: its name and why."""


def draw(task):
    name, kind, arg, _, _ = task
    formats = _FORMATS
    try:
        if kind == "slice":
            slice_figure(_STUDY, arg, formats)
        elif kind == "colour":
            colour_figure(_STUDY, arg, formats)
        elif kind == "matrix":
            error_matrix(_STUDY, formats, arg)
        else:
            albedo_figure(_STUDY, arg, formats)
    except Exception as e:  # a damaged or foreign file: named, not a traceback
        raise FigureError(f"{name}: {type(e).__name__}: {e}") from None
    return name


_FORMATS = []


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("study_dir")
    p.add_argument("--formats", default="png")
    p.add_argument("--only", default="", help="configuration ids (globs) for the slices")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    p.add_argument("--script-id", default="",
                   help="digest of this script (lamina passes it: the script comes on stdin)")
    p.add_argument("--force", action="store_true", help="redraw every figure")
    a = p.parse_args()
    formats = [f for f in a.formats.split(",") if f]
    for f in formats:
        if f not in ("pdf", "svg", "png"):
            sys.exit(f"figures.py: --formats: '{f}' is not one of pdf, svg, png")
    t0 = time.time()
    global _STUDY, _FORMATS
    study = _STUDY = Study(a.study_dir)
    _FORMATS = formats
    ids = [c["id"] for c in study.configs]
    if a.only:
        pats = [g for g in a.only.split(",") if g]
        ids = [i for i in ids if any(fnmatch.fnmatchcase(i, g) for g in pats)]
        if not ids:
            sys.exit(f"figures.py: --only {a.only}: no configuration matches")
    script_id = a.script_id
    if not script_id and "__file__" in globals() and os.path.exists(__file__):
        script_id = file_digest(os.path.abspath(__file__))
    fig_dir = os.path.join(a.study_dir, "figures")
    os.makedirs(fig_dir, exist_ok=True)
    stamp_path = os.path.join(fig_dir, ".inputs.json")
    try:
        with open(stamp_path) as f:
            stamps = json.load(f)
    except (OSError, ValueError):
        stamps = {}
    tasks = plan(study, ids, formats, script_id)
    todo = [t for t in tasks if a.force or stamps.get(t[0]) != t[4]
            or not all(os.path.exists(o) for o in t[3])]
    # The largest first (albedo grids, then matrices), so the pool's last task is a short one.
    todo.sort(key=lambda t: {"albedo": 0, "matrix": 1, "slice": 2, "colour": 2}[t[1]])
    if a.jobs > 1 and len(todo) > 1:
        import multiprocessing
        # Ctrl-C ends the workers silently, each removing its temporary file (not Python's
        # KeyboardInterrupt with a traceback in each); this process says it in one line.
        # Ended by close() and join(): each worker leaves when it reads the end of the tasks.
        # Not by the context manager, whose terminate() signals the workers: a worker's SIGTERM
        # (end_on_signal, inherited) that arrives just before it blocks on the task queue's lock
        # is seen only when that lock returns, which it never does (the pool holds it), and the
        # script then waited for that worker for ever (seen once in five runs of
        # study_cli_test). A task that failed ends the others at once (SIGKILL, no handler to
        # wait for), and their temporary files are removed here.
        pool = multiprocessing.get_context("fork").Pool(
            min(a.jobs, len(todo)),
            initializer=signal.signal, initargs=(signal.SIGINT, end_on_signal))
        try:
            done = list(pool.imap_unordered(draw, todo))
        except BaseException:
            workers = multiprocessing.active_children()
            for child in workers:
                child.kill()
            for child in workers:
                child.join()
                for path in glob.glob(os.path.join(fig_dir, "**", f"*.tmp-{child.pid}.*"),
                                      recursive=True):
                    os.unlink(path)
            raise
        pool.close()
        pool.join()
    else:
        done = [draw(t) for t in todo]
    for t in todo:
        stamps[t[0]] = t[4]
    if todo:  # nothing drawn, nothing rewritten
        tmp = f"{stamp_path}.tmp-{os.getpid()}"
        WRITING.add(tmp)
        with open(tmp, "w") as f:
            json.dump(stamps, f, indent=0, sort_keys=True)
        os.replace(tmp, stamp_path)
        WRITING.discard(tmp)
    skipped = [c for c in ids if not has_tables(study, c)]
    if skipped:
        print(f"figures: {len(skipped)} configurations without tables (--tables none): "
              "no slices or albedo curves for them", file=sys.stderr)
    print(f"figures: {len(done)} drawn, {len(tasks) - len(todo)} unchanged, {len(formats)} "
          f"format(s), {time.time() - t0:.1f} s -> {fig_dir}", file=sys.stderr)


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, end_on_signal)  # the workers inherit it
    try:
        main()
    except KeyboardInterrupt:
        sys.exit("figures.py: interrupted")
    except Exception as e:
        # One line, as lamina's own errors: the study folder is damaged or not one lamina wrote
        # (a truncated table, a hand-edited study.json, ...) — or, where it is intact, a bug
        # of this script, which the message's exception names.
        where = sys.argv[1] if len(sys.argv) > 1 else "."
        what = str(e) if isinstance(e, FigureError) else f"{type(e).__name__}: {e}"
        sys.exit(f"figures.py: {where}: cannot draw the figures from this study folder "
                 f"({what}); rerun the study that wrote it, or report this message if the "
                 f"folder is as lamina wrote it")
