"""Python models in the study: lamina's quadrature of a Python eval (lamina.plugins)."""

import csv
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import lamina

ROOT = Path(__file__).resolve().parents[2]
PLASTIC = ROOT / "examples" / "plastic.json"
BRUSHED = ROOT / "examples" / "brushed-aluminium-lacquer.json"
CLI = os.environ.get("LAMINA_CLI", str(ROOT / "build" / "lamina"))


class Lambert:
    """f = ρ/π: its cos-weighted bin averages are ρ/π exactly, whatever the quadrature."""
    name = "py-lambert"

    def __init__(self, stack):
        self.rho = np.array([0.5, 0.25, 0.125])

    def eval(self, wi, wo):
        return np.where(wo[:, 2:3] > 0, self.rho / np.pi, 0.0) * np.ones((len(wo), 3))


class WrappedWWPrime:
    """A built-in model called from Python: binned by the plugin rule it must agree with
    lamina's adaptive binning to the rules' accuracy."""
    name = "py-ww-prime"

    def __init__(self, stack):
        self.m = lamina.Model("ww-prime", stack)

    def eval(self, wi, wo):
        return self.m.eval(wi, wo)


def test_plugin_binning_of_a_constant_is_exact():
    t = lamina.bin_model(Lambert, PLASTIC, [0, 40], grid=(9, 8))
    assert t.sides == ["R"] and t.f.shape == (2, 1, 9, 8, 3)
    assert np.allclose(t.f[..., :], np.array([0.5, 0.25, 0.125]) / np.pi, rtol=1e-13)


def test_plugin_binning_agrees_with_the_adaptive_rule():
    grid = (30, 30)
    ref = lamina.Model("ww-prime", PLASTIC).binned([30], grid=grid)
    mine = lamina.bin_model(WrappedWWPrime, PLASTIC, [30], grid=grid)
    omega = ref.projected_solid_angle
    for c in range(3):
        a, b = ref.f[0, 0, :, :, c], mine.f[0, 0, :, :, c]
        misplaced = np.sum(np.abs(a - b) * omega) / np.sum(a * omega)
        # α = 0.2: the 4x4 Gauss rule per 3°x6° bin resolves the lobe to well below 1e-3.
        assert misplaced < 1e-3, (c, misplaced)


def test_delta_lobes_go_to_the_bin_they_hit():
    class Mirror:
        name = "mirror"

        def eval(self, wi, wo):
            return np.zeros((len(wo), 3))

        def delta_lobes(self, wi):
            return [((-wi[0], -wi[1], wi[2]), (0.04, 0.04, 0.04))]

    # θi = 35°: the mirror direction inside a bin, not on an edge (at 30° it lies on the edge of
    # bins 2 and 3, where the last bit of θo decides, differently on different CPUs).
    t = lamina.bin_model(Mirror, PLASTIC, [35], grid=(9, 6))
    omega = t.projected_solid_angle
    energy = np.einsum("tpc,tp->c", t.f[0, 0], omega)
    assert np.allclose(energy, 0.04, rtol=1e-12)
    assert t.f[0, 0, 3, 5, 0] > 0  # θo = 35° is in bin 3 of 9 (30–40°), φ = 180° in the last


def test_compare_with_a_python_model_puts_it_in_the_study(tmp_path):
    s = lamina.compare(PLASTIC, models=["ww-prime", Lambert, WrappedWWPrime], particles=40_000,
                       theta_i=[0, 45], grid=(18, 12), out=tmp_path / "cmp", tables="full")
    assert s.models == ["ww-prime", "py-lambert", "py-ww-prime"]
    m = s.metrics
    assert set(np.unique(m["model"])) == {"ww-prime", "py-lambert", "py-ww-prime"}
    me = {name: m[(m["model"] == name)]["misplaced_energy"] for name in s.models}
    # The wrapped model's metrics equal the built-in's to the quadratures' agreement.
    assert np.allclose(me["py-ww-prime"], me["ww-prime"], atol=2e-3)
    assert "py-lambert" in (tmp_path / "cmp" / "summary.md").read_text()
    t = s.tables("plastic")
    assert np.allclose(t["py-lambert"][..., 0], 0.5 / np.pi, rtol=1e-6)  # float32 tables
    assert (tmp_path / "cmp" / "index.html").is_file()


