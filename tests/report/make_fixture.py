#!/usr/bin/env python3
"""A tiny synthetic study directory for the explorer and figure tests (docs/formats.md, "lamina study").

Not a study: analytic lobes with known shapes stand in for the reference and the models so that the
page and the figures can be tested in seconds without simulating anything. Python standard library
only. Usage: make_fixture.py DIR

Shapes (f in 1/sr, at the bin centres):
  reference   = rho/pi * diffuse + a Gaussian lobe around the mirror direction (width w)
  ww09        = the reference scaled by 1.1 (too bright everywhere)
  ww-prime    = the lobe twice as wide
  bel18-forward does not support a Lambertian base (all NaN, supported false) and is R only on slabs.
  openpbr     = the reference scaled by 0.9 (a production coat: the explorer groups the models)
  openpbr:darkening=off = the reference scaled by 0.95 (one of its ablations)
The slab has a transmitted lobe around the straight-through direction.
"""
import json
import math
import os
import struct
import sys
import zlib
from array import array

THETA_I = [0.0, 30.0, 60.0]
N_THETA, N_PHI = 60, 40  # not the default grid on purpose: the explorer must read it from study.json
MODELS = ["ww09", "ww-prime", "bel18-forward", "openpbr", "openpbr:darkening=off"]
MODEL_GROUPS = {"ww09": "2019", "ww-prime": "2019", "bel18-forward": "2019",
                "openpbr": "production", "openpbr:darkening=off": "ablations"}
CONFIGS = [
    # id, category, parameters, sides, diffuse rho (rgb), lobe width (rad), specular weight
    ("plastic-P1-a0.05", "plastic",
     {"alpha0": "0.05", "eta0": "1.5", "tau": "0", "base": "lambertian", "rho": "0.8"},
     ["R"], (0.8, 0.8, 0.8), 0.05, 0.05),
    ("plastic-P2-a0.3", "plastic",
     {"alpha0": "0.3", "eta0": "1.5", "tau": "0", "base": "lambertian", "rho": "(0.8, 0.2, 0.1)"},
     ["R"], (0.8, 0.2, 0.1), 0.3, 0.05),
    ("paint-a0.05-a1.3", "metallic-paint",
     {"alpha0": "0.05", "eta0": "1.5", "tau": "0.1", "base": "conductor", "alpha1": "0.3",
      "eta1": "1.45", "kappa1": "(1, 0.01, 0.01)"},
     ["R"], (0.5, 0.05, 0.05), 0.08, 0.3),
    ("slab-a0.1-a1.3-clear", "slab",
     {"alpha0": "0.1", "eta0": "1.5", "tau": "0", "base": "dielectric", "alpha1": "0.3",
      "eta1": "1"},
     ["R", "T"], (0.0, 0.0, 0.0), 0.1, 0.08),
]


def bin_edges():
    th = [90.0 * i / N_THETA for i in range(N_THETA + 1)]
    ph = [180.0 * i / N_PHI for i in range(N_PHI + 1)]
    return th, ph


def omega_perp(th, ph, t, p):
    return math.radians(ph[p + 1] - ph[p]) * (math.sin(math.radians(th[t + 1])) ** 2
                                              - math.sin(math.radians(th[t])) ** 2)


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))


def lobe(theta_o, phi_o, theta_i, width, weight):
    """A normalised-ish Gaussian lobe around the mirror direction (phi = 180)."""
    wo = direction(theta_o, phi_o)
    wr = direction(theta_i, 180.0)
    c = max(-1.0, min(1.0, sum(a * b for a, b in zip(wo, wr))))
    ang = math.acos(c)
    return weight * math.exp(-0.5 * (ang / width) ** 2) / (2 * math.pi * width * width)


def table(kind, side, theta_i, rho, width, weight):
    """f[θ][φ][c] for one source, incidence and side."""
    th, ph = bin_edges()
    out = []
    for t in range(N_THETA):
        tc = 0.5 * (th[t] + th[t + 1])
        row = []
        for p in range(N_PHI):
            pc = 0.5 * (ph[p] + ph[p + 1])
            if side == "T":
                # the straight-through direction, in the lower hemisphere, is at φ = 180 as well
                base = [0.0, 0.0, 0.0]
                spec = lobe(tc, pc, theta_i, 2 * width, 0.8)
            else:
                base = [r / math.pi * (1 - 0.3 * (tc / 90) ** 2) for r in rho]
                spec = lobe(tc, pc, theta_i, width, weight)
            if kind == "ww-prime":
                spec = 0.25 * (lobe(tc, pc, theta_i, 2 * width, weight) if side == "R"
                               else lobe(tc, pc, theta_i, 4 * width, 0.8)) * 4
            f = [b + spec for b in base]
            if kind == "ww09":
                f = [1.1 * v for v in f]
            if kind == "openpbr":
                f = [0.9 * v for v in f]
            if kind == "openpbr:darkening=off":
                f = [0.95 * v for v in f]
            row.append(f)
        out.append(row)
    return out


def write_npy(path, shape, values):
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': (%s), }" % (
        ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else ""))
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    data = array("f", values)
    if sys.byteorder != "little":
        data.byteswap()
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1"))
        f.write(data.tobytes())


def write_sphere_png(path, rgb):
    """A 48×48 shaded sphere (Lambert, light from the upper left) as an 8-bit RGB PNG."""
    n = 48
    rows = []
    for j in range(n):
        row = bytearray([0])  # filter: none
        for i in range(n):
            x, y = (i + 0.5) / n * 2 - 1, 1 - (j + 0.5) / n * 2
            r2 = x * x + y * y
            if r2 > 1:
                row += bytes([255, 255, 255])
                continue
            z = math.sqrt(1 - r2)
            shade = max(0.0, (-0.4 * x + 0.5 * y + 0.77 * z)) * 0.9 + 0.1
            row += bytes(int(255 * min(1.0, c * shade)) for c in rgb)
        rows.append(bytes(row))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(b"".join(rows))) + chunk(b"IEND", b""))


