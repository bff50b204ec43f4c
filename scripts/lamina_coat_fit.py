#!/usr/bin/env python3
"""lamina-coat's tables and fitted constants (docs/lamina-coat.md).

    python3 scripts/lamina_coat_fit.py tables             # docs/lamina-coat/tables.{csv,png} + the C++ table
    python3 scripts/lamina_coat_fit.py fit STUDY_DIR      # the three constants, from a study's reference

`tables` integrates what the model derives (no fitting): the coat's directional albedo E_c(mu; r,
eta) (exact dielectric Fresnel, GGX with height-correlated Smith masking), the white lobe's
albedo E_w(mu; r), their hemispherical averages, and the smooth coat's internal reflectance under
absorption K(tau; eta)/K(0; eta). Every value is stored as a 16-bit integer v/65535: the PNG, the
CSV and the C++ table hold the same integers, so the C++ and GLSL forms read the same numbers.

`fit` reads a study run with the exact reference (`lamina study --polarization on --microsurface
multiple --only 'plastic-*,paint-*,frosted-*' --tables full`), keeps every second configuration of
each category in the study's order for fitting (the others are held out, listed in
docs/lamina-coat.md), and chooses the constants on grids: grazing energy k_g and tint path c_tau on
the fitting plastics, then base roughening k_r on the fitting metals, each minimizing the mean
misplaced energy (5% floor). The coat lobe and the metal lobe are binned by lamina (`lamina.Model`,
`lamina.bin_model`); the smooth terms are evaluated at the bins' centres. Deterministic.

Needs numpy, Pillow and lamina's Python module (PYTHONPATH=build/python).
"""
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "lamina-coat"
CXX_TABLE = ROOT / "src" / "models" / "lamina_coat" / "lamina_coat_table.inc"

N_MU, N_R, N_ETA, N_TAU = 32, 32, 16, 32
ETA0, ETA_STEP = 1.1, 0.1  # eta nodes 1.1 ... 2.6
# Rows of the table (32 columns each), in this order:
ROW_E = 0                      # E_c[eta k][r j][mu i]: row k*32 + j
ROW_EW = ROW_E + N_ETA * N_R   # E_w[r j][mu i]
ROW_EBAR = ROW_EW + N_R        # Ebar_c[eta k][r j]: row per eta, column r
ROW_EWBAR = ROW_EBAR + N_ETA   # Ebar_w[r j]
ROW_K = ROW_EWBAR + 1          # K(tau; eta)/K(0; eta)[eta k][tau node i], tau = u/(1-u), u = i/31
N_ROWS = ROW_K + N_ETA


def fresnel_dielectric(c, eta):
    c = np.clip(c, 0.0, 1.0)
    s2 = (1 - c * c) / (eta * eta)
    ct = np.sqrt(np.clip(1 - s2, 0.0, 1.0))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return np.where(s2 < 1, 0.5 * (rs * rs + rp * rp), 1.0)


def smith_lambda(mu, alpha):
    mu = np.clip(mu, 1e-12, 1.0)
    return 0.5 * (-1 + np.sqrt(1 + alpha * alpha * (1 - mu * mu) / (mu * mu)))


