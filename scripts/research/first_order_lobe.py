#!/usr/bin/env python3
"""The shape of the first-order lobe of a rough dielectric coat over a mirror (docs/models.md,
lamina-1, "Why the frosted metals stay at 20 %").

    /usr/bin/python3 scripts/research/first_order_lobe.py [--particles N] [--eta ETA] [--seed S]

Light arrives at normal incidence on a rough GGX coat (roughness alpha0, index eta over air), is
refracted by one visible facet (Heitz 2018 sampling, weight (1 - F) times the Smith escape
1/(1 + Lambda) of the refracted ray), meets a smooth mirror, and leaves through a second facet
(the same weights; total internal reflection drops it: that light belongs to the later orders).
The histogram of the exit angle theta_o (2-degree bins, energy per bin, normalised to 1) is the
"exact" first-order shape. Three lobes built from the facet slopes are compared with it by the
misplaced fraction sum |p - q| of the normalised histograms (shape only: their energies are set
equal):

  ggx        one GGX lobe of the half vector with the two spreads summed in variance,
             alpha_e^2 = 2 (alpha0 k / 2)^2, k = 1 - 1/eta (lamina-1's item 4 today);
  sum        the half-vector slope distributed as the *sum* of the two spreads' slopes,
             (k / 2)(s1 + s2) with s1, s2 GGX slopes of alpha0: same tail, 2/3 of the peak;
  compressed the sum of the two facets' slopes mapped through one facet's exact deflection
             (Snell's law, entry or exit with probability 1/2), weighted by that facet's
             transmission (1 - F) and escape: exact in the core (linear) and in the tail (where
             one steep facet makes the whole deflection).

It reproduces the table of docs/models.md; numpy only, fixed seed, about a minute.
"""
import argparse

import numpy as np

BINS = np.linspace(0, np.pi / 2, 46)


def fresnel(cos_i, eta):
    """Unpolarised dielectric Fresnel reflectance and the refracted cosine (eta = n_t / n_i)."""
    sin2_t = (1 - cos_i * cos_i) / eta**2
    cos_t = np.sqrt(np.maximum(0, 1 - sin2_t))
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return np.where(sin2_t >= 1, 1.0, 0.5 * (rs * rs + rp * rp)), cos_t


def smith_lambda(cos_t, alpha):
    tan2 = (1 - cos_t * cos_t) / np.maximum(cos_t * cos_t, 1e-30)
    return 0.5 * (-1 + np.sqrt(1 + alpha * alpha * tan2))


def ggx_slopes(rng, alpha, n):
    """Slopes of GGX normals drawn with density D(m) cos(theta_m) (a bivariate Student t, nu = 2)."""
    u = rng.random(n)
    phi = 2 * np.pi * rng.random(n)
    r = alpha * np.sqrt(u / (1 - u))
    return np.stack([r * np.cos(phi), r * np.sin(phi)], -1)


def visible_normal(rng, w, alpha):
    """Heitz 2018, 'Sampling the GGX distribution of visible normals', for w in the upper side."""
    n = len(w)
    vh = np.stack([alpha * w[:, 0], alpha * w[:, 1], w[:, 2]], -1)
    vh /= np.linalg.norm(vh, axis=-1, keepdims=True)
    lensq = vh[:, 0] ** 2 + vh[:, 1] ** 2
    safe = np.sqrt(np.maximum(lensq, 1e-30))
    t1 = np.where((lensq > 0)[:, None],
                  np.stack([-vh[:, 1] / safe, vh[:, 0] / safe, np.zeros(n)], -1),
                  np.array([1.0, 0, 0]))
    t2 = np.cross(vh, t1)
    r = np.sqrt(rng.random(n))
    phi = 2 * np.pi * rng.random(n)
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1 + vh[:, 2])
    p2 = (1 - s) * np.sqrt(1 - p1 * p1) + s * p2
    nh = p1[:, None] * t1 + p2[:, None] * t2 + np.sqrt(np.maximum(0, 1 - p1 * p1 - p2 * p2))[:, None] * vh
    m = np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(1e-7, nh[:, 2])], -1)
    return m / np.linalg.norm(m, axis=-1, keepdims=True)