def test_cli_model_plugin(tmp_path):
    plugin = tmp_path / "lambert_plugin.py"
    plugin.write_text(
        "import numpy as np\n"
        "class MODEL:\n"
        "    def __init__(self, stack):\n"
        "        pass\n"
        "    def eval(self, wi, wo):\n"
        "        return np.full((len(wo), 3), 0.3 / np.pi)\n")
    r = subprocess.run([CLI, "compare", str(PLASTIC), "--particles", "20000", "--theta-i", "0,45",
                        "--grid", "9x6", "--models", "ww-prime", "--no-figures",
                        "--model-plugin", f"lam={plugin}", "--out", str(tmp_path / "o")],
                       capture_output=True, text=True)
    if r.returncode != 0 and "without the Python module" in r.stderr:
        pytest.skip("this lamina was built without the Python module")
    assert r.returncode == 0, r.stderr
    s = lamina.load_study(tmp_path / "o", pandas=False)
    assert s.models == ["ww-prime", "lam"]
    assert np.allclose(s.tables("plastic")["lam"], 0.3 / np.pi, rtol=1e-6)


def _processes_running(text):
    """PIDs of the processes whose command line holds `text` (from /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if text in (entry / "cmdline").read_bytes().decode(errors="replace"):
                    found.append(int(entry.name))
            except OSError:
                pass
    return found


def test_an_interrupted_study_ends_its_python_model_and_removes_its_folder(tmp_path):
    # SIGTERM to lamina while a Python model bins its table: the model's process is ended with it
    # and its temporary folder removed (they were left running and behind).
    import signal
    import time
    plugin = tmp_path / "sleepy_plugin.py"
    plugin.write_text("import time\nimport numpy as np\nclass M:\n"
                      "    def eval(self, wi, wo):\n        time.sleep(120)\n"
                      "        return np.zeros((len(wo), 3))\nMODEL = M\n")
    temp = tmp_path / "tmp"
    temp.mkdir()
    run = subprocess.Popen([CLI, "compare", str(PLASTIC), "--particles", "1000", "--theta-i", "30",
                            "--grid", "9x9", "--models", "ww09", "--model-plugin", str(plugin),
                            "--out", str(tmp_path / "o")],
                           env=dict(os.environ, TMPDIR=str(temp)), stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True)
    model = f"lamina.plugin_table\0{plugin}"  # the model's process (lamina's own names it too)
    for _ in range(600):
        if _processes_running(model) or run.poll() is not None:
            break
        time.sleep(0.05)
    if run.poll() is not None:
        err = run.stderr.read()
        if "without the Python module" in err:
            pytest.skip("this lamina was built without the Python module")
        raise AssertionError(err)
    assert list(temp.iterdir()), "no temporary folder while the model runs"
    time.sleep(0.5)  # lamina registers the process once its spawn has returned
    run.send_signal(signal.SIGTERM)
    assert run.wait(timeout=30) == -signal.SIGTERM
    for _ in range(100):  # the model's process ends on its SIGTERM
        if not _processes_running(model):
            break
        time.sleep(0.05)
    assert not _processes_running(model)
    assert not list(temp.iterdir())


def test_a_bad_python_model_is_refused_with_its_name():
    class Bad:
        name = "bad"

        def eval(self, wi, wo):
            return np.full((len(wo), 3), np.nan)

    with pytest.raises(lamina.InputError) as e:
        lamina.bin_model(Bad, PLASTIC, [0], grid=(3, 3))
    assert "bad" in str(e.value)


def test_study_with_only_a_python_model(tmp_path):
    s = lamina.study(models=[Lambert], only="plastic-P1-a0.05,slab-a0.1-a1.3-clear",
                     particles=20_000, theta_i=[0], grid=(9, 6), out=tmp_path / "st")
    assert s.models == ["py-lambert"]
    assert sorted(s.configs) == ["plastic-P1-a0.05", "slab-a0.1-a1.3-clear"]
    m = s.metrics
    assert set(np.unique(m["model"])) == {"py-lambert"}
    # Lambert supports the BRDF only: the slab's T rows are not supported.
    slab_t = m[(m["config"] == "slab-a0.1-a1.3-clear") & (m["side"] == "T")]
    assert len(slab_t) == 3 and not slab_t["supported"].any()


# ---- anisotropic Python models: the unfolded grid ------------------------------------------------

def _tangent_rad(stack):
    """The brushing direction of the stack's base (its last interface's tangent_deg)."""
    layers = stack.to_dict()["layers"]
    return np.radians(layers[-1]["interface"].get("tangent_deg", 0.0))


class BrushedLambert:
    """A reciprocal anisotropic toy with bin averages in closed form:
        f(wi, wo) = ρ/π · (1 + β cos 2(φo − ψ)) · (1 + β cos 2(φi − ψ)),
    ψ the base's tangent (read from the stack), φ the azimuths in the stack's frame. It depends on
    φo alone within a bin, so its cos-weighted average over [θ0, θ1] × [φ0, φ1] is
        ρ/π · (1 + β (sin 2(φ1 − ψ) − sin 2(φ0 − ψ)) / (2 (φ1 − φ0))) · (1 + β cos 2(φi − ψ)),
    whatever θ0, θ1 (the cos-weight integrates out)."""
    name = "py-brushed-lambert"
    rho = np.array([0.5, 0.25, 0.125])
    beta = 0.5

    def __init__(self, stack):
        self.psi = _tangent_rad(stack)

    def eval(self, wi, wo):
        g = lambda w: 1 + self.beta * np.cos(2 * (np.arctan2(w[:, 1], w[:, 0]) - self.psi))
        f = (self.rho / np.pi)[None, :] * (g(wo) * g(wi))[:, None]
        return np.where(wo[:, 2:3] > 0, f, 0.0)


def brushed_lambert_bins(psi, phi_i_deg, n_theta, n_phi_unfolded):
    """BrushedLambert's closed-form table [incidence, θ bin, φ bin, 3] on the unfolded grid."""
    beta, rho = BrushedLambert.beta, BrushedLambert.rho
    edges = np.linspace(0, 2 * np.pi, n_phi_unfolded + 1)
    p0, p1 = edges[:-1], edges[1:]
    g_o = 1 + beta * (np.sin(2 * (p1 - psi)) - np.sin(2 * (p0 - psi))) / (2 * (p1 - p0))
    g_i = 1 + beta * np.cos(2 * (np.radians(np.asarray(phi_i_deg, dtype=float)) - psi))
    out = g_i[:, None, None, None] * g_o[None, None, :, None] * (rho / np.pi)[None, None, None, :]
    return np.broadcast_to(out, (len(g_i), n_theta, n_phi_unfolded, 3))