def directional_albedo(mu, alpha, eta, n=128):
    """E(mu) = ∫ F D G2 /(4 mu) dwo by the visible normals (Heitz 2018, "Sampling the GGX
    distribution of visible normals"): Gauss-Legendre on n x n nodes in (s, u2), u1 = s²; eta
    None: F = 1. Accurate to about 1e-3 at worst (small alpha at normal incidence, where the
    facets that reflect below the horizon cut the domain), 1e-4 elsewhere."""
    if mu <= 0:
        return 1.0 if eta is not None else 0.0
    if alpha <= 0:
        return float(fresnel_dielectric(mu, eta)) if eta is not None else 1.0
    x, w = np.polynomial.legendre.leggauss(n)
    x, w = 0.5 * (x + 1), 0.5 * w
    s_, u2 = np.meshgrid(x, x, indexing="ij")
    weight = (np.outer(w, w) * 2 * s_).ravel()
    u1, u2 = (s_ * s_).ravel(), u2.ravel()
    wi = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
    vh = np.array([alpha * wi[0], 0.0, wi[2]])
    vh /= np.linalg.norm(vh)
    t1v = np.array([0.0, 1.0, 0.0]) if vh[0] > 0 else np.array([1.0, 0.0, 0.0])
    t2v = np.cross(vh, t1v)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    t1, t2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1 + vh[2])
    t2 = (1 - s) * np.sqrt(1 - t1 * t1) + s * t2
    nh = t1[:, None] * t1v + t2[:, None] * t2v + np.sqrt(np.clip(1 - t1 * t1 - t2 * t2, 0, None))[:, None] * vh
    m = np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.clip(nh[:, 2], 0, None)], -1)
    m /= np.linalg.norm(m, axis=-1, keepdims=True)
    c = m @ wi
    mu_o = 2 * c * m[:, 2] - mu
    li, lo = smith_lambda(mu, alpha), smith_lambda(np.clip(mu_o, 1e-12, 1), alpha)
    f = fresnel_dielectric(c, eta) if eta is not None else 1.0
    return float(np.sum(weight * np.where(mu_o > 0, f * (1 + li) / (1 + li + lo), 0.0)))


def hemispherical_average(e):
    """2 ∫ E mu dmu of E interpolated linearly between the 32 mu nodes (as the model reads it):
    exact, Simpson's rule on each interval."""
    mu = np.linspace(0, 1, N_MU)
    a, b = mu[:-1], mu[1:]
    return float(np.sum((b - a) / 3 * (e[:-1] * (2 * a + b) + e[1:] * (a + 2 * b))))


def make_tables():
    t = np.zeros((N_ROWS, 32))
    mu = np.linspace(0, 1, N_MU)
    r = np.linspace(0, 1, N_R)
    for j, rj in enumerate(r):
        t[ROW_EW + j] = [directional_albedo(m, rj * rj, None) for m in mu]
    t[ROW_EWBAR] = [hemispherical_average(t[ROW_EW + j]) for j in range(N_R)]
    mq = (np.arange(20000) + 0.5) / 20000
    for k in range(N_ETA):
        eta = ETA0 + ETA_STEP * k
        for j, rj in enumerate(r):
            t[ROW_E + k * N_R + j] = [directional_albedo(m, rj * rj, eta) for m in mu]
        t[ROW_EBAR + k] = [hemispherical_average(t[ROW_E + k * N_R + j]) for j in range(N_R)]
        # The smooth coat's internal reflectance, 2 ∫ F(mu'; 1/eta) exp(-2 tau/mu') mu' dmu'.
        internal = fresnel_dielectric(mq, 1 / eta)
        k0 = np.mean(internal * 2 * mq)
        for i in range(N_TAU):
            u = i / (N_TAU - 1)
            tau = u / (1 - u) if u < 1 else np.inf
            t[ROW_K + k, i] = np.mean(internal * np.exp(-2 * tau / mq) * 2 * mq) / k0 if u < 1 else 0.0
    q = np.round(np.clip(t, 0, 1) * 65535).astype(np.uint16)
    OUT.mkdir(parents=True, exist_ok=True)
    from PIL import Image
    Image.fromarray(q, mode="I;16").save(OUT / "tables.png")
    with open(OUT / "tables.csv", "w") as f:
        f.write("# lamina-coat tables: value = integer / 65535; 32 columns; rows as scripts/lamina_coat_fit.py\n")
        for row in q:
            f.write(",".join(str(int(v)) for v in row) + "\n")
    with open(CXX_TABLE, "w") as f:
        f.write("// Written by scripts/lamina_coat_fit.py tables (the same integers as docs/lamina-coat/tables.csv).\n")
        for row in q:
            f.write("{" + ",".join(str(int(v)) for v in row) + "},\n")
    print(f"{N_ROWS} x 32 values written to {OUT}/tables.{{png,csv}} and {CXX_TABLE}")


