// lamina explorer: the views of a study directory (docs/explorer.md). Plain browser JavaScript,
// no build step. Data: window.LAMINA_INDEX (explorer/data/index.js) and, per configuration,
// window.LAMINA_DATA[id] (explorer/data/<id>.js, loaded on demand by a <script> tag: file:// pages
// cannot fetch). Drawing: Plotly (explorer/plotly.min.js, vendored from npm at build time).
"use strict";

(function () {
  if (!window.LAMINA_INDEX || typeof Plotly !== "object") {
    document.getElementById("status").textContent = (window.LAMINA_INDEX ? "explorer/plotly.min.js" : "explorer/data/index.js") +
      " did not load: regenerate the page with `lamina explorer DIR`.";
    return;
  }
  const INDEX = window.LAMINA_INDEX;
  const STUDY = INDEX.study;
  const THETA_I = STUDY.theta_i;
  const CHANNELS = ["R", "G", "B"];
  const CHANNEL_COLORS = ["#b8322f", "#2e8540", "#2c5aa0"];

  // One colour per model, the same in every view and in the figures: web/model-colors.json, the one
  // table both read (lamina copies it into explorer/data/index.js as `palette`).
  const PALETTE = INDEX.palette || { models: {}, extra: ["#555"], dashed: [] };
  const MODEL_COLORS = PALETTE.models;
  const EXTRA_COLORS = PALETTE.extra;
  // Variants are dashed: Ele10 is WW09 with one change and often coincides with it, and so do
  // the two Bel18 cosines; a dashed line on top lets the solid one show through.
  const MODEL_DASH = Object.fromEntries((PALETTE.dashed || []).map((m) => [m, "dash"]));
  // Ablations ("openpbr:darkening=off") are dashed in their model's colour.
  const baseName = (name) => name.split(":")[0];
  const modelDash = (name) => MODEL_DASH[name] || (name.includes(":") ? "dash" : "solid");

  // The configuration widgets, in the order of the original study's explorer.
  const PARAMS = [
    ["alpha0", "α0 (top roughness)"], ["eta0", "η0 (top IOR)"], ["tau", "τa (absorption)"],
    ["tau_s", "τs (scattering)"], ["base", "base"], ["alpha1", "α1 (base roughness)"],
    ["eta1", "η1 (base IOR)"], ["kappa1", "κ1 (base extinction)"], ["rho", "ρ (base albedo)"],
    ["film_nm", "film thickness (nm)"], ["film_eta", "film η"],
  ];

  const configs = INDEX.configs;
  const byId = new Map(configs.map((c) => [c.id, c]));
  const models = (STUDY.models && STUDY.models.length)
    ? STUDY.models.slice()
    : Array.from(new Set(configs.flatMap((c) => c.sources.slice(1))));
  const categories = Array.from(new Set(configs.map((c) => c.category)));

  function modelColor(name) {
    if (MODEL_COLORS[name]) return MODEL_COLORS[name];
    if (MODEL_COLORS[baseName(name)]) return MODEL_COLORS[baseName(name)];
    const k = models.indexOf(name);
    return EXTRA_COLORS[(k < 0 ? 0 : k) % EXTRA_COLORS.length];
  }

  const state = {
    config: configs.length ? configs[0].id : null,
    incidence: Math.min(2, THETA_I.length - 1),  // the θi shown: an index into THETA_I
    phiI: 0,  // the azimuth φi shown, on an unfolded configuration (one lit from several)
    channels: [true, true, true],
    side: "R",
    log: true,
    shown: new Set(models),
    isoModel: models[0],
    isoChannel: 0,
    polChannel: 0,
    diffMode: "f",
    levels: "",
    lbMetric: "mf",
    lbIncidence: "all",
    lbAgg: "mean",
  };

  const $ = (id) => document.getElementById(id);
  const status = (text) => { $("status").textContent = text || ""; };
  const fmt = (v) => (v === null || v === undefined || !isFinite(v)) ? "–"
    : (Math.abs(v) >= 100 ? v.toFixed(0) : Number(v.toPrecision(2)).toString());
  const PLOT_CONFIG = { displaylogo: false, responsive: true, toImageButtonOptions: { format: "svg" } };

  // ---- Data: loading and decoding -------------------------------------------------------------

  const decoded = new Map();

  function bytesOf(b64) {
    const bin = atob(b64);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    return bytes.buffer;
  }

  // A packed array (docs/formats.md, "Packed arrays"): deflate, then byte planes of the
  // differences along n of each channel's run, laid out [outer, channels, n]. Returns the
  // elements (2 or 4 bytes each) in their order [outer, n, channels], as an ArrayBuffer.
  async function unpack(b64, width, n, channels) {
    const stream = new Blob([bytesOf(b64)]).stream().pipeThrough(new DecompressionStream("deflate"));
    const planes = new Uint8Array(await new Response(stream).arrayBuffer());
    const count = planes.length / width;
    const out = width === 2 ? new Uint16Array(count) : new Uint32Array(count);
    const row = n * channels;
    for (let o = 0; o < count; o += row)
      for (let c = 0; c < channels; ++c) {
        let x = 0;
        for (let k = 0; k < n; ++k) {
          const i = o + c * n + k;
          let d = 0;
          for (let b = 0; b < width; ++b) d += planes[b * count + i] * 2 ** (8 * b);
          x = width === 2 ? (x + d) & 0xffff : (x + d) >>> 0;  // modulo 2^16 or 2^32
          out[o + k * channels + c] = x;
        }
      }
    return out.buffer;
  }

  async function decode(raw) {
    const h = raw.hemi;
    const T = nTheta();
    // Studies' data written before packing held the raw bytes.
    const array = (b64, width, n) => raw.packed ? unpack(b64, width, n, 3) : Promise.resolve(bytesOf(b64));
    // 16-bit codes of log10 f (docs/explorer.md, "Data"): 0 is zero, 65535 not supported.
    const logDecode = async (b64, lo, hi) => {
      const codes = new Uint16Array(await array(b64, 2, h.n_phi));
      const out = new Float32Array(codes.length);
      const step = (hi - lo) / 65533;
      for (let k = 0; k < codes.length; ++k) {
        const q = codes[k];
        out[k] = q === 0 ? 0 : q === 65535 ? NaN : Math.pow(10, lo + (q - 1) * step);
      }
      return out;
    };
    const hemi = await logDecode(h.codes, h.lo, h.hi);
    const hemiSe = h.se_codes ? await logDecode(h.se_codes, h.se_lo, h.se_hi) : null;
    // The polarization view's 16-bit codes (docs/explorer.md, "Data"): q / 65534 of [lo, hi],
    // 65535 where the bin has no light.
    const linearDecode = async (b64, lo, hi) => {
      const codes = new Uint16Array(await array(b64, 2, h.n_phi));
      const out = new Float32Array(codes.length);
      for (let k = 0; k < codes.length; ++k) out[k] = codes[k] === 65535 ? NaN : lo + (hi - lo) * codes[k] / 65534;
      return out;
    };
    const p = raw.polarization;
    const pol = p ? {
      dop: await linearDecode(p.dop, 0, 1),
      dopSe: await linearDecode(p.dop_se, 0, 1),
      aolp: await linearDecode(p.aolp, -90, 90),
    } : null;
    return {
      raw,
      sources: raw.sources,
      sides: raw.sides,
      slice: new Float32Array(await array(raw.slice, 4, 2 * T)),
      // incidences: the slice holds [source, incidence, side, 2T, 3]
      get nInc() { return this.slice.length / (raw.sources.length * raw.sides.length * 2 * T * 3); },
      sliceSe: raw.slice_se ? new Float32Array(await array(raw.slice_se, 4, 2 * T)) : null,
      hemi,
      hemiSe,
      hemiShape: h,
      pol,
    };
  }

  function loadConfig(id) {
    if (decoded.has(id)) return Promise.resolve(decoded.get(id));
    return new Promise((resolve, reject) => {
      const done = () => {
        const raw = window.LAMINA_DATA && window.LAMINA_DATA[id];
        if (!raw) { reject(new Error("explorer/data/" + id + ".js did not define the configuration")); return; }
        decode(raw).then((d) => { decoded.set(id, d); resolve(d); },
          (e) => reject(new Error("explorer/data/" + id + ".js is damaged (" + e.message +
            "): write the page again with lamina explorer")));
      };
      if (window.LAMINA_DATA && window.LAMINA_DATA[id]) { done(); return; }
      const s = document.createElement("script");
      s.src = "explorer/data/" + encodeURIComponent(id) + ".js";
      s.onload = done;
      s.onerror = () => reject(new Error("cannot load explorer/data/" + id + ".js"));
      document.head.appendChild(s);
    });
  }

  const nTheta = () => STUDY.grid.n_theta;

  // A configuration's incidences as [θi, φi] pairs, in its tables' order: an unfolded one's own
  // (index entry `incidences`: an anisotropic stack lit from several azimuths, docs/formats.md),
  // else the study's θi at φi = 0.
  const incidencesOf = (cfg) => cfg.incidences || THETA_I.map((t) => [t, 0]);
  const isUnfolded = (cfg) => Boolean(cfg.incidences);
  // The azimuths an unfolded configuration is lit from.
  const azimuthsOf = (cfg) => Array.from(new Set(incidencesOf(cfg).map(([, p]) => p))).sort((a, b) => a - b);
  // The index of the incidence shown: the widgets' θi at the widgets' φi, or at the first azimuth
  // the configuration has for that θi (θi = 0 is lit once).
  function incidenceIndex(cfg) {
    const t = THETA_I[state.incidence];
    if (!isUnfolded(cfg)) return state.incidence;
    const incs = incidencesOf(cfg);
    let k = incs.findIndex(([a, b]) => a === t && b === state.phiI);
    if (k < 0) k = incs.findIndex(([a]) => a === t);
    return k < 0 ? 0 : k;
  }
  // "θi = 45°", and ", φi = 90°" on an unfolded configuration.
  function incidenceText(cfg, k) {
    const [t, p] = incidencesOf(cfg)[k];
    return "θi = " + t + "°" + (isUnfolded(cfg) ? ", φi = " + p + "°" : "");
  }

  // f on the incident plane: x from −90° (light's side) to +90° (mirror / straight through).
  function slicePlane(d, source, inc, side, channel) {
    const T = nTheta(), I = d.nInc, D = d.sides.length;
    const s = d.sources.indexOf(source), sd = d.sides.indexOf(side);
    const out = new Array(2 * T);
    const base = ((s * I + inc) * D + sd) * 2 * T;
    for (let x = 0; x < 2 * T; ++x) out[x] = d.slice[(base + x) * 3 + channel];
    return out;
  }

  function sliceSe(d, inc, side, channel) {
    if (!d.sliceSe) return null;
    const T = nTheta(), D = d.sides.length, sd = d.sides.indexOf(side);
    const base = (inc * D + sd) * 2 * T;
    const out = new Array(2 * T);
    for (let x = 0; x < 2 * T; ++x) out[x] = d.sliceSe[(base + x) * 3 + channel];
    return out;
  }

  function sliceAngles() {
    const T = nTheta(), xs = new Array(2 * T);
    for (let x = 0; x < 2 * T; ++x) {
      const t = x < T ? T - 1 - x : x - T;
      const c = (t + 0.5) * 90 / T;
      xs[x] = x < T ? -c : c;
    }
    return xs;
  }

  function isSupported(cfg, model, side) {
    const s = cfg.supported && cfg.supported[model];
    if (!cfg.sources.includes(model)) return false;
    if (!s) return true;
    return s[side] !== false;
  }

  function unsupportedReason(cfg, model) {
    const s = cfg.supported && cfg.supported[model];
    if (!cfg.sources.includes(model)) return "not in this study";
    return (s && s.reason) ? s.reason : "";
  }

  // "m (reason)", or the reason alone when it already names the model.
  const unsupportedText = (cfg, m) => {
    const r = unsupportedReason(cfg, m);
    return !r ? m : r.startsWith(m) ? r : m + " (" + r + ")";
  };

  const selectedChannels = () => [0, 1, 2].filter((c) => state.channels[c]);

  // ---- Widgets ----------------------------------------------------------------------------------

  function setOptions(select, items, value) {
    select.innerHTML = "";
    for (const [v, label] of items) {
      const o = document.createElement("option");
      o.value = v;
      o.textContent = label;
      select.appendChild(o);
    }
    select.value = value;
  }

  function numericSort(values) {
    const num = values.every((v) => v !== "" && !isNaN(Number(v)));
    return values.sort((a, b) => num ? Number(a) - Number(b) : a.localeCompare(b));
  }

  // The configuration with parameter `key` = `value` that keeps most of the others (earlier
  // widgets weigh more), within the current category.
  function bestMatch(key, value) {
    const cur = byId.get(state.config);
    let best = null, bestScore = -1;
    for (const c of configs) {
      if (c.category !== cur.category || c.parameters[key] !== value) continue;
      let score = 0;
      PARAMS.forEach(([k], n) => {
        if (k !== key && c.parameters[k] === cur.parameters[k]) score += 1 << (PARAMS.length - n);
      });
      if (score > bestScore) { best = c; bestScore = score; }
    }
    return best;
  }

  function buildConfigWidgets() {
    const cur = byId.get(state.config);
    setOptions($("w-category"), categories.map((c) => [c, c + " (" + configs.filter((x) => x.category === c).length + ")"]), cur.category);
    const inCategory = configs.filter((c) => c.category === cur.category);
    const box = $("param-widgets");
    box.innerHTML = "";
    for (const [key, label] of PARAMS) {
      const values = numericSort(Array.from(new Set(inCategory.map((c) => c.parameters[key]).filter((v) => v !== undefined))));
      if (!values.length) continue;
      const l = document.createElement("label");
      l.textContent = label + " ";
      const sel = document.createElement("select");
      sel.id = "w-param-" + key;
      sel.dataset.param = key;
      // Values that need other widgets to change are marked with an arrow.
      setOptions(sel, values.map((v) => {
        const exact = inCategory.some((c) => c.parameters[key] === v &&
          PARAMS.every(([k]) => k === key || c.parameters[k] === cur.parameters[k]));
        return [v, exact ? v : v + "  →"];
      }), cur.parameters[key] !== undefined ? cur.parameters[key] : values[0]);
      sel.disabled = values.length < 2;
      sel.addEventListener("change", () => {
        const c = bestMatch(key, sel.value);
        if (c) selectConfig(c.id);
      });
      l.appendChild(sel);
      box.appendChild(l);
    }
    setOptions($("w-config"), inCategory.map((c) => [c.id, c.id]), cur.id);
    $("config-desc").textContent = (cur.sides.includes("T") ? "BRDF and BTDF (a slab)" : "BRDF (opaque base)") +
      (isUnfolded(cur) ? " · full hemisphere (φ over 0°–360°), lit from φi = " + azimuthsOf(cur).join("°, ") + "°" : "");
    // The azimuth of the light: among those of an unfolded configuration; 0° otherwise.
    const phis = azimuthsOf(cur);
    if (!phis.includes(state.phiI)) state.phiI = phis[0];
    setOptions($("w-phi-i"), phis.map((p) => [p, p + "°"]), state.phiI);
    $("w-phi-i").disabled = phis.length < 2;
    $("w-phi-i-row").hidden = !isUnfolded(cur);
    // The hemisphere widget: BTDF only where the configuration transmits.
    $("w-side-T").disabled = !cur.sides.includes("T");
    if (!cur.sides.includes(state.side)) state.side = "R";
    $("w-side-" + state.side).checked = true;
    buildModelWidgets();
  }

  // The model families (study.json model_groups, from the registry): the 2019 set, Belcour's
  // statistical successors, the production coats, their one-flag ablations, a film's own model. A
  // study without the field puts every model in one group.
  const GROUP_NAMES = {
    lamina: "lamina-1", "2019": "2019 study", successors: "statistical successors", production: "production coats",
    films: "thin-film models", ablations: "production ablations", external: "your models (tables, Python)",
    reference: "reference", other: "models",
  };
  const GROUP_ORDER = ["lamina", "2019", "successors", "production", "ablations", "films",
    "external", "reference", "other"];
  const modelGroup = (m) => (STUDY.model_groups && STUDY.model_groups[m]) || "other";
  const groups = GROUP_ORDER.map((g) => [g, models.filter((m) => modelGroup(m) === g)])
    .filter(([, ms]) => ms.length);

  // Shows exactly the models of one group (or every model).
  function showGroup(g) {
    state.shown = new Set(g === "all" ? models : models.filter((m) => modelGroup(m) === g));
    buildModelWidgets();
    render();
  }

  function buildModelWidgets() {
    const cur = byId.get(state.config);
    const box = $("w-models");
    box.innerHTML = "";
    if (groups.length > 1) {
      const bar = document.createElement("div");
      bar.className = "group-bar";
      for (const [g] of [["all"]].concat(groups)) {
        const b = document.createElement("button");
        b.type = "button";
        b.id = "w-group-" + g;
        b.textContent = g === "all" ? "all" : GROUP_NAMES[g];
        b.title = "show only " + (g === "all" ? "every model" : "the " + GROUP_NAMES[g]);
        b.addEventListener("click", () => showGroup(g));
        bar.appendChild(b);
      }
      box.appendChild(bar);
    }
    for (const [g, ms] of groups) {
      if (groups.length > 1) {
        const h = document.createElement("div");
        h.className = "group-head";
        h.id = "w-group-head-" + g;
        h.textContent = GROUP_NAMES[g];
        box.appendChild(h);
      }
      for (const m of ms) {
        const ok = isSupported(cur, m, state.side);
        const l = document.createElement("label");
        l.className = "model-row" + (ok ? "" : " ns");
        l.dataset.group = g;
        const cb = document.createElement("input");
        cb.type = "checkbox";
        cb.id = "w-model-" + m;
        cb.checked = state.shown.has(m);
        cb.addEventListener("change", () => {
          if (cb.checked) state.shown.add(m); else state.shown.delete(m);
          render();
        });
        const sw = document.createElement("span");
        sw.className = "swatch";
        sw.style.background = modelDash(m) === "dash"
          ? "repeating-linear-gradient(90deg, " + modelColor(m) + " 0 6px, transparent 6px 9px)" : modelColor(m);
        l.append(cb, sw, document.createTextNode(m));
        if (!ok) {
          const t = document.createElement("span");
          t.className = "ns-tag";
          t.textContent = "not supported";
          l.appendChild(t);
        }
        box.appendChild(l);
      }
    }
    // The iso-value view follows to a model that supports this configuration when its own does not.
    if (!isSupported(cur, state.isoModel, state.side)) {
      const ok = models.find((m) => isSupported(cur, m, state.side));
      if (ok) state.isoModel = ok;
    }
    setOptions($("w-iso-model"), models.map((m) => [m, m + (isSupported(cur, m, state.side) ? "" : " (not supported)")]), state.isoModel);
  }

  function buildStaticWidgets() {
    $("study-name").textContent = "— " + (STUDY.name || "");
    const parts = [configs.length + " configurations", models.length + " models"];
    if (STUDY.preset) parts.push("preset " + STUDY.preset);
    if (STUDY.particles) parts.push(Number(STUDY.particles).toExponential(1).replace("e+", "·10^") + " particles per incidence");
    parts.push("grid " + STUDY.grid.n_theta + "×" + STUDY.grid.n_phi);
    // Which reference: exact, the 2019 study's (bpb19) or a mix; its rough interfaces scatter once
    // (the masked energy is lost) or multiply; light polarized or the Fresnel factors averaged.
    if (STUDY.physics) parts.push(STUDY.physics === "bpb19" ? "the 2019 reference" : STUDY.physics + " reference");
    if (STUDY.microsurface) parts.push((STUDY.microsurface === "multiple" ? "multiple" : "single") + "-scattering microsurfaces");
    if (typeof STUDY.polarization === "boolean") parts.push(STUDY.polarization ? "polarized light" : "unpolarized Fresnel factors");
    if (STUDY.lamina_version) parts.push("lamina " + STUDY.lamina_version);
    $("study-info").textContent = parts.join(" · ");
    setOptions($("w-incidence"), THETA_I.map((t, i) => [i, t + "°"]), state.incidence);
    setOptions($("w-lb-incidence"), [["all", "all θi"]].concat(THETA_I.map((t, i) => [i, "θi = " + t + "°"])), "all");
    // A study written before misplaced_floor existed ranks by the relative misplaced energy.
    const hasFloored = Object.values(INDEX.metrics || {}).some((mm) => Object.values(mm).some((sides) =>
      Object.values(sides).some((cell) => cell && cell.mf)));
    if (!hasFloored) {
      state.lbMetric = "me";
      const opt = $("w-lb-metric").querySelector('option[value="mf"]');
      if (opt) opt.remove();
    }
    $("w-lb-metric").value = state.lbMetric;

    $("w-category").addEventListener("change", () => {
      const first = configs.find((c) => c.category === $("w-category").value);
      if (first) selectConfig(first.id);
    });
    $("w-config").addEventListener("change", () => selectConfig($("w-config").value));
    $("w-incidence").addEventListener("change", () => { state.incidence = Number($("w-incidence").value); render(); });
    $("w-phi-i").addEventListener("change", () => { state.phiI = Number($("w-phi-i").value); render(); });
    CHANNELS.forEach((c, k) => $("w-ch-" + c.toLowerCase()).addEventListener("change", (e) => {
      state.channels[k] = e.target.checked;
      if (!selectedChannels().length) { state.channels[k] = true; e.target.checked = true; }
      render();
    }));
    for (const side of ["R", "T"]) $("w-side-" + side).addEventListener("change", () => {
      state.side = side; buildModelWidgets(); render();
    });
    $("w-log").addEventListener("change", () => { state.log = $("w-log").checked; render(); });
    $("w-iso-model").addEventListener("change", () => { state.isoModel = $("w-iso-model").value; render(); });
    $("w-iso-channel").addEventListener("change", () => { state.isoChannel = Number($("w-iso-channel").value); render(); });
    $("w-levels").addEventListener("change", () => { state.levels = $("w-levels").value; render(); });
    $("w-diff").addEventListener("change", () => { state.diffMode = $("w-diff").value; render(); });
    $("w-pol-channel").addEventListener("change", () => { state.polChannel = Number($("w-pol-channel").value); render(); });
    $("w-lb-metric").addEventListener("change", () => { state.lbMetric = $("w-lb-metric").value; render(); });
    $("w-lb-incidence").addEventListener("change", () => { state.lbIncidence = $("w-lb-incidence").value; render(); });
    $("w-lb-agg").addEventListener("change", () => { state.lbAgg = $("w-lb-agg").value; render(); });
  }

  function selectConfig(id) {
    if (!byId.has(id)) return;
    state.config = id;
    buildConfigWidgets();
    writeHash();
    render();
  }

  // The state in the address (#config=…&ti=…&side=…): a view can be shared as a link.
  function writeHash() {
    const h = "config=" + encodeURIComponent(state.config) + "&ti=" + THETA_I[state.incidence] +
      (isUnfolded(byId.get(state.config)) ? "&phi=" + state.phiI : "") + "&side=" + state.side;
    if (location.hash.slice(1) !== h) history.replaceState(null, "", "#" + h);
  }

  function readHash() {
    const p = new URLSearchParams(location.hash.slice(1));
    if (p.get("config") && byId.has(p.get("config"))) state.config = p.get("config");
    const ti = THETA_I.indexOf(Number(p.get("ti")));
    if (p.get("ti") !== null && ti >= 0) state.incidence = ti;
    if (p.get("phi") !== null && isFinite(Number(p.get("phi")))) state.phiI = Number(p.get("phi"));
    if (p.get("side") === "T" && byId.get(state.config).sides.includes("T")) state.side = "T";
  }

  // ---- Layout helpers ---------------------------------------------------------------------------

  // n side-by-side subplots, one per channel: axis names and a layout skeleton.
  function channelGrid(channels, xTitle, yTitle, height) {
    const n = channels.length, gap = 0.045;
    const layout = {
      height, margin: { l: 62, r: 12, t: 30, b: 48 }, hovermode: "closest",
      // The legend 62 pixels below the plots, clear of the x axes' titles at any height.
      legend: { orientation: "h", x: 0, yanchor: "top", y: -62 / Math.max(height - 78, 100) }, annotations: [], plot_bgcolor: "#fff",
    };
    channels.forEach((c, k) => {
      const sx = k === 0 ? "" : String(k + 1);
      const x0 = k / n + (k ? gap / 2 : 0), x1 = (k + 1) / n - (k < n - 1 ? gap / 2 : 0);
      layout["xaxis" + sx] = { domain: [x0, x1], anchor: "y" + sx, title: { text: xTitle }, zeroline: false, gridcolor: "#e8e8e8" };
      layout["yaxis" + sx] = {
        anchor: "x" + sx, title: { text: k === 0 ? yTitle : "" }, type: state.log ? "log" : "linear",
        gridcolor: "#e8e8e8", exponentformat: "power",
      };
      layout.annotations.push({
        text: "<b>" + CHANNELS[c] + " channel</b>", xref: "paper", yref: "paper", x: (x0 + x1) / 2, y: 1.0,
        xanchor: "center", yanchor: "bottom", showarrow: false, font: { color: CHANNEL_COLORS[c] },
      });
    });
    return layout;
  }
  const axisSuffix = (k) => (k === 0 ? "" : String(k + 1));

  // Ticks of a log axis over [lo, hi] (log10): decades, or 1-2-5 when the span is short, written
  // as plain numbers (0.02, 5, 300) or 1e-5 beyond.
  function logTicks(lo, hi) {
    const vals = [];
    const mantissas = hi - lo > 2.5 ? [1] : hi - lo > 1.2 ? [1, 3] : [1, 2, 5];
    for (let e = Math.floor(lo); e <= Math.ceil(hi); ++e)
      for (const m of mantissas) {
        const v = m * Math.pow(10, e);
        if (Math.log10(v) >= lo && Math.log10(v) <= hi) vals.push(v);
      }
    const text = vals.map((v) => (v >= 1e-3 && v < 1e5) ? String(Number(v.toPrecision(1))) : v.toExponential(0).replace("e+", "e"));
    return { tickmode: "array", tickvals: vals, ticktext: text };
  }

  // ---- View 1: the incident-plane slice ------------------------------------------------------------

  function drawSlice(d, cfg) {
    const chans = selectedChannels();
    const xs = sliceAngles();
    const inc = incidenceIndex(cfg), side = state.side, thetaI = incidencesOf(cfg)[inc][0];
    const traces = [];
    // On a log scale, at most six decades below the highest value drawn (zeros have no place).
    let fmax = 0;
    for (const c of chans) for (const s of ["reference"].concat(models.filter((m) => state.shown.has(m) && isSupported(cfg, m, side))))
      for (const v of slicePlane(d, s, inc, side, c)) if (v > fmax) fmax = v;
    const logTop = Math.log10(fmax || 1) + 0.25, logBottom = logTop - 6.25;
    const floor = Math.pow(10, logBottom);
    chans.forEach((c, k) => {
      const ax = { xaxis: "x" + axisSuffix(k), yaxis: "y" + axisSuffix(k) };
      const ref = slicePlane(d, "reference", inc, side, c);
      const se = sliceSe(d, inc, side, c);
      if (se) {
        const lo = ref.map((f, x) => {
          const v = f - 2 * se[x];
          return state.log ? Math.max(v, floor) : v;
        });
        const hi = ref.map((f, x) => f + 2 * se[x]);
        traces.push(Object.assign({ x: xs, y: lo, type: "scatter", mode: "lines", line: { width: 0 },
          hoverinfo: "skip", showlegend: false, legendgroup: "reference", name: "reference −2·se" }, ax));
        traces.push(Object.assign({ x: xs, y: hi, type: "scatter", mode: "lines", line: { width: 0 },
          fill: "tonexty", fillcolor: "rgba(0,0,0,0.18)", hoverinfo: "skip", legendgroup: "reference",
          name: "reference ±2·se", showlegend: k === 0 }, ax));
      }
      traces.push(Object.assign({ x: xs, y: ref, type: "scatter", mode: "lines", name: "reference",
        legendgroup: "reference", showlegend: k === 0, line: { color: modelColor("reference"), width: 2 },
        hovertemplate: "reference<br>θo %{x:.1f}°<br>f %{y:.4g} 1/sr<extra></extra>" }, ax));
      for (const m of models) {
        if (!state.shown.has(m) || !isSupported(cfg, m, side)) continue;
        traces.push(Object.assign({ x: xs, y: slicePlane(d, m, inc, side, c), type: "scatter", mode: "lines",
          name: m, legendgroup: m, showlegend: k === 0, line: { color: modelColor(m), width: 1.6, dash: modelDash(m) },
          hovertemplate: m + "<br>θo %{x:.1f}°<br>f %{y:.4g} 1/sr<extra></extra>" }, ax));
      }
    });
    const layout = channelGrid(chans, "θo (°)", (side === "R" ? "BRDF" : "BTDF") + " f (1/sr)", 420);
    chans.forEach((c, k) => {
      Object.assign(layout["xaxis" + axisSuffix(k)], { range: [-90, 90], tickvals: [-90, -60, -30, 0, 30, 60, 90] });
      if (state.log) {
        // Let the data decide within the six decades; label decades only when the span is wide.
        const ya = layout["yaxis" + axisSuffix(k)];
        let lo = Infinity;
        for (const t of traces) if (t.yaxis === "y" + axisSuffix(k) && t.hoverinfo !== "skip")
          for (const v of t.y) if (v > 0 && v < lo) lo = v;
        const bottom = Math.max(logBottom, Math.log10(lo) - 0.15);
        ya.range = [bottom, logTop];
        Object.assign(ya, logTicks(bottom, logTop));
      }
    });
    // The light's direction (−θi) and the mirror or straight-through direction (+θi), dotted.
    layout.shapes = [];
    chans.forEach((c, k) => {
      for (const x of [-thetaI, thetaI])
        layout.shapes.push({ type: "line", xref: "x" + axisSuffix(k), yref: "y" + axisSuffix(k) + " domain", x0: x, x1: x, y0: 0, y1: 1,
          line: { color: x < 0 ? "#c9a227" : "#999", width: 1, dash: "dot" } });
    });
    const parts = [cfg.id, incidenceText(cfg, inc), side === "R" ? "reflection" : "transmission"];
    if (isUnfolded(cfg))
      parts.push("the plane φ = φi (negative θo) and φi + 180°" +
        // Light along the normal has no azimuth: the study lights it once, and its slice is the
        // plane of that incidence's φi, whatever the φi widget says.
        (thetaI === 0 && incidencesOf(cfg)[inc][1] !== state.phiI
          ? " (normal incidence is lit once, from φi = " + incidencesOf(cfg)[inc][1] + "°: other planes on the iso maps)" : ""));
    if (cfg.spectral)
      parts.push("channels: linear sRGB (D65) of a spectral reference, " + cfg.spectral.min_nm + "–" + cfg.spectral.max_nm + " nm");
    parts.push("dotted: the light's direction (−θi) and the " + (side === "R" ? "mirror" : "straight-through") + " direction");
    // Plotly does not wrap a title: the parts go on as many lines as the plot's width needs.
    const perLine = Math.max(40, Math.floor(($("slice").clientWidth || 1000) / 7.2));
    const lines = [""];
    for (const part of parts) {
      const last = lines.length - 1;
      if (lines[last] && lines[last].length + 3 + part.length > perLine) lines.push(part);
      else lines[last] += (lines[last] ? " · " : "") + part;
    }
    layout.title = { text: lines.join(" ·<br>"), font: { size: 13 }, x: 0.01, xanchor: "left", y: 1, yref: "container", yanchor: "top",
      pad: { t: 6 + 17 * (lines.length - 1) } };  // Plotly anchors a title of several lines by its first
    layout.margin.t = 46 + 22 * (lines.length - 1);
    for (const a of layout.annotations) a.y = 1.0;
    Plotly.react($("slice"), traces, layout, PLOT_CONFIG);

    const missing = models.filter((m) => !isSupported(cfg, m, side))
      .map((m) => unsupportedText(cfg, m));
    $("unsupported").textContent = missing.length
      ? "Not supported for this configuration's " + (side === "R" ? "BRDF" : "BTDF") + ": " + missing.join("; ")
      : "";
  }

  // ---- View 2: iso-values on the projected disk -----------------------------------------------------

  const ISO_N = 101;
  let isoLookupCache = null;

  // For each pixel of the projected disk (x = −sinθ cosφ so that the light is on the left), the
  // index of its (θ, φ) bin in the merged hemisphere table, or −1 outside the disk.
  function isoLookup(h) {
    const key = h.theta_edges.join() + "|" + h.phi_edges.join() + "|" + Boolean(h.unfolded);
    if (isoLookupCache && isoLookupCache.key === key) return isoLookupCache;
    const axis = Array.from({ length: ISO_N }, (_, i) => -1 + 2 * i / (ISO_N - 1));
    const idx = new Int32Array(ISO_N * ISO_N);
    const find = (edges, v) => {
      let k = 0;
      while (k < edges.length - 2 && v >= edges[k + 1]) ++k;
      return k;
    };
    for (let j = 0; j < ISO_N; ++j)
      for (let i = 0; i < ISO_N; ++i) {
        const x = axis[i], y = axis[j], r = Math.hypot(x, y);
        if (r > 1) { idx[j * ISO_N + i] = -1; continue; }
        const theta = Math.asin(Math.min(1, r)) * 180 / Math.PI;
        // Folded: φ and −φ are one bin. Unfolded (φ over [0°, 360°)): the view from above turned
        // half a turn, (x, y) = −sinθ (cos φ, sin φ), so that φ = 0 is on the left.
        const phi = h.unfolded ? (Math.atan2(-y, -x) * 180 / Math.PI + 360) % 360
          : Math.atan2(Math.abs(y), -x) * 180 / Math.PI;
        idx[j * ISO_N + i] = find(h.theta_edges, theta) * h.n_phi + find(h.phi_edges, phi);
      }
    isoLookupCache = { key, idx, axis };
    return isoLookupCache;
  }

  // `source` "se" is the reference's standard error.
  function hemiMap(d, source, inc, side, channel) {
    const h = d.hemiShape, L = isoLookup(h);
    const I = d.nInc, D = d.sides.length;
    const isSe = source === "se";
    const s = isSe ? 0 : d.sources.indexOf(source), sd = d.sides.indexOf(side);
    const base = isSe ? (inc * D + sd) * h.n_theta * h.n_phi : ((s * I + inc) * D + sd) * h.n_theta * h.n_phi;
    const table = isSe ? d.hemiSe : d.hemi;
    const z = [];
    for (let j = 0; j < ISO_N; ++j) {
      const row = new Array(ISO_N);
      for (let i = 0; i < ISO_N; ++i) {
        const k = L.idx[j * ISO_N + i];
        row[i] = k < 0 ? null : table[(base + k) * 3 + channel];
      }
      z.push(row);
    }
    return z;
  }

  function parseLevels(text) {
    return text.split(/[,\s]+/).map(Number).filter((v) => isFinite(v) && (!state.log || v > 0));
  }

  // Automatic levels are evenly spaced in what is shown (half decades on a log scale, eighths of
  // the maximum on a linear one), so one Plotly contour trace draws them all; chosen levels get a
  // line trace each.
  function autoLevels(dmin, dmax) {
    if (!(dmax > dmin)) return null;
    if (state.log) return { start: Math.ceil(dmin * 2) / 2, end: dmax, size: 0.5 };
    const size = dmax / 8;
    return { start: size, end: dmax - size / 2, size };
  }

  function levelValues(auto) {
    const out = [];
    for (let v = auto.start; v <= auto.end + 1e-9; v += auto.size) out.push(state.log ? Math.pow(10, v) : v);
    return out;
  }

  function isoTraces(z, levels, auto, zmin, zmax, title, showScale) {
    const L = isoLookupCache;
    const toDisplay = (v) => (v === null || !isFinite(v)) ? null : state.log ? (v > 0 ? Math.log10(v) : null) : v;
    const zd = z.map((row) => row.map(toDisplay));
    const common = {
      x: L.axis, y: L.axis, z: zd, zmin, zmax, colorscale: "Viridis", showscale: showScale,
      hovertemplate: title + "<br>f %{customdata:.4g} 1/sr<extra></extra>", customdata: z,
      colorbar: { title: { text: state.log ? "log10 f" : "f (1/sr)", side: "right" }, thickness: 12, len: 0.9 },
    };
    if (auto) {
      return [Object.assign(common, {
        type: "contour", autocontour: false,
        contours: { start: auto.start, end: auto.end, size: auto.size, coloring: "heatmap", showlines: true,
          showlabels: !state.log, labelfont: { size: 9, color: "#fff" } },
        line: { color: "rgba(255,255,255,0.85)", width: 1 },
      })];
    }
    const traces = [Object.assign(common, { type: "heatmap" })];
    for (const level of levels) {
      const lv = state.log ? Math.log10(level) : level;
      traces.push({
        type: "contour", x: L.axis, y: L.axis, z: zd, showscale: false, hoverinfo: "skip",
        autocontour: false, showlegend: false,
        contours: { start: lv, end: lv, size: 1, coloring: "none", showlabels: !state.log,
          labelfont: { size: 9, color: "#fff" } },
        line: { color: "rgba(255,255,255,0.9)", width: 1 }, name: "f = " + fmt(level),
      });
    }
    return traces;
  }

  // `light`: [θi, φi] of an unfolded configuration, whose light is marked where it comes from and
  // whose plane of incidence is dotted; a folded one has its light on the left.
  function diskLayout(title, light) {
    if (light) {
      const [t, p] = light, r = Math.sin(t * Math.PI / 180), c = Math.cos(p * Math.PI / 180), s = Math.sin(p * Math.PI / 180);
      const layout = diskLayout(title);
      layout.shapes[1] = { type: "line", x0: c, x1: -c, y0: s, y1: -s, line: { color: "#bbb", width: 0.7, dash: "dot" } };
      layout.annotations = [{ x: -r * c, y: -r * s, text: "☀", showarrow: false, font: { size: 14, color: "#c9a227" } },
        { x: -0.98, y: -0.98, text: "light ☀ at φi = " + p + "°; φ = 0 on the left, 90° at the bottom", showarrow: false,
          font: { size: 10, color: "#777" }, xanchor: "left" }];
      return layout;
    }
    return {
      height: 340, margin: { l: 8, r: 8, t: 34, b: 8 }, title: { text: title, font: { size: 12 } },
      xaxis: { visible: false, range: [-1.04, 1.04], constrain: "domain" },
      yaxis: { visible: false, range: [-1.04, 1.04], scaleanchor: "x" },
      shapes: [{ type: "circle", x0: -1, x1: 1, y0: -1, y1: 1, line: { color: "#888", width: 1 } },
        { type: "line", x0: -1, x1: 1, y0: 0, y1: 0, line: { color: "#bbb", width: 0.7, dash: "dot" } }],
      annotations: [{ x: -0.98, y: -0.98, text: "light", showarrow: false, font: { size: 10, color: "#777" }, xanchor: "left" }],
      plot_bgcolor: "#fff", showlegend: false,
    };
  }

  function drawIso(d, cfg) {
    const inc = incidenceIndex(cfg), side = state.side, c = state.isoChannel, m = state.isoModel;
    const light = isUnfolded(cfg) ? incidencesOf(cfg)[inc] : undefined;
    const ref = hemiMap(d, "reference", inc, side, c);
    const supported = isSupported(cfg, m, side);
    const mod = supported ? hemiMap(d, m, inc, side, c) : null;
    let zmax = 0;
    for (const z of [ref, mod]) if (z) for (const row of z) for (const v of row) if (v > zmax) zmax = v;
    const dmax = state.log ? Math.log10(zmax || 1) : zmax;
    const dmin = state.log ? dmax - 4 : 0;
    const auto = state.levels.trim() ? null : autoLevels(dmin, dmax);
    const levels = auto ? levelValues(auto) : parseLevels(state.levels);
    const ch = CHANNELS[c];
    const sideName = side === "R" ? "BRDF" : "BTDF";
    const refLayout = diskLayout("reference · " + sideName + " · channel " + ch + " · " + incidenceText(cfg, inc), light);
    // A reference with nothing to contour says why rather than leaving a blank disk: no light on
    // this side (an opaque slab's BTDF), or all of it in a bin or two (a smooth stack's delta lobe).
    let lit = 0;
    for (const row of ref) for (const v of row) if (v > 0) ++lit;
    const emptyNote = lit === 0 ? "The reference has no light on this side (" + sideName + " 0 in every bin). "
      : lit <= 2 ? "The reference's light falls in " + lit + " bin" + (lit > 1 ? "s" : "") +
        " (a smooth interface's delta lobe): too few to contour; the slice shows it. " : "";
    const given = state.levels.trim() ? state.levels.trim().split(/[,\s]+/).length : 0;
    $("w-levels").setCustomValidity(given > levels.length ? "numbers" + (state.log ? " above 0 (log scale)" : "") : "");
    $("iso-levels").textContent = emptyNote + (levels.length ? "White contour lines at f = " + levels.map(fmt).join(", ") + " 1/sr"
      : "No contour lines: the levels must be numbers" + (state.log ? " above 0 on the log scale" : "")) +
      (given > levels.length && levels.length ? " (" + (given - levels.length) + " of the levels given ignored: not " +
        (state.log ? "numbers above 0)" : "numbers)") : "") +
      (auto && state.log ? " (every half decade)" : "") + "; reference and model share one colour scale" +
      (state.log ? " (log10 f, four decades)" : "") +
      ". Difference: red where the model puts too much energy, blue too little" +
      (state.diffMode === "sigma" ? "; in units of the reference's standard error, |Δf / se| < 2 is within its noise." : ".");
    Plotly.react($("iso-ref"), isoTraces(ref, levels, auto, dmin, dmax, "reference", false), refLayout, PLOT_CONFIG);
    if (mod) {
      Plotly.react($("iso-model"), isoTraces(mod, levels, auto, dmin, dmax, m, true), diskLayout(m + " · " + sideName + " · channel " + ch, light), PLOT_CONFIG);
      // Δf in 1/sr, or in units of the reference's standard error (|z| < 2: within the noise).
      const sigma = state.diffMode === "sigma" && d.hemiSe ? hemiMap(d, "se", inc, side, c) : null;
      const diff = mod.map((row, j) => row.map((v, i) => {
        if (v === null || ref[j][i] === null) return null;
        if (!sigma) return v - ref[j][i];
        const e = sigma[j][i];
        return e > 0 ? (v - ref[j][i]) / e : null;
      }));
      let amax = 0;
      for (const row of diff) for (const v of row) if (v !== null && isFinite(v)) amax = Math.max(amax, Math.abs(v));
      amax = sigma ? Math.min(Math.max(amax, 4), 20) : amax || 1;
      Plotly.react($("iso-diff"), [{
        type: "contour", x: isoLookupCache.axis, y: isoLookupCache.axis, z: diff, zmin: -amax, zmax: amax, zmid: 0,
        colorscale: "RdBu", ncontours: sigma ? undefined : 10, autocontour: !sigma,
        contours: sigma ? { start: -amax, end: amax, size: Math.max(2, Math.round(amax / 5)), coloring: "heatmap", showlines: true }
          : { coloring: "heatmap", showlines: true },
        line: { color: "rgba(40,40,40,0.5)", width: 0.6 },
        colorbar: { title: { text: sigma ? "Δf / se" : "Δf (1/sr)", side: "right" }, thickness: 12, len: 0.9 },
        hovertemplate: sigma ? "(model − reference) / se<br>%{z:.2f}<extra></extra>" : "model − reference<br>Δf %{z:.3g} 1/sr<extra></extra>",
      }], diskLayout(m + " − reference" + (sigma ? ", in se" : ""), light), PLOT_CONFIG);
    } else {
      const layout = diskLayout(m + " · " + ch);
      // The reason on lines that fit the disk (Plotly does not wrap an annotation).
      const words = String(unsupportedReason(cfg, m) || "").split(" "), reason = [""];
      for (const w of words)
        if (reason[reason.length - 1] && reason[reason.length - 1].length + 1 + w.length > 34) reason.push(w);
        else reason[reason.length - 1] += (reason[reason.length - 1] ? " " : "") + w;
      layout.annotations.push({ x: 0, y: 0, text: "<b>not supported</b><br>" + reason.join("<br>"),
        showarrow: false, font: { size: 12, color: "#8a1c1c" } });
      Plotly.react($("iso-model"), [], layout, PLOT_CONFIG);
      const dl = diskLayout(m + " − reference");
      dl.annotations.push({ x: 0, y: 0, text: "<b>not supported</b>", showarrow: false, font: { size: 14, color: "#8a1c1c" } });
      Plotly.react($("iso-diff"), [], dl, PLOT_CONFIG);
    }
  }

  // ---- View 6: polarization of the reference ---------------------------------------------------------

  // A polarization map of the reference (`table`: [incidence, side, θ, φ, channel] on the merged
  // bins) on the projected disk, as hemiMap.
  function polMap(d, table, inc, side, channel) {
    const h = d.hemiShape, L = isoLookup(h);
    const base = (inc * d.sides.length + d.sides.indexOf(side)) * h.n_theta * h.n_phi;
    const z = [];
    for (let j = 0; j < ISO_N; ++j) {
      const row = new Array(ISO_N);
      for (let i = 0; i < ISO_N; ++i) {
        const k = L.idx[j * ISO_N + i];
        const v = k < 0 ? NaN : table[(base + k) * 3 + channel];
        row[i] = isFinite(v) ? v : null;
      }
      z.push(row);
    }
    return z;
  }

  // A cyclic colour scale for the angle of linear polarization: −90° and +90° are one direction.
  const AOLP_COLORS = [[0, "#c0392b"], [0.25, "#e6b91e"], [0.5, "#2e8b57"], [0.75, "#2c5aa0"], [1, "#c0392b"]];

  function drawPolarization(d, cfg) {
    const none = $("pol-none"), maps = $("pol-maps"), note = $("pol-note");
    const reason = STUDY.polarization === false
      ? "Not polarized: this study's reference follows unpolarized Fresnel factors (" +
        (STUDY.physics === "bpb19" ? "--physics bpb19" : "--polarization off") +
        "), so it says nothing about the polarization of the light it reflects."
      : !d.pol ? "No polarization data for " + cfg.id + ": the study stored no Stokes vectors of its reference" +
        " (configs/" + cfg.id + "/reference_stokes.lza: `lamina study --reference-stokes on`, a polarized reference that is not spectral)."
        : null;
    document.body.dataset.polarization = reason ? "none" : "drawn";
    none.hidden = !reason;
    maps.hidden = Boolean(reason);
    if (reason) { none.textContent = reason; note.textContent = ""; return; }
    const inc = incidenceIndex(cfg), side = state.side, c = state.polChannel;
    $("w-pol-channel").value = String(c);
    const light = isUnfolded(cfg) ? incidencesOf(cfg)[inc] : undefined;
    const L = isoLookup(d.hemiShape);
    const dop = polMap(d, d.pol.dop, inc, side, c), dopSe = polMap(d, d.pol.dopSe, inc, side, c);
    // The angle where the degree is above twice its standard error (elsewhere it is noise). A
    // folded bin holds the patch φ ≥ 0 (the lower half of the disk); its mirror image, the upper
    // half, has the opposite angle (docs/physics.md §8: the mirror flips S2).
    const aolp = polMap(d, d.pol.aolp, inc, side, c).map((row, j) => row.map((v, i) => {
      if (v === null || dop[j][i] === null || !(dop[j][i] > 2 * dopSe[j][i])) return null;
      return !isUnfolded(cfg) && L.axis[j] > 0 ? -v : v;
    }));
    const ch = CHANNELS[c], what = side === "R" ? "reflected" : "transmitted";
    Plotly.react($("pol-dop"), [{
      type: "heatmap", x: L.axis, y: L.axis, z: dop, zmin: 0, zmax: 1, colorscale: "Viridis", customdata: dopSe,
      colorbar: { title: { text: "degree", side: "right" }, thickness: 12, len: 0.9 },
      hovertemplate: "degree of polarization %{z:.3f} ± %{customdata:.3f}<extra></extra>",
    }], diskLayout("degree of polarization · " + what + " · " + ch + " · " + incidenceText(cfg, inc), light), PLOT_CONFIG);
    Plotly.react($("pol-aolp"), [{
      type: "heatmap", x: L.axis, y: L.axis, z: aolp, zmin: -90, zmax: 90, colorscale: AOLP_COLORS,
      colorbar: { title: { text: "angle (°)", side: "right" }, thickness: 12, len: 0.9, tickvals: [-90, -45, 0, 45, 90] },
      hovertemplate: "angle of linear polarization %{z:.1f}°<extra></extra>",
    }], diskLayout("angle of linear polarization · " + ch, light), PLOT_CONFIG);
    note.textContent = "For unpolarized incident light: the degree of polarization √(S1² + S2² + S3²) / S0 of each bin's " +
      "Stokes vector (0 unpolarized, 1 fully polarized; ± its standard error on hover, and noise alone gives about that much " +
      "where the light is unpolarized). The angle of the linear part, ½ atan2(S2, S1), is drawn where the degree exceeds " +
      "twice its standard error: 0° is polarized horizontally, ⊥ to the vertical plane of the exit direction (s-polarized " +
      "in the plane of incidence), ±90° in that plane.";
  }

  // ---- View 3: directional albedo against θi -------------------------------------------------------

  function drawAlbedo(cfg) {
    const chans = selectedChannels(), side = state.side;
    const traces = [];
    // Against θi at the azimuth shown (θi = 0, lit once, belongs to every azimuth).
    const incs = incidencesOf(cfg);
    const phiShown = azimuthsOf(cfg).includes(state.phiI) ? state.phiI : incs[incidenceIndex(cfg)][1];
    const ks = incs.map((_, k) => k).filter((k) => !isUnfolded(cfg) || incs[k][0] === 0 ||
      incs[k][1] === phiShown);
    const THETA_I = ks.map((k) => incs[k][0]);
    const pick = (arr) => ks.map((k) => arr[k]);
    chans.forEach((c, k) => {
      const ax = { xaxis: "x" + axisSuffix(k), yaxis: "y" + axisSuffix(k) };
      const ref = pick(cfg.albedo.reference[side]).map((v) => (v ? v[c] : null));
      const se = cfg.albedo_se && cfg.albedo_se[side] ? pick(cfg.albedo_se[side]).map((v) => 2 * v[c]) : null;
      traces.push(Object.assign({ x: THETA_I, y: ref, type: "scatter", mode: "lines+markers", name: "reference (±2·se)",
        legendgroup: "reference", showlegend: k === 0, line: { color: "#000", width: 2 },
        error_y: se ? { type: "data", array: se, visible: true, color: "#555" } : undefined,
        hovertemplate: "reference<br>θi %{x}°<br>albedo %{y:.4f}<extra></extra>" }, ax));
      // What the reference loses to its single-scattering microsurfaces (config.json → energy):
      // energy that no side of the reference holds, and that models which conserve it put back.
      const lost = cfg.budget && cfg.budget.lost_microsurface;
      // Drawn only where some channel lost something (an entry is an RGB triple, or null); its
      // note under the plot with it.
      const lostAny = Boolean(lost && lost.some((v) => v && v.some((x) => x > 0)));
      $("albedo-lost-note").hidden = !lostAny;
      if (lostAny) {
        traces.push(Object.assign({ x: THETA_I, y: pick(lost).map((v) => (v ? v[c] : null)), type: "scatter",
          mode: "lines+markers", name: "reference: lost to microsurfaces", legendgroup: "lost", showlegend: k === 0,
          line: { color: "#888", width: 1.5, dash: "dot" }, marker: { size: 4, symbol: "x" },
          hovertemplate: "reference: lost to microsurfaces<br>θi %{x}°<br>fraction %{y:.4f}<extra></extra>" }, ax));
      }
      for (const m of models) {
        if (!state.shown.has(m) || !isSupported(cfg, m, side) || !cfg.albedo[m]) continue;
        traces.push(Object.assign({ x: THETA_I, y: pick(cfg.albedo[m][side]).map((v) => (v ? v[c] : null)),
          type: "scatter", mode: "lines+markers", name: m, legendgroup: m, showlegend: k === 0,
          line: { color: modelColor(m), width: 1.5, dash: modelDash(m) }, marker: { size: 5 },
          hovertemplate: m + "<br>θi %{x}°<br>albedo %{y:.4f}<extra></extra>" }, ax));
      }
    });
    const layout = channelGrid(chans, "θi (°)" + (isUnfolded(cfg) ? " at φi = " + phiShown + "°" : ""),
      (side === "R" ? "reflected" : "transmitted") + " albedo", 330);
    chans.forEach((c, k) => {
      layout["yaxis" + axisSuffix(k)].type = "linear";
      Object.assign(layout["xaxis" + axisSuffix(k)], { range: [-3, 90], tickvals: THETA_I });
    });
    Plotly.react($("albedo"), traces, layout, PLOT_CONFIG);
  }

  // ---- View 4: the leaderboard -----------------------------------------------------------------------

  function aggregate(values) {
    const v = values.filter((x) => x !== null && x !== undefined && isFinite(x));
    if (!v.length) return null;
    return state.lbAgg === "max" ? Math.max(...v) : v.reduce((a, b) => a + b, 0) / v.length;
  }

  // A configuration's values of one metric over the leaderboard's incidences (θi: at every
  // azimuth of an unfolded configuration) and the selected channels.
  function cellValues(cell, key, cfg) {
    if (!cell || !cell[key]) return [];
    const all = incidencesOf(cfg).map((_, i) => i);
    const incs = state.lbIncidence === "all" ? all
      : all.filter((i) => incidencesOf(cfg)[i][0] === THETA_I[Number(state.lbIncidence)]);
    const out = [];
    for (const i of incs) for (const c of selectedChannels()) {
      const v = cell[key][i] ? cell[key][i][c] : null;
      out.push(v === null ? null : key === "ae" ? Math.abs(v) : v);
    }
    return out;
  }

  // The leaderboard's metrics with a noise floor, and the metrics.csv column of that floor (data
  // index keys: mf misplaced_floor, me misplaced_energy, nf noise_floor, nf_mf misplaced_floor_noise).
  const NOISE_FLOOR_OF = { mf: "nf_mf", me: "nf" };

  function drawLeaderboard() {
    const side = state.side, metric = state.lbMetric;
    const cols = ["noise floor"].concat(models);
    const shownConfigs = configs.filter((c) => c.sides.includes(side));
    const rows = shownConfigs.map((c) => c.id);
    const z = [], text = [], hover = [], raw = [];
    for (const cfg of shownConfigs) {
      const mm = (INDEX.metrics || {})[cfg.id] || {};
      const zr = [], tr = [], hr = [], rr = [];
      // The noise floor: what a perfect model would score against this reference (misplaced energy,
      // relative or floored: each metric has its own).
      const nfKey = NOISE_FLOOR_OF[metric];
      let nf = null;
      if (nfKey) for (const m of models) if (mm[m] && mm[m][side]) { nf = aggregate(cellValues(mm[m][side], nfKey, cfg)); if (nf !== null) break; }
      zr.push(nf !== null && nf > 0 ? Math.log10(nf) : null);
      rr.push(nf);
      tr.push(nfKey ? fmt(nf) : "");
      hr.push(cfg.id + "<br>noise floor " + fmt(nf));
      for (const m of models) {
        const has = cfg.sides.includes(side);
        const ok = has && isSupported(cfg, m, side);
        const v = ok && mm[m] ? aggregate(cellValues(mm[m][side], metric, cfg)) : null;
        zr.push(v !== null && v > 0 ? Math.log10(v) : null);
        rr.push(v);
        const below = nfKey && v !== null && nf !== null && v <= 2 * nf;
        tr.push(!has ? "" : !ok ? "n/s" : fmt(v) + (below ? "≈" : ""));
        hr.push(cfg.id + " · " + m + "<br>" + (!has ? "no " + (side === "R" ? "BRDF" : "BTDF")
          : !ok ? "not supported" + (unsupportedReason(cfg, m) ? ": " + unsupportedReason(cfg, m) : "")
          : $("w-lb-metric").selectedOptions[0].textContent + " " + fmt(v) + (below ? " (within 2× the noise floor)" : "")));
      }
      z.push(zr); text.push(tr); hover.push(hr); raw.push(rr);
    }
    // A last row: each model's mean over the configurations it supports (never counting n/s as 0),
    // the ranking of the models at a glance.
    if (rows.length > 1) {
      const MEAN = "mean of supported";
      const zr = [], tr = [], hr = [];
      cols.forEach((col, j) => {
        const vals = raw.map((r) => r[j]).filter((v) => v !== null && isFinite(v));
        const m = vals.length ? vals.reduce((a, b) => a + b, 0) / vals.length : null;
        zr.push(m !== null && m > 0 ? Math.log10(m) : null);
        tr.push(m === null ? "" : "<b>" + fmt(m) + "</b>");
        hr.push(col + "<br>mean over the " + vals.length + " configurations with a value");
      });
      rows.push(MEAN); z.push(zr); text.push(tr); hover.push(hr);
    }
    const all = z.flat().filter((v) => v !== null);
    let zmin = all.length ? Math.min(...all) : -3, zmax = all.length ? Math.max(...all) : 0;
    if (!(zmax > zmin)) { zmin -= 0.5; zmax += 0.5; }  // one value (one configuration, one model)
    // The colour bar's labels: the decades inside [zmin, zmax], or its two ends where fewer than
    // two decades fall inside (a bar labelled outside its range shows no label at all).
    let ticks = [];
    for (let e = Math.ceil(zmin); e <= Math.floor(zmax); ++e) ticks.push(e);
    if (ticks.length < 2) ticks = [zmin, zmax];
    const cur = rows.indexOf(state.config);
    const trace = {
      type: "heatmap", x: cols, y: rows, z, text, customdata: hover, zmin, zmax,
      texttemplate: "%{text}", textfont: { size: 10 }, colorscale: "YlOrRd", reversescale: true, xgap: 1, ygap: 1,
      hovertemplate: "%{customdata}<extra></extra>",
      colorbar: { title: { text: "log scale" }, tickvals: ticks, ticktext: ticks.map((e) => fmt(Math.pow(10, e))), thickness: 12 },
    };
    // Column headers slanted when level ones would run into each other (long model names: the
    // ablations' "openpbr:darkening=off"), with the top margin to hold them.
    const longest = Math.max(...cols.map((c) => String(c).length), 1);
    const width = $("leaderboard").clientWidth || 900;
    const slanted = longest * 6.5 > (width - 220) / Math.max(cols.length, 1);
    const top = slanted ? Math.min(280, 40 + 5 * longest) : 70;
    // At least 90 pixels of grid, so that the colour bar beside a row or two can be read.
    const gridHeight = Math.max(19 * rows.length, 90);
    const layout = {
      height: 40 + top + gridHeight,
      margin: { l: Math.min(320, Math.max(200, 24 + 6.6 * Math.max(...rows.map((r) => String(r).length)))), r: 20, t: top, b: 10 },
      // Explicit categories and ranges: the grid stays drawn even where every cell is empty.
      xaxis: { side: "top", tickangle: slanted ? -40 : 0, fixedrange: true, type: "category", categoryorder: "array",
        categoryarray: cols, range: [-0.5, cols.length - 0.5] },
      yaxis: { fixedrange: true, tickfont: { size: 11 }, type: "category", categoryorder: "array",
        categoryarray: rows, range: [rows.length - 0.5, -0.5] },
      plot_bgcolor: "#e9ebef",
      shapes: (cur < 0 ? [] : [{ type: "rect", xref: "paper", x0: 0, x1: 1, yref: "y", y0: cur - 0.5, y1: cur + 0.5,
        line: { color: "#2458a6", width: 2 } }]).concat(
        // the noise floor apart from the models, the mean row apart from the configurations
        [{ type: "line", xref: "x", x0: 0.5, x1: 0.5, yref: "paper", y0: 0, y1: 1, line: { color: "#333", width: 1.5 } }],
        rows.length > shownConfigs.length ? [{ type: "line", xref: "paper", x0: 0, x1: 1, yref: "y",
          y0: shownConfigs.length - 0.5, y1: shownConfigs.length - 0.5, line: { color: "#333", width: 1.5 } }] : []),
      // The caption above the column headers (slanted ones reach top − 20 pixels above the grid).
      annotations: [{ xref: "paper", yref: "paper", x: 0, y: 1, yanchor: "bottom", yshift: slanted ? top - 24 : 34, showarrow: false, align: "left",
        text: (side === "R" ? "BRDF" : "BTDF") + " · " + (state.lbAgg === "max" ? "worst" : "mean") + " over " +
          (state.lbIncidence === "all" ? "all incidences" : "θi = " + THETA_I[Number(state.lbIncidence)] + "°") +
          " and the selected channels · ≈: within 2× the noise floor · n/s: not supported", font: { size: 11, color: "#555" } }],
    };
    if (!all.length) {
      // Plotly draws no text on a heat map without values: a text trace says what each cell is.
      trace.showscale = false;
      layout.annotations.push({ xref: "paper", yref: "paper", x: 0.5, y: -0.02, yanchor: "top", showarrow: false,
        text: "no model has this metric for the " + (side === "R" ? "BRDF" : "BTDF") + " of these configurations",
        font: { size: 12, color: "#8a1c1c" } });
      layout.margin.b = 30;
    }
    const cellText = {
      type: "scatter", mode: "text", hoverinfo: "skip", showlegend: false, textfont: { size: 10, color: "#555" },
      x: [], y: [], text: [],
    };
    if (!all.length) rows.forEach((r, i) => cols.forEach((c, j) => { cellText.x.push(c); cellText.y.push(r); cellText.text.push(text[i][j]); }));
    const gd = $("leaderboard");
    Plotly.react(gd, all.length ? [trace] : [trace, cellText], layout, PLOT_CONFIG);
    if (!gd.dataset.clickBound) {
      gd.on("plotly_click", (ev) => {
        const p = ev.points && ev.points[0];
        if (p && byId.has(p.y)) {
          const col = p.x;
          if (models.includes(col)) { state.isoModel = col; state.shown.add(col); }
          selectConfig(p.y);
          $("slice").scrollIntoView({ behavior: "instant", block: "start" });
        }
      });
      gd.dataset.clickBound = "1";
    }
  }

  // ---- View 5: sphere renderings -----------------------------------------------------------------------

  function drawRenders(cfg) {
    const box = $("renders");
    box.innerHTML = "";
    const names = Object.keys(cfg.renders || {});
    if (!names.length) {
      box.textContent = "This study has no sphere renderings for " + cfg.id + " (configs/" + cfg.id + "/renders/<source>.png).";
      return;
    }
    for (const s of ["reference"].concat(models)) {
      if (!cfg.renders[s]) {
        // A model the renderer could not draw: say so in its place.
        const err = cfg.render_errors && cfg.render_errors[s];
        if (err !== undefined && isNaN(Number(err))) {
          const f = document.createElement("figure");
          f.innerHTML = '<div class="render-missing"></div><figcaption></figcaption>';
          f.querySelector(".render-missing").textContent = err;
          f.querySelector("figcaption").textContent = s;
          box.appendChild(f);
        }
        continue;
      }
      const f = document.createElement("figure");
      const img = document.createElement("img");
      img.src = cfg.renders[s];
      img.alt = s;
      const cap = document.createElement("figcaption");
      const err = cfg.render_errors && cfg.render_errors[s];
      cap.textContent = s + (err === undefined ? "" : isNaN(Number(err)) ? " · " + err : " · rel. RMSE " + fmt(Number(err)));
      cap.style.color = modelColor(s);
      f.append(img, cap);
      box.appendChild(f);
    }
  }

  // ---- View 5b: live spheres (web/spheres.js; docs/explorer.md, "Live spheres") -------------------------

  const LIVE_SIZE = 192, LIVE_SPP = 256;
  const live = { renderer: null, why: "", frame: 0, running: -1, visible: false, pending: null };
  // A parameter as the study writes it (study/configurations.cpp): a number, or an RGB triple
  // "(r, g, b)"; null for anything else (a measured metal's name, an anisotropic "αx×αy").
  function rgbParameter(text) {
    if (text === undefined) return null;
    const s = String(text).trim(), m = s.match(/^\((.*)\)$/);
    const parts = m ? m[1].split(",") : [s];
    if (parts.length !== 1 && parts.length !== 3) return null;
    const v = parts.map((x) => (x.trim() === "" ? NaN : Number(x)));
    if (v.some((x) => !Number.isFinite(x))) return null;
    return v.length === 1 ? [v[0], v[0], v[0]] : v;
  }
  // The coat τa widget: one number (grey) or three, r, g, b, each in [0, 10]; null if it holds
  // anything else (the widget is then marked invalid and the configuration's τa is used).
  function liveTau(cfg) {
    const input = $("w-live-tau"), text = input.value.trim();
    const v = rgbParameter(text.startsWith("(") ? text : "(" + text + ")");
    const ok = v && v.every((x) => x >= 0 && x <= 10);
    input.setCustomValidity(ok ? "" : "one number, or three (r, g, b), each in [0, 10]");
    return ok ? v : rgbParameter((cfg.parameters || {}).tau) || [0, 0, 0];
  }
  // The lamina-coat material of a configuration's coat (its parameters as the study lists them),
  // with the widgets' values where the user changed them: null where lamina-coat does not apply
  // (lamina-coat: one dielectric coat, absorbing only, over a Lambertian or conductor base whose
  // index is given per channel; lamina-coat is isotropic). The study's parameters are strings:
  // numbers, RGB triples "(r, g, b)", a measured metal's name, an anisotropic "αx×αy".
  function coatMaterial(cfg) {
    const q = cfg.parameters || {}, w = (id) => Number($(id).value), num = (k) => Number(q[k]);
    const conductor = q.base === "conductor";
    if (q.layers !== undefined || q.tau_s !== undefined || q.film_nm !== undefined ||
        (q.base !== "lambertian" && !conductor) || !(num("eta0") >= 1.1) || !Number.isFinite(num("alpha0")) ||
        (q.alpha1 !== undefined && !Number.isFinite(num("alpha1")))) return null;
    const eta1 = conductor ? rgbParameter(q.eta1) : [1, 1, 1], kappa1 = conductor ? rgbParameter(q.kappa1) : [0, 0, 0];
    if (!eta1 || !kappa1) return null;  // a measured metal: its index is a spectrum
    const eta = w("w-live-eta");
    return {
      eta, alpha_coat: w("w-live-alpha0"), tau: liveTau(cfg),
      conductor, albedo: $("w-live-colour").value.match(/\w\w/g).map((h) => parseInt(h, 16) / 255),
      base_eta: eta1.map((v) => v / eta), base_k: kappa1.map((v) => v / eta),
      alpha_base: w("w-live-alpha1"),
    };
  }
  // Sets the live widgets to the configuration's stack.
  function resetLiveWidgets(cfg) {
    const p = cfg.parameters || {}, finite = (v, otherwise) => (Number.isFinite(Number(v)) && v !== undefined ? v : otherwise);
    $("w-live-alpha0").value = finite(p.alpha0, 0.1);
    $("w-live-eta").value = finite(p.eta0, 1.5);
    const tau = rgbParameter(p.tau) || [0, 0, 0];
    $("w-live-tau").value = tau[0] === tau[1] && tau[1] === tau[2] ? String(tau[0]) : tau.join(", ");
    $("w-live-tau").setCustomValidity("");
    $("w-live-alpha1").value = finite(p.alpha1, 0);
    const rho = rgbParameter(p.rho) || [0.8, 0.8, 0.8];
    $("w-live-colour").value = "#" + rho.map((c) =>
      Math.round(255 * Math.min(1, Math.max(0, c))).toString(16).padStart(2, "0")).join("");
  }
  // The hemisphere table of `source` at every incidence, for the table path of spheres.js.
  function liveTable(d, source) {
    const h = d.hemiShape, I = d.nInc, D = d.sides.length, s = d.sources.indexOf(source), sd = d.sides.indexOf("R");
    const n = h.n_theta * h.n_phi, values = new Float32Array(I * n * 3);
    const order = THETA_I.slice(0, I).map((t, i) => i).sort((a, b) => THETA_I[a] - THETA_I[b]);  // ascending θi
    order.forEach((i, k) =>
      values.set(d.hemi.subarray(((s * I + i) * D + sd) * n * 3, ((s * I + i) * D + sd + 1) * n * 3), k * n * 3));
    return { theta_edges: h.theta_edges, phi_edges: h.phi_edges, theta_i: order.map((i) => THETA_I[i]), values };
  }
  function drawLive(d, cfg, reset) {
    const note = $("live-note"), select = $("w-live-model");
    if (!live.renderer && !live.why) {
      const r = window.LAMINA_SPHERES ? window.LAMINA_SPHERES.createRenderer($("live-canvas"), LIVE_SIZE, window.LAMINA_GLSL)
        : { why: "The live spheres' script (explorer/spheres.js) is missing." };
      if (r.why) live.why = r.why; else live.renderer = r;
    }
    if (live.why) {
      $("live-canvas").hidden = true;
      note.textContent = live.why;
      document.body.dataset.live = "unavailable";
      return;
    }
    if (reset) resetLiveWidgets(cfg);
    // The models this configuration can show: lamina-coat where it applies, and every source the
    // study has a table of (folded configurations: the tables are interpolated over the bins).
    const choices = [];
    const l1 = d.raw.lamina1;
    if (l1) choices.push("lamina-1");
    if (coatMaterial(cfg)) choices.push("lamina-coat");
    if (!d.hemiShape.unfolded && d.nInc <= 32 && d.hemiShape.n_theta < 64 && d.hemiShape.n_phi < 64)
      for (const s of d.sources) if (s === "reference" || isSupported(cfg, s, "R")) choices.push("table:" + s);
    const keep = select.value;
    setOptions(select, choices.map((c) => [c, c.startsWith("table:") ? c.slice(6) + " (table)" : c + " (GLSL)"]),
      choices.includes(keep) ? keep : choices[0]);
    if (!choices.length) {
      // Nothing to draw: no canvas, and none of the models' widgets either.
      $("live-canvas").hidden = true;
      $("live-coat").hidden = true;
      $("live-l1").hidden = true;
      note.textContent = "No model of this configuration can be rendered live.";
      document.body.dataset.live = "none";
      return;
    }
    $("live-canvas").hidden = false;
    const model = select.value, env = $("w-live-env").value;
    const scene = { env, lobeAlpha: Math.min(Math.max(Number($("w-live-alpha0").value), 0.02), 1) };
    if (model === "lamina-1") {
      // The study's states (config.json → lamina1_gpu): the stack's own, or one variant's
      // per-material part over the stack's slope-sum table.
      if (!l1.all) l1.all = window.LAMINA_SPHERES.floatsOf(l1.floats);
      if (reset || $("w-live-l1").dataset.config !== cfg.id) {
        setOptions($("w-live-l1"), [["", "the configuration's stack"]].concat(l1.variants.map(([p, v], k) =>
          [String(k), (L1_PARAMS[p] || p) + " = " + v])), "");
        $("w-live-l1").dataset.config = cfg.id;
      }
      const k = $("w-live-l1").value;
      const state = window.LAMINA_SPHERES.variantState(l1.all, l1, k === "" ? -1 : Number(k));
      // The proposal's lobe follows the coat's roughness (lamina render's lobe_alpha_for).
      const alpha0 = k !== "" && l1.variants[Number(k)][0] === "alpha0" ? l1.variants[Number(k)][1] : Number(cfg.parameters.alpha0);
      if (Number.isFinite(alpha0)) scene.lobeAlpha = Math.min(Math.max(alpha0, 0.02), 1);
      Object.assign(scene, { model: "lamina-1", state });
    } else if (model === "lamina-coat") Object.assign(scene, { model: "lamina-coat", material: coatMaterial(cfg) });
    else Object.assign(scene, { model: "table", table: liveTable(d, model.slice(6)) });
    $("live-coat").hidden = model !== "lamina-coat";
    $("live-l1").hidden = model !== "lamina-1";
    note.textContent = model === "lamina-1" ? "lamina-1 in GLSL (lamina1.glsl) on the state the study computed: the stack's, or one parameter changed at a time."
      : model === "lamina-coat" ? "lamina-coat in GLSL, its parameters live."
      : model.slice(6) + ": the study's binned table, interpolated linearly over the bins and incidences (a highlight narrower than a bin is spread over it).";
    document.body.dataset.live = model;
    document.body.dataset.liveMaterial = model === "lamina-coat" ? JSON.stringify(scene.material) : "";
    // Another view's widget redraws the page: the live image restarts only when its scene changed.
    const key = JSON.stringify([cfg.id, model, env, model === "lamina-1" ? $("w-live-l1").value : "",
      model === "lamina-coat" ? scene.material : null]);
    if (key === live.key) return;
    live.key = key;
    live.pending = scene;
    ++live.frame;
    liveRun();
  }
  // Compiles and accumulates the pending scene, only while the canvas is on screen: on software
  // GL a pass costs tens of milliseconds, which the rest of the page should not wait for.
  function liveRun() {
    if (!live.visible || !live.renderer) return;
    if (live.pending) {
      try {
        live.renderer.setScene(live.pending);
      } catch (e) {
        $("live-note").textContent = "The shader failed: " + e.message;
        live.pending = null;
        return;
      }
      live.pending = null;
    }
    if (live.renderer.samples >= LIVE_SPP) return;
    const frame = live.frame;
    if (live.running === frame) return;
    live.running = frame;
    // One step at a time, each once the last has finished on the GPU; the passes per step
    // double while a step takes under 30 ms and halve above 60 ms.
    let passes = 1, submitted = 0;
    const tick = () => {
      if (frame !== live.frame || !live.visible) { live.running = -1; return; }
      if (live.renderer.busy()) { requestAnimationFrame(tick); return; }
      const now = performance.now();
      if (submitted) passes = now - submitted < 30 ? Math.min(2 * passes, 16) : now - submitted > 60 ? Math.max(passes >> 1, 1) : passes;
      live.renderer.step(Math.min(passes, LIVE_SPP - live.renderer.samples));
      submitted = performance.now();
      live.renderer.show(0);
      $("live-spp").textContent = live.renderer.samples + " spp";
      document.body.dataset.liveSpp = String(live.renderer.samples);
      if (live.renderer.samples < LIVE_SPP) requestAnimationFrame(tick); else live.running = -1;
    };
    tick();
  }
  new IntersectionObserver((entries) => {
    live.visible = entries.some((e) => e.isIntersecting);
    liveRun();
  }).observe($("live-canvas"));
  const L1_PARAMS = { alpha0: "coat α", eta0: "coat η", tau_a: "coat τa", alpha1: "base α", albedo: "base albedo" };
  let liveData = null;
  for (const id of ["w-live-l1", "w-live-model", "w-live-env", "w-live-alpha0", "w-live-eta", "w-live-tau", "w-live-alpha1", "w-live-colour"])
    $(id).addEventListener("input", () => liveData && drawLive(liveData.d, liveData.cfg, false));

  // ---- Rendering ---------------------------------------------------------------------------------------

  let renderSerial = 0;

  // What the views of other files draw with: the page's state and helpers.
  const VIEW_API = { state, models, nTheta, sliceAngles, slicePlane, isoLookup, ISO_N, diskLayout,
    incidenceIndex, incidenceText, incidencesOf, isUnfolded, isSupported, modelColor, PLOT_CONFIG };

  async function render() {
    const serial = ++renderSerial;
    const cfg = byId.get(state.config);
    status("loading " + cfg.id + " …");
    let d;
    try {
      d = await loadConfig(cfg.id);
    } catch (e) {
      if (serial !== renderSerial) return;
      // The views still hold the configuration shown before: hidden, with the reason in their place.
      status("");
      $("load-error").textContent = "Cannot show " + cfg.id + ": " + e.message;
      document.body.dataset.loadError = cfg.id;
      console.warn(e.message);
      return;
    }
    if (serial !== renderSerial) return;  // a later change superseded this one
    delete document.body.dataset.loadError;
    $("load-error").textContent = "";
    const t0 = performance.now(), times = {};
    const timed = (name, f) => { const t = performance.now(); f(); times[name] = Math.round(performance.now() - t); };
    timed("slice", () => drawSlice(d, cfg));
    timed("iso", () => drawIso(d, cfg));
    timed("albedo", () => drawAlbedo(cfg));
    timed("leaderboard", () => drawLeaderboard());
    timed("polarization", () => drawPolarization(d, cfg));
    drawRenders(cfg);
    const newConfig = !liveData || liveData.cfg !== cfg;
    liveData = { d, cfg };
    drawLive(d, cfg, newConfig);
    // Views kept in their own files (web/colour.js), registered in window.LAMINA_VIEWS.
    for (const v of window.LAMINA_VIEWS || []) timed(v.name, () => v.draw(VIEW_API, d, cfg));
    document.body.dataset.viewMs = JSON.stringify(times);
    writeHash();
    status("");
    document.body.dataset.config = cfg.id;
    document.body.dataset.renders = String(Number(document.body.dataset.renders || 0) + 1);
    document.body.dataset.drawMs = (performance.now() - t0).toFixed(0);
  }

  window.LAMINA_EXPLORER = { state, selectConfig, render, models, configs, groups, showGroup };

  if (!configs.length) { status("This study has no configurations."); return; }
  readHash();
  buildStaticWidgets();
  buildConfigWidgets();
  $("w-incidence").value = state.incidence;
  render();
})();