def test_an_anisotropic_python_model_gets_the_full_azimuth():
    # Light from φi = 30° on the brushed example (tangent 30°): the unfolded grid, 2 × 12 φ bins.
    stack = lamina.Stack(BRUSHED)
    t = lamina.bin_model(BrushedLambert, stack, [0, 40, 70], grid=(9, 12), phi_i=[0, 30, 200])
    assert t.f.shape == (3, 1, 9, 24, 3)
    assert t.phi_edges[-1] == 360
    want = brushed_lambert_bins(_tangent_rad(stack), [0, 30, 200], 9, 24)
    # The 4 × 4 Gauss rule is exact in θ and integrates cos 2φ over a 15° bin to ~1e-12.
    assert np.allclose(t.f[:, 0], want, rtol=1e-10, atol=0)
    # Its albedo over the full azimuth is ρ (1 + β cos 2(φi − ψ)): ∫ cos 2φo dφo vanishes.
    albedo = np.einsum("itpc,tp->ic", t.f[:, 0], t.projected_solid_angle)
    g_i = 1 + 0.5 * np.cos(2 * (np.radians([0, 30, 200]) - _tangent_rad(stack)))
    assert np.allclose(albedo, g_i[:, None] * BrushedLambert.rho, rtol=1e-12)


def test_an_isotropic_stack_lit_off_phi_0_unfolds_and_one_phi_i_serves_every_incidence():
    t = lamina.bin_model(Lambert, PLASTIC, [0, 40], grid=(9, 8), phi_i=30)
    assert t.f.shape == (2, 1, 9, 16, 3)
    assert np.allclose(t.f, np.array([0.5, 0.25, 0.125]) / np.pi, rtol=1e-13)
    # Lit from φi = 0 it keeps the folded grid.
    assert lamina.bin_model(Lambert, PLASTIC, [0], grid=(9, 8), phi_i=0).f.shape == (1, 1, 9, 8, 3)