# --- The fit ----------------------------------------------------------------------------------

class Tables:
    """The committed tables, read as the model reads them (linear between nodes, clamped)."""

    def __init__(self):
        self.t = np.loadtxt(OUT / "tables.csv", delimiter=",", comments="#") / 65535.0

    @staticmethod
    def _node(x, n):
        s = np.clip(x, 0.0, 1.0) * (n - 1)
        i = np.minimum(s.astype(int), n - 2)
        return i, s - i

    def _lerp_row(self, rows, x):
        i, w = self._node(x, 32)
        return self.t[rows, i] + w * (self.t[rows, i + 1] - self.t[rows, i])

    def albedo(self, mu, r, eta):
        mu = np.asarray(mu, float)
        j, wr = self._node(np.full_like(mu, r), 32)
        k, we = self._node(np.full_like(mu, (eta - ETA0) / (ETA_STEP * (N_ETA - 1))), N_ETA)
        def at(kk):
            lo = self._lerp_row(ROW_E + kk * N_R + j, mu)
            hi = self._lerp_row(ROW_E + kk * N_R + j + 1, mu)
            return lo + wr * (hi - lo)
        return at(k) + we * (at(k + 1) - at(k))

    def white(self, mu, r):
        mu = np.asarray(mu, float)
        j, wr = self._node(np.full_like(mu, r), 32)
        lo, hi = self._lerp_row(ROW_EW + j, mu), self._lerp_row(ROW_EW + j + 1, mu)
        return lo + wr * (hi - lo)

    def average(self, r, eta):
        k, we = self._node(np.array([(eta - ETA0) / (ETA_STEP * (N_ETA - 1))]), N_ETA)
        lo, hi = self._lerp_row(ROW_EBAR + k, np.array([r])), self._lerp_row(ROW_EBAR + k + 1, np.array([r]))
        return float((lo + we * (hi - lo))[0])

    def white_average(self, r):
        return float(self._lerp_row(np.array([ROW_EWBAR]), np.array([r]))[0])

    def internal(self, tau, eta):
        k, we = self._node(np.full(3, (eta - ETA0) / (ETA_STEP * (N_ETA - 1))), N_ETA)
        u = np.asarray(tau, float) / (1 + np.asarray(tau, float))
        lo, hi = self._lerp_row(ROW_K + k, u), self._lerp_row(ROW_K + k + 1, u)
        return lo + we * (hi - lo)


