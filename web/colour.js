// lamina explorer, view 7: the colour of the reflected (or transmitted) light (docs/explorer.md,
// "Colour"). Loaded before explorer.js; registers itself in window.LAMINA_VIEWS, which the
// explorer's render() draws with its helpers. The colour science is window.LAMINA_COLOUR, which
// the browser test checks against published data.
"use strict";

(function () {
  // ---- Colour science -----------------------------------------------------------------------------

  // Linear sRGB → CIE 1931 XYZ: the matrix of IEC 61966-2-1:1999 §5.2 (D65; linear sRGB (1, 1, 1) is
  // the white, Y = 1). lamina's spectral tables are M⁻¹ · XYZ with this standard's inverse matrix
  // (docs/physics.md §10).
  const RGB_TO_XYZ = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
  ];
  // The reference white of CIELAB: the XYZ of linear sRGB (1, 1, 1), so that an equal-energy grey
  // has a* = b* = 0 exactly.
  const WHITE = RGB_TO_XYZ.map((row) => row[0] + row[1] + row[2]);

  function xyzOf(rgb) {
    return RGB_TO_XYZ.map((row) => row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2]);
  }

  // The sRGB transfer curve (IEC 61966-2-1:1999 §5.2, the encoding of a linear value in [0, 1]).
  function srgbEncode(v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
  }

  // CIELAB of XYZ against WHITE (CIE 015:2018 §8.2.1): L* = 116 f(Y/Yn) − 16, a* = 500 (f(X/Xn) −
  // f(Y/Yn)), b* = 200 (f(Y/Yn) − f(Z/Zn)), f(t) = t^(1/3) above (6/29)³, linear below.
  function labOf(rgb) {
    const xyz = xyzOf(rgb);
    const d = 6 / 29;
    const f = (t) => (t > d * d * d ? Math.cbrt(t) : t / (3 * d * d) + 4 / 29);
    const fx = f(xyz[0] / WHITE[0]), fy = f(xyz[1] / WHITE[1]), fz = f(xyz[2] / WHITE[2]);
    return [116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)];
  }

  // CIEDE2000 colour difference ΔE00 of two CIELAB colours, kL = kC = kH = 1: CIE 142-2001 and
  // ISO/CIE 11664-6:2014, as written out in G. Sharma, W. Wu, E. N. Dalal, "The CIEDE2000
  // colour-difference formula: implementation notes, supplementary test data, and mathematical
  // observations", Color Res. Appl. 30(1), 21–30 (2005), eqs. (1)–(22); hue angles in degrees,
  // the hue of a neutral colour (a' = b = 0) taken as 0 (their eqs. 4, 10 and 14 notes).
  function ciede2000(lab1, lab2) {
    const [L1, a1, b1] = lab1, [L2, a2, b2] = lab2;
    const rad = Math.PI / 180, deg = 180 / Math.PI;
    const C1 = Math.hypot(a1, b1), C2 = Math.hypot(a2, b2);
    const Cbar = (C1 + C2) / 2, Cbar7 = Math.pow(Cbar, 7);
    const G = 0.5 * (1 - Math.sqrt(Cbar7 / (Cbar7 + Math.pow(25, 7))));  // eq. (3)
    const ap1 = (1 + G) * a1, ap2 = (1 + G) * a2;                         // eq. (4)
    const Cp1 = Math.hypot(ap1, b1), Cp2 = Math.hypot(ap2, b2);           // eq. (5)
    const hue = (b, ap) => (b === 0 && ap === 0 ? 0 : (Math.atan2(b, ap) * deg + 360) % 360);  // eq. (6)
    const hp1 = hue(b1, ap1), hp2 = hue(b2, ap2);
    const dLp = L2 - L1, dCp = Cp2 - Cp1;                                  // eqs. (8), (9)
    let dhp = 0;                                                           // eq. (10)
    if (Cp1 * Cp2 !== 0) {
      dhp = hp2 - hp1;
      if (dhp > 180) dhp -= 360;
      else if (dhp < -180) dhp += 360;
    }
    const dHp = 2 * Math.sqrt(Cp1 * Cp2) * Math.sin((dhp / 2) * rad);     // eq. (11)
    const Lbp = (L1 + L2) / 2, Cbp = (Cp1 + Cp2) / 2;                     // eqs. (12), (13)
    let hbp = hp1 + hp2;                                                   // eq. (14)
    if (Cp1 * Cp2 !== 0) {
      if (Math.abs(hp1 - hp2) <= 180) hbp = (hp1 + hp2) / 2;
      else hbp = hp1 + hp2 < 360 ? (hp1 + hp2 + 360) / 2 : (hp1 + hp2 - 360) / 2;
    }
    const T = 1 - 0.17 * Math.cos((hbp - 30) * rad) + 0.24 * Math.cos(2 * hbp * rad) +
      0.32 * Math.cos((3 * hbp + 6) * rad) - 0.2 * Math.cos((4 * hbp - 63) * rad);  // eq. (15)
    const dTheta = 30 * Math.exp(-Math.pow((hbp - 275) / 25, 2));          // eq. (16)
    const Cbp7 = Math.pow(Cbp, 7);
    const RC = 2 * Math.sqrt(Cbp7 / (Cbp7 + Math.pow(25, 7)));             // eq. (17)
    const l50 = (Lbp - 50) * (Lbp - 50);
    const SL = 1 + (0.015 * l50) / Math.sqrt(20 + l50);                     // eq. (18)
    const SC = 1 + 0.045 * Cbp;                                             // eq. (19)
    const SH = 1 + 0.015 * Cbp * T;                                         // eq. (20)
    const RT = -Math.sin(2 * dTheta * rad) * RC;                            // eq. (21)
    const tL = dLp / SL, tC = dCp / SC, tH = dHp / SH;
    return Math.sqrt(tL * tL + tC * tC + tH * tH + RT * tC * tH);           // eq. (22)
  }

  // The colour shown for a linear RGB value already multiplied by the view's exposure: negative
  // channels (a spectral colour outside sRGB's gamut) are shown as 0, and a value whose largest
  // channel exceeds 1 is divided by it (its hue kept, its brightness clipped); then the transfer
  // curve, and 8 bits. Returns [r, g, b] in 0..255 and whether it was clipped.
  function displayOf(rgb) {
    const c = rgb.map((v) => (v > 0 ? v : 0));
    const m = Math.max(c[0], c[1], c[2]);
    const s = m > 1 ? 1 / m : 1;
    return { srgb: c.map((v) => Math.round(255 * srgbEncode(v * s))), clipped: m > 1 };
  }

  window.LAMINA_COLOUR = { RGB_TO_XYZ, WHITE, xyzOf, srgbEncode, labOf, ciede2000, displayOf };

  // ---- The view ---------------------------------------------------------------------------------------

  // Display modes: what each bin's colour is made of (docs/explorer.md, "Colour").
  //   f      — the BRDF's value: the colour of the light the surface sends towards θo (radiance,
  //            for an incident irradiance of 1);
  //   fcos   — f · cos θo: the light per unit of projected solid angle, what the projected disk
  //            integrates to the albedo (grazing directions darken);
  //   chroma — f at one luminance, Y = CHROMA_Y: hue and saturation alone.
  const CHROMA_Y = 0.4;
  const settings = { mode: "f", ev: 0 };
  let last = null;  // [api, d, cfg] of the last draw, to redraw on the view's own widgets

  const el = (id) => document.getElementById(id);

  // The merged bins' projected solid angles Ω⊥ = ½ (sin²θ1 − sin²θ0) Δφ (lamina's formula,
  // HemisphereGrid::projected_solid_angle in src/core/grid.cpp, over a merged bin; a folded bin's
  // mirror half would double every weight alike) and cos θo at their centres.
  function binGeometry(h) {
    const rad = Math.PI / 180, w = [], cosc = [];
    for (let t = 0; t < h.n_theta; ++t) {
      const s0 = Math.sin(h.theta_edges[t] * rad), s1 = Math.sin(h.theta_edges[t + 1] * rad);
      cosc.push(Math.cos(0.5 * (h.theta_edges[t] + h.theta_edges[t + 1]) * rad));
      for (let p = 0; p < h.n_phi; ++p) w.push(0.5 * (s1 * s1 - s0 * s0) * (h.phi_edges[p + 1] - h.phi_edges[p]) * rad);
    }
    return { w, cosc };
  }

  // The linear RGB of every merged bin of one source, [bin] of [r, g, b] (null: not supported).
  function hemiRgb(d, source, inc, side) {
    const h = d.hemiShape, n = h.n_theta * h.n_phi;
    const s = d.sources.indexOf(source), sd = d.sides.indexOf(side);
    const base = ((s * d.nInc + inc) * d.sides.length + sd) * n;
    const out = new Array(n);
    for (let k = 0; k < n; ++k) {
      const o = (base + k) * 3, v = [d.hemi[o], d.hemi[o + 1], d.hemi[o + 2]];
      out[k] = v.some((x) => !isFinite(x)) ? null : v;
    }
    return out;
  }

  // What a bin shows before the exposure: f, f · cos θo, or f scaled to Y = CHROMA_Y (null where
  // it has no light to take a colour from).
  function shown(rgb, cosTheta) {
    if (!rgb) return null;
    if (settings.mode === "fcos") return rgb.map((v) => v * cosTheta);
    if (settings.mode === "chroma") {
      const y = xyzOf(rgb)[1];
      return y > 0 ? rgb.map((v) => (v * CHROMA_Y) / y) : null;
    }
    return rgb;
  }

  // The exposure k, in whole stops: 2^(EV − ⌈log2 m⌉), m the largest channel of the reference over
  // the hemisphere's merged bins and the plane's bins, so that at EV 0 the reference's brightest bin
  // lies in (1/2, 1] and none clips; one k for every source of the view. A power of two keeps the
  // shown colours exact: k does not depend on the last digits of m. The chromaticity mode needs
  // none (k = 1).
  function exposureOf(values) {
    if (settings.mode === "chroma") return 1;
    let m = 0;
    for (const v of values) if (v) m = Math.max(m, v[0], v[1], v[2]);
    return m > 0 ? Math.pow(2, settings.ev - Math.ceil(Math.log2(m))) : 1;
  }

  function draw(api, d, cfg) {
    last = [api, d, cfg];
    const view = el("colour-view");
    if (!view) return;
    const st = api.state, side = st.side, inc = api.incidenceIndex(cfg);
    const h = d.hemiShape, geo = binGeometry(h), L = api.isoLookup(h), N = api.ISO_N;
    const light = api.isUnfolded(cfg) ? api.incidencesOf(cfg)[inc] : undefined;
    const models = api.models.filter((m) => st.shown.has(m) && d.sources.includes(m));
    const sources = ["reference"].concat(models);
    const supported = (m) => m === "reference" || api.isSupported(cfg, m, side);

    // The merged bins' shown values, per source; the plane's bins at full resolution.
    const bins = {}, plane = {};
    const T = api.nTheta(), xs = api.sliceAngles();
    const cosPlane = xs.map((x) => Math.cos((x * Math.PI) / 180));
    for (const s of sources) {
      if (!supported(s)) continue;
      bins[s] = hemiRgb(d, s, inc, side).map((v, k) => shown(v, geo.cosc[Math.floor(k / h.n_phi)]));
      const ch = [0, 1, 2].map((c) => api.slicePlane(d, s, inc, side, c));
      plane[s] = xs.map((_, x) => {
        const v = [ch[0][x], ch[1][x], ch[2][x]];
        return v.every(isFinite) ? shown(v, cosPlane[x]) : null;
      });
    }
    const k = exposureOf(bins.reference.concat(plane.reference));
    const lab = (v) => (v ? labOf(v.map((x) => x * k)) : null);
    const refLab = bins.reference.map(lab), refPlaneLab = plane.reference.map(lab);
    // The reference's energy per bin, Y(f) · Ω⊥, whatever the mode: the weight of the mean ΔE00.
    const refRgb = hemiRgb(d, "reference", inc, side);
    const weight = refRgb.map((v, j) => (v ? Math.max(0, xyzOf(v)[1]) * geo.w[j] : 0));

    // The disks.
    const disks = el("colour-disks");
    while (disks.children.length > sources.length) { Plotly.purge(disks.lastChild); disks.lastChild.remove(); }
    const means = {};
    sources.forEach((s, n) => {
      let div = disks.children[n];
      if (!div) { div = document.createElement("div"); div.className = "plot colour-disk"; disks.appendChild(div); }
      div.dataset.source = s;
      const layout = api.diskLayout(s, light);
      layout.height = 250;
      layout.margin = { l: 4, r: 4, t: 40, b: 4 };
      if (!bins[s]) {
        layout.annotations.push({ x: 0, y: 0, text: "<b>not supported</b>", showarrow: false, font: { size: 12, color: "#8a1c1c" } });
        Plotly.react(div, [], layout, api.PLOT_CONFIG);
        return;
      }
      const labs = s === "reference" ? refLab : bins[s].map(lab);
      const dE = labs.map((v, j) => (v && refLab[j] ? ciede2000(refLab[j], v) : null));
      let num = 0, den = 0;
      dE.forEach((e, j) => { if (e !== null && weight[j] > 0) { num += weight[j] * e; den += weight[j]; } });
      means[s] = den > 0 ? num / den : null;
      const z = [], text = [];
      for (let j = 0; j < N; ++j) {
        const row = new Array(N), trow = new Array(N);
        for (let i = 0; i < N; ++i) {
          const b = L.idx[j * N + i], v = b < 0 ? null : bins[s][b];
          if (!v) { row[i] = [0, 0, 0, 0]; trow[i] = ""; continue; }
          const shownRgb = displayOf(v.map((x) => x * k));
          row[i] = shownRgb.srgb.concat([1]);
          const t = Math.floor(b / h.n_phi), p = b % h.n_phi;
          trow[i] = "θo " + h.theta_edges[t].toFixed(0) + "–" + h.theta_edges[t + 1].toFixed(0) + "°, φo " +
            h.phi_edges[p].toFixed(0) + "–" + h.phi_edges[p + 1].toFixed(0) + "°<br>sRGB " + shownRgb.srgb.join(", ") +
            (shownRgb.clipped ? " (clipped)" : "") + (s === "reference" ? "" : "<br>ΔE00 " + (dE[b] === null ? "–" : dE[b].toFixed(2)));
        }
        z.push(row);
        text.push(trow);
      }
      layout.title.text = s + (s === "reference" ? "" : "<br><span style='font-size:11px'>mean ΔE00 " +
        (means[s] === null ? "–" : means[s].toFixed(2)) + "</span>");
      if (s !== "reference") layout.title.font = { size: 12, color: api.modelColor(s) };
      Plotly.react(div, [{
        type: "image", z, colormodel: "rgba", x0: L.axis[0], dx: L.axis[1] - L.axis[0], y0: L.axis[0], dy: L.axis[1] - L.axis[0],
        text, hovertemplate: s + "<br>%{text}<extra></extra>",
      }], layout, api.PLOT_CONFIG);
    });

    // The strip: colour against θo along the plane of incidence, one row per source.
    const rows = sources.filter((s) => plane[s]);
    const z = [], text = [];
    for (const s of rows) {
      const row = [], trow = [];
      plane[s].forEach((v, x) => {
        if (!v) { row.push([0, 0, 0, 0]); trow.push(""); return; }
        const shownRgb = displayOf(v.map((c) => c * k));
        row.push(shownRgb.srgb.concat([1]));
        const dE = s === "reference" || !refPlaneLab[x] ? null : ciede2000(refPlaneLab[x], lab(v));
        trow.push(s + "<br>θo " + xs[x].toFixed(1) + "°<br>sRGB " + shownRgb.srgb.join(", ") + (shownRgb.clipped ? " (clipped)" : "") +
          (dE === null ? "" : "<br>ΔE00 " + dE.toFixed(2)));
      });
      z.push(row);
      text.push(trow);
    }
    // Plotly draws an image's pixels square: a row is ROW degrees of θo tall.
    const ROW = 5;
    Plotly.react(el("colour-strip"), [{
      type: "image", z, colormodel: "rgba", x0: xs[0], dx: 90 / T, y0: 0, dy: ROW, text,
      hovertemplate: "%{text}<extra></extra>",
    }], {
      height: 90 + 26 * rows.length, margin: { l: 150, r: 10, t: 30, b: 40 },
      title: { text: "colour along the plane of incidence · " + api.incidenceText(cfg, inc), font: { size: 12 } },
      xaxis: { title: { text: "θo (°): light's side < 0 < mirror side" }, range: [-90, 90], zeroline: false },
      yaxis: { tickvals: rows.map((_, n) => n * ROW), ticktext: rows, range: [(rows.length - 0.5) * ROW, -0.5 * ROW] },
      plot_bgcolor: "#888",
    }, api.PLOT_CONFIG);

    const what = settings.mode === "f" ? "f" : settings.mode === "fcos" ? "f · cos θo" : "f at equal luminance";
    el("colour-note").textContent = "Each bin: linear RGB of " + what +
      (settings.mode === "chroma" ? " (Y = " + CHROMA_Y + ")" : " × exposure 2^" + Math.round(Math.log2(k)) + " sr") +
      ", then the sRGB transfer curve. ΔE00 (CIEDE2000) against the reference, per bin on hover; the mean over the " +
      "hemisphere weighted by the reference's energy Y · Ω⊥: " +
      models.map((m) => m + " " + (means[m] === undefined || means[m] === null ? "n/s" : means[m].toFixed(2))).join(", ") + ".";
    view.dataset.exposure = String(k);
    view.dataset.meanDe = JSON.stringify(means);
  }

  function init() {
    const mode = el("w-colour-mode"), ev = el("w-colour-ev");
    if (!mode || !ev) return;
    mode.addEventListener("change", () => {
      settings.mode = mode.value;
      ev.disabled = settings.mode === "chroma";  // one luminance: no exposure
      if (last) draw(...last);
    });
    ev.addEventListener("change", () => {
      const v = Number(ev.value);
      settings.ev = isFinite(v) ? Math.max(-20, Math.min(20, v)) : 0;
      ev.value = String(settings.ev);
      if (last) draw(...last);
    });
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", init);
  else init();

  (window.LAMINA_VIEWS = window.LAMINA_VIEWS || []).push({ name: "colour", draw });
})();