def test_a_delta_lobe_lands_at_its_azimuth_on_the_unfolded_grid():
    class Mirror:
        def eval(self, wi, wo):
            return np.zeros((len(wo), 3))

        def delta_lobes(self, wi):
            return [((-wi[0], -wi[1], wi[2]), (0.04, 0.04, 0.04))]

    # θi = 35° from φi = 100°: the mirror direction at θ = 35° (bin 3 of 9), φ = 280° (bin 18 of
    # 24, 270°–285°).
    t = lamina.bin_model(Mirror, PLASTIC, [35], grid=(9, 12), phi_i=100)
    energy = np.einsum("tpc,tp->c", t.f[0, 0], t.projected_solid_angle)
    assert np.allclose(energy, 0.04, rtol=1e-12)
    assert t.f[0, 0, 3, 18, 0] > 0 and np.count_nonzero(t.f[0, 0, ..., 0]) == 1


def test_phi_i_out_of_range_is_refused():
    for bad in (-1, 361, float("nan"), [0, 30, 60]):
        with pytest.raises(lamina.InputError) as e:
            lamina.bin_model(Lambert, PLASTIC, [0, 40], grid=(3, 3), phi_i=bad)
        assert e.value.field == "phi_i"


def test_incidences_and_grids_are_checked_before_the_model_is_asked():
    class Watched(Lambert):
        calls = 0

        def eval(self, wi, wo):
            Watched.calls += 1
            return super().eval(wi, wo)

    bad = [({"theta_i": [float("nan")]}, "theta_i"), ({"theta_i": [95]}, "theta_i"),
           ({"grid": (30000, 30000)}, "grid"), ({"grid": "abc"}, "grid"),
           ({"grid": (2.5, 3)}, "grid"), ({"grid": {"n_theta": 3}}, "grid")]
    for kwargs, field in bad:
        args = {"theta_i": [30], "grid": (3, 3), **kwargs}
        with pytest.raises(lamina.InputError) as e:
            lamina.bin_model(Watched, PLASTIC, **args)
        assert e.value.field == field, (kwargs, e.value)
    assert Watched.calls == 0
    # simulate's form of a grid serves too.
    t = lamina.bin_model(Lambert, PLASTIC, [30], grid={"n_theta": 3, "n_phi": 4})
    assert t.f.shape[-3:-1] == (3, 4)