class Coat:
    """lamina-coat's terms as models/lamina_coat/lamina_coat.cpp evaluates them, for candidate
    constants (k_g, c_tau, k_r); the coat's own GGX lobe is not here (binned by lamina)."""

    def __init__(self, tables, stack, k_g, c_tau, k_r):
        coat, base = stack["layers"][0], stack["layers"][1]["interface"]
        self.T, self.eta = tables, coat["interface"]["eta"]
        self.r = np.sqrt(coat["interface"]["alpha"])
        tau = coat.get("medium", {}).get("tau_a", 0.0)
        self.tau = np.broadcast_to(np.asarray(tau, float), (3,)) * (1 + c_tau * self.r)
        self.k_g, self.name = k_g, "lamina-coat-candidate"
        ewbar = tables.white_average(self.r)
        self.white_norm = k_g / (np.pi * (1 - ewbar)) if ewbar < 1 - 1e-6 else 0.0
        self.conductor = base["type"] == "conductor"
        if self.conductor:
            self.eta_b = np.broadcast_to(np.asarray(base["eta"], float), (3,)) / self.eta
            self.k_b = np.broadcast_to(np.asarray(base["k"], float), (3,)) / self.eta
            self.alpha_b = np.sqrt(base["alpha"] ** 2 + k_r * self.r ** 4)
        else:
            rho = np.broadcast_to(np.asarray(base["albedo"], float), (3,))
            average = tables.average(self.r, self.eta) + k_g * (1 - ewbar)
            K = (1 - (1 - average) / self.eta ** 2) * tables.internal(self.tau, self.eta)
            self.lambert = rho / (np.pi * (1 - rho * K))

    def transmittance(self, mu):
        return np.maximum(0.0, 1 - self.T.albedo(mu, self.r, self.eta) - self.k_g * (1 - self.T.white(mu, self.r)))

    def eval(self, wi, wo):
        """Everything but the coat's GGX lobe: [N, 3]."""
        mi, mo, e = wi[:, 2], wo[:, 2], self.eta
        g = self.white_norm * (1 - self.T.white(mi, self.r)) * (1 - self.T.white(mo, self.r))
        ri = np.stack([wi[:, 0] / e, wi[:, 1] / e, np.sqrt(1 - (1 - mi * mi) / e ** 2)], -1)
        ro = np.stack([wo[:, 0] / e, wo[:, 1] / e, np.sqrt(1 - (1 - mo * mo) / e ** 2)], -1)
        t = self.transmittance(mi) * self.transmittance(mo) / e ** 2
        tint = np.exp(-self.tau[None, :] * (1 / ri[:, 2] + 1 / ro[:, 2])[:, None])
        if self.conductor:
            h = ri + ro
            h /= np.linalg.norm(h, axis=-1, keepdims=True)
            a2 = self.alpha_b ** 2
            D = a2 / (np.pi * (h[:, 2] ** 2 * (a2 - 1) + 1) ** 2)
            G = 1 / (1 + smith_lambda(ri[:, 2], self.alpha_b) + smith_lambda(ro[:, 2], self.alpha_b))
            base = (D * G / (4 * ri[:, 2] * ro[:, 2]))[:, None] * fresnel_conductor(np.sum(ri * h, -1), self.eta_b, self.k_b)
        else:
            base = np.broadcast_to(self.lambert, (len(wi), 3))
        return g[:, None] + base * tint * t[:, None]

    def peak_directions(self, wi):
        return [np.array([-wi[0], -wi[1], wi[2]])]


def fresnel_conductor(c, eta, k):
    c = np.clip(c, 0.0, 1.0)[:, None]
    n = eta[None, :] + 1j * k[None, :]
    ct = np.sqrt(1 - (1 - c * c) / (n * n))
    rs = (c - n * ct) / (c + n * ct)
    rp = (n * c - ct) / (n * c + ct)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def misplaced_floor(model, reference, omega):
    """The study's metric (src/study/metrics.cpp), averaged over incidences and channels."""
    diff = (np.abs(model - reference) * omega[None, :, :, None]).sum((1, 2))
    energy = (reference * omega[None, :, :, None]).sum((1, 2))
    return float(np.mean(diff / np.maximum(energy, 0.05)))


def fitting_split(study):
    """Every second configuration of each category, in the study's order, is fitted on; the
    others are held out."""
    seen, fit, held = {}, [], []
    for cid in study.configs:
        cat = study.config(cid)["category"]
        if cat not in ("plastic", "metallic-paint", "frosted-metal"):
            continue
        (fit if seen.get(cat, 0) % 2 == 0 else held).append(cid)
        seen[cat] = seen.get(cat, 0) + 1
    return fit, held