def supported(model, cfg_id, side):
    if model == "bel18-forward":
        return not cfg_id.startswith("plastic") and side == "R"
    return side == "R"


def main():
    root = sys.argv[1]
    os.makedirs(os.path.join(root, "configs"), exist_ok=True)
    th, ph = bin_edges()
    sources = ["reference"] + MODELS
    metrics = ["config,category,model,theta_i,side,channel,misplaced_energy,misplaced_floor,"
               "albedo_ref,albedo_model,albedo_error,rmse,log_rmse,noise_floor,"
               "misplaced_floor_noise,supported"]
    study_configs = []
    for cfg_id, category, params, sides, rho, width, weight in CONFIGS:
        d = os.path.join(root, "configs", cfg_id)
        os.makedirs(d, exist_ok=True)
        values, se_values = [], []
        albedo = {s: {side: [] for side in sides} for s in sources}
        tables = {}
        for s in sources:
            for i, ti in enumerate(THETA_I):
                for side in sides:
                    if s != "reference" and not supported(s, cfg_id, side):
                        tab = None
                    else:
                        tab = table(s, side, ti, rho, width, weight)
                    tables[(s, i, side)] = tab
                    alb = [0.0, 0.0, 0.0]
                    for t in range(N_THETA):
                        for p in range(N_PHI):
                            for c in range(3):
                                v = float("nan") if tab is None else tab[t][p][c]
                                values.append(v)
                                if tab is not None:
                                    alb[c] += v * omega_perp(th, ph, t, p)
                                if s == "reference":
                                    se_values.append(0.03 * v + 0.002)
                    albedo[s][side].append(alb if tab is not None else None)
        write_npy(os.path.join(d, "tables.npy"),
                  [len(sources), len(THETA_I), len(sides), N_THETA, N_PHI, 3], values)
        write_npy(os.path.join(d, "reference_se.npy"),
                  [len(THETA_I), len(sides), N_THETA, N_PHI, 3], se_values)
        support = {m: {"R": supported(m, cfg_id, "R"),
                       "T": "T" in sides and supported(m, cfg_id, "T"),
                       "reason": "" if supported(m, cfg_id, "R") else "base: lambertian"}
                   for m in MODELS}
        config = {"id": cfg_id, "category": category, "parameters": params,
                  "stack": {"name": cfg_id, "layers": []}, "sides": sides, "sources": sources,
                  "supported": support, "albedo": albedo,
                  "energy": [{"theta_i": ti, "reflected": albedo["reference"]["R"][i]}
                             for i, ti in enumerate(THETA_I)]}
        if cfg_id == "paint-a0.05-a1.3":  # sphere renderings for one configuration only
            os.makedirs(os.path.join(d, "renders"), exist_ok=True)
            # as `lamina render --compare` names them: the reference is random-walk.png
            for k, s in enumerate(sources):
                if s == "bel18-forward" or ":" in s:  # render --compare draws no ablations
                    continue
                write_sphere_png(os.path.join(d, "renders",
                                              ("random-walk" if s == "reference" else s) + ".png"),
                                 (0.9, 0.25 + 0.1 * k, 0.2))
            with open(os.path.join(d, "renders", "errors.csv"), "w") as f:
                f.write("model,rel_rmse,seconds\nww09,0.125,1.0\nww-prime,0.05,1.0\n"
                        "bel18-forward,not supported,\n")
        with open(os.path.join(d, "config.json"), "w") as f:
            json.dump(config, f, indent=1)
        study_configs.append({"id": cfg_id, "category": category, "parameters": params,
                              "sides": sides})
        for m in MODELS:
            for i, ti in enumerate(THETA_I):
                for side in sides:
                    for c, ch in enumerate("rgb"):
                        ok = supported(m, cfg_id, side)
                        if not ok:
                            metrics.append(f"{cfg_id},{category},{m},{ti:g},{side},{ch},,,,,,,,,,false")
                            continue
                        ref, mod = tables[("reference", i, side)], tables[(m, i, side)]
                        num = den = 0.0
                        for t in range(N_THETA):
                            for p in range(N_PHI):
                                w = omega_perp(th, ph, t, p)
                                num += abs(mod[t][p][c] - ref[t][p][c]) * w
                                den += ref[t][p][c] * w
                        e = num / den if den > 0 else float("nan")
                        mf = num / max(den, 0.05)
                        ar = albedo["reference"][side][i][c]
                        am = albedo[m][side][i][c]
                        err = (am - ar) / ar if ar > 0 else float("nan")
                        metrics.append(f"{cfg_id},{category},{m},{ti:g},{side},{ch},{e:.6g},{mf:.6g},"
                                       f"{ar:.6g},{am:.6g},{err:.6g},{e * 0.1:.6g},{e * 0.05:.6g},"
                                       f"0.004,{0.004 * min(1.0, den / 0.05):.6g},true")
    study = {"lamina_version": "fixture", "preset": "fixture", "particles": 1000, "seed": 1,
             "grid": {"n_theta": N_THETA, "n_phi": N_PHI}, "theta_i": THETA_I, "models": MODELS,
             "model_groups": MODEL_GROUPS,
             "configurations": study_configs}
    with open(os.path.join(root, "study.json"), "w") as f:
        json.dump(study, f, indent=1)
    with open(os.path.join(root, "metrics.csv"), "w") as f:
        f.write("\n".join(metrics) + "\n")


if __name__ == "__main__":
    main()