def test_truth_values_and_bad_node_counts_are_refused(tmp_path):
    # True would be read as 1 degree or one node; a node count outside [1, MAX] would bin with
    # no node or allocate without bound (a study of built-in models only checks it too).
    for kw in ({"theta_i": [True]}, {"phi_i": True}, {"phi_i": np.bool_(False)}):
        args = {"theta_i": [0, 40], **kw}
        with pytest.raises(lamina.InputError) as e:
            lamina.bin_model(Lambert, PLASTIC, grid=(3, 3), **args)
        assert e.value.field == next(iter(kw)) and "expected" in e.value.problem
    for field, bad in (("nodes", 0), ("nodes", 2.5), ("nodes", True), ("nodes", 33),
                       ("peak_nodes", -1), ("peak_nodes", 257)):
        with pytest.raises(lamina.InputError) as e:
            lamina.bin_model(Lambert, PLASTIC, [0], grid=(3, 3), **{field: bad})
        assert e.value.field == field and "an integer in [1, " in e.value.problem
        with pytest.raises(lamina.InputError) as e:
            lamina.compare(PLASTIC, models=["ww09"], out=tmp_path / "c", particles=1e3,
                           **{field: bad})
        assert e.value.field == field
    assert not (tmp_path / "c").exists()
    t = lamina.bin_model(Lambert, PLASTIC, [0], grid=(3, 3), nodes=np.int64(2), peak_nodes=1)
    np.testing.assert_allclose(t.f[0, 0, :, :, 0], 0.5 / np.pi, rtol=1e-13)
    m = lamina.Model("ww09", PLASTIC)
    for bad in (True, np.bool_(False), "3"):
        with pytest.raises(lamina.InputError) as e:
            m.binned([30], (3, 3), phi_i=bad)
        assert e.value.field == "phi_i"
    with pytest.raises(lamina.InputError) as e:
        lamina.Table.from_arrays(np.zeros((1, 1, 3, 3, 3)), [True])
    assert e.value.field == "theta_i/0"


def test_a_python_model_returning_garbage_is_named():
    # What a model returns besides eval is checked: a NaN or missing direction, a lobe without an
    # RGB energy, a support answer that is neither a pair nor a dict (a traceback from lamina's
    # own code before).
    class Peaks(Lambert):
        def __init__(self, stack, peaks=None):
            super().__init__(stack)
            self.peaks = peaks

        def peak_directions(self, wi):
            return self.peaks

    class Lobes(Lambert):
        lobes = None

        def delta_lobes(self, wi):
            return self.lobes

    class Supports(Lambert):
        answer = None

        def supports(self, stack):
            return self.answer

    cases = [(Peaks(None, None), "peak_directions", "expected a list"),
             (Peaks(None, [[np.nan, 0, 1]]), "peak_directions", "three finite numbers"),
             (Peaks(None, [[0, 1]]), "peak_directions", "three finite numbers")]
    for lobes in (None, [([0, 0, 1], [1, 2])], [([0, 0, 1], "x")], [(1, 2, 3)]):
        m = Lobes(None)
        m.lobes = lobes
        cases.append((m, "delta_lobes", ""))
    for answer in (None, "yes", (True,)):
        m = Supports(None)
        m.answer = answer
        cases.append((m, "supports", "expected (brdf, btdf)"))
    for model, field, text in cases:
        with pytest.raises(lamina.InputError) as e:
            lamina.bin_model(model, PLASTIC, [30], grid=(3, 3))
        assert e.value.file == f"Python model '{lamina.model_name(model)}'", e.value
        assert e.value.field == field and text in e.value.problem, e.value


def test_a_plugin_that_exits_is_a_failure_not_an_unsupported_model(tmp_path):
    # The binned table or "unsupported" is written to the output file, so no exit status of the
    # plugin's own (sys.exit(3) once read as "supports neither side") passes for an answer.
    from lamina import plugin_table
    stack = tmp_path / "stack.json"
    stack.write_text(PLASTIC.read_text())
    args = ["--stack", str(stack), "--theta-i", "30", "--grid", "3x3"]
    exits = tmp_path / "exits.py"
    exits.write_text("import sys\nsys.exit(3)\n")
    assert plugin_table.main([str(exits), *args, "--out", str(tmp_path / "a.csv")]) == 1
    assert not (tmp_path / "a.csv").exists()
    none = tmp_path / "none.py"
    none.write_text("class M:\n    def supports(self, s): return (False, False)\n"
                    "    def eval(self, wi, wo): return wo * 0\nMODEL = M()\n")
    assert plugin_table.main([str(none), *args, "--out", str(tmp_path / "b.csv")]) == 0
    assert (tmp_path / "b.csv").read_text() == "unsupported\n"