def fit(study_dir):
    import lamina
    study = lamina.load_study(str(study_dir))
    theta_i, grid = list(study.theta_i), (90, 90)
    nt, nphi = grid
    te, pe = np.linspace(0, np.pi / 2, nt + 1), np.linspace(0, np.pi, nphi + 1)
    omega = np.diff(pe)[None, :] * np.diff(np.sin(te) ** 2)[:, None]
    tc, pc = 0.5 * (te[1:] + te[:-1]), 0.5 * (pe[1:] + pe[:-1])
    T_, P_ = np.meshgrid(tc, pc, indexing="ij")
    centres = np.stack([np.sin(T_) * np.cos(P_), np.sin(T_) * np.sin(P_), np.cos(T_)], -1).reshape(-1, 3)
    tables = Tables()
    fit_ids, held_ids = fitting_split(study)
    print("fitted on:", " ".join(fit_ids))
    print("held out:", " ".join(held_ids))
    data = {}
    for cid in fit_ids:
        stack = study.config(cid)["stack"]
        clear = json.loads(json.dumps(stack))
        clear["layers"][1] = {"interface": {"type": "lambertian", "albedo": 0.0}}
        # The coat's GGX lobe alone: lamina's binning of the openpbr model over a black base
        # (its coat lobe is exactly lamina-coat's: exact Fresnel, height-correlated Smith).
        coat_lobe = np.asarray(lamina.Model("openpbr", lamina.Stack(clear)).binned(theta_i=theta_i, grid=grid).f)[:, 0]
        data[cid] = (stack, coat_lobe, np.asarray(study.tables(cid)["reference"], float)[:, 0])

    def at_centres(coat, k):
        t = np.radians(theta_i[k])
        wi = np.broadcast_to(np.array([np.sin(t), 0.0, np.cos(t)]), centres.shape)
        return coat.eval(np.ascontiguousarray(wi), centres).reshape(nt, nphi, 3)

    # 1. Grazing energy and tint path on the fitting plastics (smooth terms: the bins' centres).
    plastics = [c for c in fit_ids if study.config(c)["category"] == "plastic"]
    best = None
    for k_g in np.arange(0.0, 1.01, 0.1):
        for c_tau in np.arange(0.0, 1.01, 0.1):
            err = []
            for cid in plastics:
                stack, coat_lobe, ref = data[cid]
                coat = Coat(tables, stack, k_g, c_tau, 0.0)
                model = coat_lobe + np.stack([at_centres(coat, k) for k in range(len(theta_i))])
                err.append(misplaced_floor(model, ref, omega))
            e = float(np.mean(err))
            if best is None or e < best[0]:
                best = (e, k_g, c_tau)
    _, k_g, c_tau = best
    print(f"plastics: k_g = {k_g:.2f}, c_tau = {c_tau:.2f}: misplaced energy {best[0]:.4f}")

    # 2. Base roughening on the fitting metals (the metal lobe binned by lamina).
    metals = [c for c in fit_ids if study.config(c)["category"] != "plastic"]
    best = None
    for k_r in np.arange(0.05, 0.501, 0.025):
        err = []
        for cid in metals:
            stack, coat_lobe, ref = data[cid]
            coat = Coat(tables, stack, k_g, c_tau, k_r)
            rest = np.asarray(lamina.bin_model(coat, lamina.Stack(stack), theta_i, grid).f)[:, 0]
            err.append(misplaced_floor(coat_lobe + rest, ref, omega))
        e = float(np.mean(err))
        print(f"  k_r = {k_r:.3f}: {e:.4f}", flush=True)
        if best is None or e < best[0]:
            best = (e, k_r)
    k_r = best[1]
    print(f"metals: k_r = {k_r:.3f}: misplaced energy {best[0]:.4f}")
    with open(OUT / "fit.csv", "w") as f:
        f.write("constant,value,what\n")
        f.write(f"k_g,{k_g:.3f},grazing energy: the reflected part of the coat's multiple scattering\n")
        f.write(f"c_tau,{c_tau:.3f},tint path: s = 1 + c_tau r\n")
        f.write(f"k_r,{k_r:.3f},base roughening: alpha_b^2 = alpha1^2 + k_r alpha0^2\n")
    print(f"written to {OUT / 'fit.csv'}")


if __name__ == "__main__":
    if len(sys.argv) >= 2 and sys.argv[1] == "tables":
        make_tables()
    elif len(sys.argv) >= 3 and sys.argv[1] == "fit":
        fit(Path(sys.argv[2]))
    else:
        print(__doc__)
        sys.exit(2)