def refract(w, m, eta):
    """w points away from the interface on its side, m on the same side; eta = n_t / n_i."""
    c = np.sum(w * m, -1)
    f, cos_t = fresnel(c, eta)
    return -w / eta + (c / eta - cos_t)[:, None] * m, f


def histogram(theta, weight):
    h, _ = np.histogram(theta, BINS, weights=weight)
    return h / h.sum()


def exact(rng, alpha0, eta, n):
    wi = np.tile([0, 0, 1.0], (n, 1))
    t, f = refract(wi, visible_normal(rng, wi, alpha0), eta)
    weight = (1 - f) / (1 + smith_lambda(np.abs(t[:, 2]), alpha0))
    up = t * np.array([1, 1, -1.0])  # the mirror: going up inside
    v = -up * np.array([1, 1, -1.0])  # towards where it came from, in the flipped frame
    to, f = refract(v, visible_normal(rng, v, alpha0), 1 / eta)
    weight *= (1 - f) / (1 + smith_lambda(np.abs(to[:, 2]), alpha0))
    ok = (f < 1) & (t[:, 2] < 0) & (to[:, 2] < 0)
    return histogram(np.arccos(np.clip(-to[ok, 2], -1, 1)), weight[ok])


def lobe(inside_theta, weight, eta):
    """Exit angles of inside directions at inside_theta through a flat top (weight 1 - F)."""
    sin_o = np.sin(inside_theta) * eta
    ok = (inside_theta < np.pi / 2) & (sin_o < 1)
    theta_o = np.arcsin(np.minimum(sin_o, 1))
    f, _ = fresnel(np.cos(theta_o), eta)
    return histogram(theta_o[ok], ((1 - f) * weight)[ok])


def half_vector_lobe(slopes, eta):
    """The mirror direction about half vectors of these slopes, at normal incidence inside."""
    tan_h = np.linalg.norm(slopes, axis=-1)
    return lobe(2 * np.arctan(tan_h), np.ones(len(tan_h)), eta)


def compressed(rng, alpha0, eta, n):
    s = ggx_slopes(rng, alpha0, n) + ggx_slopes(rng, alpha0, n)
    delta = np.arctan(np.linalg.norm(s, axis=-1))
    entry = rng.random(n) < 0.5
    # Entry, outside -> inside at normal incidence: the inside ray turns by delta - asin(sin delta / eta).
    f_in, _ = fresnel(np.cos(delta), eta)
    dev_in = delta - np.arcsin(np.sin(delta) / eta)
    w_in = (1 - f_in) / (1 + smith_lambda(np.cos(dev_in), alpha0))
    # Exit, inside -> outside: the outside ray turns by asin(eta sin delta) - delta (total internal
    # reflection beyond asin(1/eta)); as an inside angle through a flat top, asin(sin(.) / eta).
    x = eta * np.sin(delta)
    dev_out_o = np.arcsin(np.minimum(x, 1)) - delta
    f_out, _ = fresnel(np.cos(delta), 1 / eta)
    w_out = np.where(x < 1, (1 - f_out) / (1 + smith_lambda(np.cos(dev_out_o), alpha0)), 0.0)
    dev_out = np.arcsin(np.sin(dev_out_o) / eta)
    return lobe(np.where(entry, dev_in, dev_out), np.where(entry, w_in, w_out), eta)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--particles", type=int, default=2_000_000)
    ap.add_argument("--eta", type=float, default=1.5)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    eta, n = a.eta, a.particles
    k = 1 - 1 / eta
    print(f"misplaced shape against the exact first order, normal incidence, eta {eta}, {n} paths")
    print("alpha0   ggx      sum      compressed")
    for alpha0 in (0.1, 0.2, 0.3, 0.4, 0.5):
        ref = exact(rng, alpha0, eta, n)
        ggx = half_vector_lobe(ggx_slopes(rng, np.sqrt(2) * k * alpha0 / 2, n), eta)
        two = half_vector_lobe(k / 2 * (ggx_slopes(rng, alpha0, n) + ggx_slopes(rng, alpha0, n)), eta)
        comp = compressed(rng, alpha0, eta, n)
        print(f"{alpha0:5.1f}  " + "  ".join(f"{np.abs(ref - q).sum():7.3f}" for q in (ggx, two, comp)))


if __name__ == "__main__":
    main()