class WrappedWB20:
    """lamina's wb20 (anisotropic) called from Python."""
    name = "py-wb20"

    def __init__(self, stack):
        self.m = lamina.Model("wb20", stack)

    def eval(self, wi, wo):
        return self.m.eval(wi, wo)


BRUSHED_CONFIG = "brushed-al-a0.2-a1.05x.3"  # a rough coat: no delta lobe


def test_study_brushed_category_with_python_models(tmp_path):
    s = lamina.study(models=["wb20", BrushedLambert, WrappedWB20], preset="standard",
                     only="brushed-gold-a0.001-a1.05x.3-t30," + BRUSHED_CONFIG,
                     particles=20_000, theta_i=[0, 40], grid=(9, 12), out=tmp_path / "st",
                     tables="full")
    assert s.models == ["wb20", "py-brushed-lambert", "py-wb20"]
    m = s.metrics
    for cid in ("brushed-gold-a0.001-a1.05x.3-t30", BRUSHED_CONFIG):
        cfg = s.config(cid)
        assert cfg["phi_i"] == [0, 0, 45, 90] and cfg["theta_i"] == [0, 40, 40, 40]
        rows = m[(m["config"] == cid) & (m["model"] == "py-brushed-lambert")]
        assert len(rows) == 4 * 3 and rows["supported"].all()
        assert sorted(set(rows["phi_i"])) == [0, 45, 90]
        # Bin by bin, the study's table is the closed form at each incidence (θi, φi).
        t = s.tables(cid)["py-brushed-lambert"]
        stack = lamina.Stack(cfg["stack"])
        want = brushed_lambert_bins(_tangent_rad(stack), cfg["phi_i"], 9, 24)
        assert t.shape == (4, 1, 9, 24, 3)
        assert np.allclose(t[:, 0], want, rtol=1e-6, atol=0)  # float32 tables
    # lamina's wb20 through Python agrees with the built-in wb20 binned by lamina's adaptive rule,
    # at every azimuth: the same incidences, bins and frame.
    t = s.tables(BRUSHED_CONFIG)
    # Ω⊥ of the unfolded bins (the brushed stack's: one patch each).
    omega = lamina.bin_model(Lambert, lamina.Stack(s.config(BRUSHED_CONFIG)["stack"]), [0],
                             grid=(9, 12)).projected_solid_angle
    assert omega.shape == (9, 24)
    for i in range(4):
        for c in range(3):
            a, b = t["wb20"][i, 0, :, :, c], t["py-wb20"][i, 0, :, :, c]
            misplaced = np.sum(np.abs(a - b) * omega) / np.sum(a * omega)
            # Measured 1e-7 to 8e-7 (float32 tables); both rules aim at 1e-4 of a bin.
            assert misplaced < 1e-4, (i, c, misplaced)


def test_cli_model_plugin_on_a_brushed_configuration(tmp_path):
    plugin = tmp_path / "brushed_plugin.py"
    plugin.write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
        "from test_plugins import BrushedLambert as MODEL\n")
    cid = "brushed-gold-a0.001-a1.05x.3-t30"
    r = subprocess.run([CLI, "study", "--preset", "standard", "--only", cid, "--models", "wb20",
                        "--particles", "20000", "--theta-i", "0,40", "--grid", "9x12",
                        "--tables", "full", "--no-figures", "--model-plugin", f"toy={plugin}",
                        "--out", str(tmp_path / "o")], capture_output=True, text=True)
    if r.returncode != 0 and "without the Python module" in r.stderr:
        pytest.skip("this lamina was built without the Python module")
    assert r.returncode == 0, r.stderr
    s = lamina.load_study(tmp_path / "o", pandas=False)
    assert s.models == ["wb20", "toy"]
    cfg = s.config(cid)
    want = brushed_lambert_bins(_tangent_rad(lamina.Stack(cfg["stack"])), cfg["phi_i"], 9, 24)
    assert np.allclose(s.tables(cid)["toy"][:, 0], want, rtol=1e-6, atol=0)
    toy = s.metrics[s.metrics["model"] == "toy"]
    assert len(toy) == 4 * 3 and toy["supported"].all()
