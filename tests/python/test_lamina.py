"""The Python module against the CLI and against independent computations (docs/python.md).

Run by ctest (`python`): PYTHONPATH=BUILD/python LAMINA_CLI=BUILD/lamina python3 -m pytest.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import lamina

ROOT = Path(__file__).resolve().parents[2]
PLASTIC = ROOT / "examples" / "plastic.json"
SLAB = ROOT / "examples" / "slab.json"
BRUSHED = ROOT / "examples" / "brushed-aluminium-lacquer.json"
CLI = os.environ.get("LAMINA_CLI", str(ROOT / "build" / "lamina"))


def cli(*args, check=True):
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"lamina {' '.join(map(str, args))} failed:\n{r.stderr}")
    return r


def read_brdf_csv(path):
    """brdf.csv → (f, se) [incidence, side, θ, φ, 3] by a reader independent of lamina's."""
    rows = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    thetas = list(dict.fromkeys(rows["theta_i"].tolist()))
    sides = list(dict.fromkeys(rows["side"].tolist()))
    n_theta = len(np.unique(rows["theta_lo"]))
    n_phi = len(np.unique(rows["phi_lo"]))
    shape = (len(thetas), len(sides), n_theta, n_phi)
    f = np.stack([rows[c] for c in ("f_r", "f_g", "f_b")], -1).reshape(*shape, 3)
    se = np.stack([rows[c] for c in ("se_r", "se_g", "se_b")], -1).reshape(*shape, 3)
    return f, se, thetas, sides


# ---- stacks and errors --------------------------------------------------------------------------

def test_stack_from_file_and_dict_are_equal():
    a = lamina.Stack(PLASTIC)
    b = lamina.Stack(json.loads(PLASTIC.read_text()))
    assert a.to_dict()["layers"] == b.to_dict()["layers"]
    assert lamina.Stack(a.to_dict()) == a
    assert not a.transmits and lamina.Stack(SLAB).transmits
    assert "dielectric" in a.describe()


def test_bad_stack_is_an_input_error_naming_the_field():
    bad = json.loads(PLASTIC.read_text())
    bad["layers"][0]["interface"]["alpha"] = 2.0
    with pytest.raises(lamina.InputError) as e:
        lamina.Stack(bad)
    assert isinstance(e.value, ValueError)
    assert e.value.file == "<dict>"
    assert "alpha" in e.value.field
    assert "[0, 1]" in e.value.problem or "1" in e.value.problem


def test_single_directions_are_checked():
    m = lamina.Model("ww-prime", PLASTIC)
    for bad in ([np.nan, 0, 1], [0, 0, 0], [0, 0, 2]):
        for method in (m.peak_directions, m.delta_lobes):
            with pytest.raises(lamina.InputError) as e:
                method(bad)
            assert e.value.field == "wi" and "finite unit vectors" in e.value.problem
    assert len(m.peak_directions([0, 0, 1])) >= 1


def test_non_finite_numbers_are_named():
    with pytest.raises(lamina.InputError) as e:
        lamina.simulate(PLASTIC, theta_i=[30, float("nan")], particles=1000)
    assert e.value.field == "theta_i/1" and "not a finite number" in e.value.problem
    bad = json.loads(PLASTIC.read_text())
    bad["layers"][0]["interface"]["eta"] = float("inf")
    with pytest.raises(lamina.InputError) as e:
        lamina.Stack(bad)
    assert e.value.file == "<dict>" and e.value.field == "/layers/0/interface/eta"


def test_cyclic_deep_and_huge_arguments_are_input_errors():
    # A container holding itself, or nested far deeper than a stack (five levels), is refused
    # before anything recurses through it (it crashed the interpreter); an integer beyond a
    # double's range is no finite number.
    cyclic = json.loads(PLASTIC.read_text())
    cyclic["self"] = cyclic
    deep = 0.5
    for _ in range(5000):
        deep = [deep]
    looped = [30.0]
    looped.append(looped)
    for call in (lambda: lamina.Stack(cyclic),
                 lambda: lamina.Stack({"layers": [{"interface": {"type": "lambertian",
                                                                 "albedo": deep}}]}),
                 lambda: lamina.simulate(PLASTIC, theta_i=looped, particles=1000)):
        with pytest.raises(lamina.InputError) as e:
            call()
        assert "nested more than 32 levels deep" in e.value.problem
    with pytest.raises(lamina.InputError) as e:
        lamina.Stack({"layers": [{"interface": {"type": "lambertian", "albedo": 10**400}}]})
    assert e.value.field == "/layers/0/interface/albedo"


def test_directions_at_the_horizon_give_finite_values():
    # Cosines of 1e-170: the models' products of cosines underflow there; such a direction is
    # taken on the horizon, where a BRDF is 0, not NaN.
    wi, wo = [1, 0, 1e-170], [-1, 0, 1e-170]
    for name in ("ww-prime", "lamina-1", "openpbr"):
        f = lamina.Model(name, PLASTIC).eval(wi, wo)
        assert np.all(np.isfinite(f)) and np.all(f == 0), name


def test_incidences_must_be_numbers():
    m = lamina.Model("ww-prime", PLASTIC)
    assert m.albedo(np.float64(45)).shape == (3,)
    for bad, field in (("30", "theta_i"), (["30"], "theta_i/0"), (None, "theta_i")):
        with pytest.raises(lamina.InputError) as e:
            m.albedo(bad)
        assert e.value.field == field and "expected a number of degrees" in e.value.problem


def test_one_model_may_be_named_without_a_list(tmp_path):
    # A string is one model's name (iterated, its letters were taken for models: "unknown model
    # 'w'").
    r = lamina.compare(PLASTIC, models="ww-prime", out=tmp_path / "c", particles=1000,
                       theta_i=[30], grid=(9, 9))
    assert r.models == ["ww-prime"]


def test_study_names_are_checked_before_any_work(tmp_path):
    # An id names a folder and a CSV cell: "../x" would write beside the study, "a,b" would break
    # metrics.csv after the whole study had run. Refused before anything is written.
    plastic = json.loads(PLASTIC.read_text())
    for config_id, field in (("../x", "configs[0].id"), ("a,b", "configs[0].id")):
        with pytest.raises(lamina.InputError) as e:
            lamina.compare(plastic, models=["ww-prime"], config_id=config_id,
                           out=tmp_path / "c", particles=1000, theta_i=[30], grid=(9, 9))
        assert e.value.field == field
        assert "is not usable as an id" in e.value.problem
    with pytest.raises(lamina.InputError) as e:
        lamina.study(configs=[{"id": "a", "stack": plastic}, {"id": "a", "stack": plastic}],
                     models=["ww-prime"], out=tmp_path / "s", particles=1000, theta_i=[30],
                     grid=(9, 9))
    assert e.value.field == "configs[1].id" and "appears twice" in e.value.problem
    assert not (tmp_path / "c").exists() and not (tmp_path / "s").exists()
    assert not (tmp_path / "x").exists()
    # A check the CLI shares names the Python argument, not the command-line option.
    with pytest.raises(lamina.InputError) as e:
        lamina.study(only="nope*", out=tmp_path / "o", particles=1000, theta_i=[30], grid=(9, 9))
    assert (e.value.file, e.value.field) == ("arguments", "only")
    assert "matches no configuration" in e.value.problem and "--only" not in str(e.value)
    # An empty `only` names nothing: it is not every configuration (a whole study by accident).
    for empty in ("", " , "):
        with pytest.raises(lamina.InputError) as e:
            lamina.study(only=empty, out=tmp_path / "o", particles=1000, theta_i=[30])
        assert e.value.field == "only" and "names no configuration" in e.value.problem
    assert not (tmp_path / "o").exists()


def test_incidences_are_given_once():
    # As on the command line: a table holds one block per incidence.
    m = lamina.Model("ww-prime", lamina.Stack(PLASTIC))
    for call in (lambda: m.binned(theta_i=[30, 30], grid=(9, 9)), lambda: m.albedo([0, 0])):
        with pytest.raises(lamina.InputError) as e:
            call()
        assert e.value.field == "theta_i" and "given twice" in e.value.problem


def test_missing_file_names_the_file(tmp_path):
    with pytest.raises(lamina.InputError) as e:
        lamina.Stack(tmp_path / "nope.json")
    assert "nope.json" in e.value.file


def test_bad_arguments_are_input_errors():
    with pytest.raises(lamina.InputError) as e:
        lamina.simulate(PLASTIC, theta_i=[95], particles=1000)
    assert e.value.field == "theta_i"
    with pytest.raises(lamina.InputError) as e:
        lamina.simulate(PLASTIC, theta_i=[0], particles=1000, grid=(0, 10))
    assert e.value.field == "grid"
    with pytest.raises(lamina.InputError) as e:
        lamina.simulate(PLASTIC, theta_i=[0], particles=1000, kernel="gpu")
    assert e.value.field == "kernel"


def test_a_thin_film_runs_on_the_scalar_kernel():
    # docs/physics.md §9: the scalar kernel traces films; the SIMD kernel refuses; the default
    # (auto) runs the scalar one.
    lens = ROOT / "examples" / "coated-lens.json"
    with pytest.raises(lamina.InputError) as e:
        lamina.simulate(lens, theta_i=[0], particles=1000, kernel="simd")
    assert (e.value.file, e.value.field) == ("arguments", "kernel")  # the argument, not --kernel
    r = lamina.simulate(lens, theta_i=[0], particles=20_000, threads=1)
    # MgF2 a quarter wave thick at 550 nm on glass: R = 1.37 %, 1.25 %, 1.49 % in the channels
    # (the Airy sums; standard error 8e-4) where bare glass reflects 4.26 %.
    reflected = np.asarray(r.energy["reflected"]).ravel()
    assert np.all((reflected > 0.010) & (reflected < 0.018)), reflected


def test_light_from_an_azimuth_unfolds_the_grid(tmp_path):
    # docs/physics.md §5: an anisotropic stack (or light from phi_i != 0) has no mirror symmetry
    # in phi, so its table covers phi in [0, 360) with twice the bins, each one patch; Python
    # gets the CLI's bits, its edges and solid angles, and the budget's reflected term is the
    # table's albedo on that grid.
    brushed = ROOT / "examples" / "brushed-aluminium-lacquer.json"
    cli("simulate", brushed, "--theta-i", "30", "--phi-i", "40", "--particles", 200_000,
        "--seed", 5, "--grid", "9x12", "--out", tmp_path / "cli")
    r = lamina.simulate(brushed, theta_i=[30], phi_i=40, particles=200_000, seed=5, grid=(9, 12),
                        threads=1)
    r.write(tmp_path / "py")
    for name in ("brdf.csv", "energy.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes()
    assert r.f.shape == (1, 1, 9, 24, 3)
    assert np.allclose(r.phi_edges, np.linspace(0, 360, 25))
    assert r.info["phi_i"] == 40 and r.info["grid"]["folded"] is False
    assert r.info["grid"]["n_phi_bins"] == 24 and r.info["grid"]["phi_range_deg"] == [0, 360]
    omega = r.table.projected_solid_angle
    assert omega.shape == (9, 24) and np.isclose(omega.sum(), np.pi)  # ∫ cos θ dω, one hemisphere
    albedo = np.einsum("itpc,tp->ic", r.f[:, 0], omega)
    assert np.allclose(albedo, r.energy["reflected"], rtol=8 * 2.0**-24, atol=1e-12)
    # The brushed highlight follows the light: the reflected flux peaks within a bin of the
    # mirror azimuth phi_i + 180 = 220 degrees.
    flux = np.einsum("tpc,tp->p", r.f[0, 0], omega)
    assert abs((np.argmax(flux) + 0.5) * 15 - 220) <= 15


def test_a_spectral_stack_gives_wavelength_tables(tmp_path):
    # docs/physics.md §10: a stack with a spectral value is traced spectrally (scalar kernel);
    # the arrays are those the CLI writes to spectral.npy, bit for bit in float32.
    gold = ROOT / "examples" / "gold-under-coat.json"
    r = lamina.simulate(gold, theta_i=[0, 45], particles=30_000, grid=(9, 6), threads=1)
    sp = r.spectral
    assert len(sp["bin_edges_nm"]) == 31 and sp["bin_edges_nm"][0] == 360
    assert sp["f"].shape == (2, 1, 9, 6, 30) and sp["xyz"].shape == (2, 1, 9, 6, 3)
    assert sp["energy"].shape == (2, 30, 8)
    # Gold reflects red more than blue: the albedo rises with the wavelength across the visible.
    albedo = sp["energy"][0, :, 0]
    assert albedo[-3:].mean() > albedo[:3].mean() + 0.3
    cli("simulate", gold, "--theta-i", "0,45", "--particles", 30_000, "--grid", "9x6",
        "--out", tmp_path / "cli")
    assert np.array_equal(np.load(tmp_path / "cli" / "spectral.npy")[:, :1],
                          sp["f"].astype(np.float32))
    assert lamina.simulate(PLASTIC, theta_i=[0], particles=1000).spectral is None


# ---- simulate: bitwise the CLI's ------------------------------------------------------------------

@pytest.mark.parametrize("stack", [PLASTIC, SLAB])
def test_simulate_is_bitwise_the_cli(tmp_path, stack):
    args = dict(theta_i=[0, 45, 80], particles=300_000, seed=7, grid=(18, 12))
    cli("simulate", stack, "--theta-i", "0,45,80", "--particles", args["particles"], "--seed", 7,
        "--grid", "18x12", "--threads", 2, "--out", tmp_path / "cli")
    r = lamina.simulate(stack, threads=1, **args)  # another thread count: same bits
    r.write(tmp_path / "py")
    for name in ("brdf.csv", "energy.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes()
    f, se, thetas, sides = read_brdf_csv(tmp_path / "cli" / "brdf.csv")
    assert np.array_equal(r.f, f) and np.array_equal(r.se, se)  # round-trip text: exact
    assert r.theta_i == thetas and r.sides == sides
    assert r.f.shape == (3, len(sides), 18, 12, 3)
    assert np.allclose(r.theta_edges, np.linspace(0, 90, 19))
    assert np.allclose(r.phi_edges, np.linspace(0, 180, 13))
    # The energy budget: the reflected term is the BRDF's albedo Σ f Ω⊥ (the same exits). The SIMD
    # kernel sums the exits' flux for the budget in float over at most 8 steps before double
    # (simulator/kernel_simd.cpp, kFlushSteps), each sum within 8 · 2^-24 of exact: with the
    # reference's arbitrary weights (polarized, multiple scattering) that bounds the difference.
    omega = r.table.projected_solid_angle
    albedo = np.einsum("itpc,tp->ic", r.f[:, 0], omega)
    assert np.allclose(albedo, r.energy["reflected"], rtol=8 * 2.0**-24, atol=1e-12)
    total = sum(r.energy[k] for k in ("reflected", "transmitted", "absorbed_medium",
                                      "absorbed_base", "lost_microsurface", "cut_off"))
    assert np.allclose(total, 1, atol=1e-9)
    assert r.info["seed"] == 7 and r.info["particles"] == args["particles"]


def test_simulate_multiple_scattering_is_the_clis(tmp_path):
    # The microsurface walk on the default (SIMD) kernel: the CLI's bits, nothing lost on the
    # microsurfaces of the slab.
    args = dict(theta_i=[0, 60], particles=100_000, seed=5, grid=(18, 12))
    cli("simulate", SLAB, "--theta-i", "0,60", "--particles", args["particles"], "--seed", 5,
        "--grid", "18x12", "--microsurface", "multiple", "--out", tmp_path / "cli")
    r = lamina.simulate(SLAB, microsurface="multiple", **args)
    r.write(tmp_path / "py")
    for name in ("brdf.csv", "energy.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes()
    assert np.all(r.energy["lost_microsurface"] == 0)


def test_physics_names_the_reference(tmp_path):
    # The exact reference is the default; physics="bpb19" is the 2019 study's, and a setting given
    # beside it wins, as on the command line.
    assert lamina.SIMULATION_SETTINGS["polarization"] is True
    assert lamina.SIMULATION_SETTINGS["microsurface"] == "multiple"
    assert lamina.REFERENCE_PHYSICS["bpb19"] == {"polarization": False, "microsurface": "single"}
    args = dict(theta_i=[30], particles=20_000, seed=3, grid=(9, 9))
    r = lamina.simulate(PLASTIC, physics="bpb19", **args)
    assert r.info["physics"] == "bpb19" and r.info["microsurface"] == "single"
    assert lamina.simulate(PLASTIC, **args).info["physics"] == "exact"
    mixed = lamina.simulate(PLASTIC, physics="bpb19", microsurface="multiple", **args)
    assert mixed.info["physics"] == "custom" and mixed.info["polarization"] is False
    with pytest.raises(lamina.InputError, match="physics"):
        lamina.simulate(PLASTIC, physics="bpb18", **args)


def test_simulate_transmission_masking_is_the_clis(tmp_path):
    # The slab's rough interfaces refract with single scattering (the 2019 reference, physics=
    # "bpb19"): smith and pbrt differ there, and each is the CLI's.
    args = dict(theta_i=[60], particles=100_000, seed=3, grid=(18, 12), physics="bpb19")
    tables = {}
    for masking in ("smith", "pbrt"):
        cli("simulate", SLAB, "--theta-i", "60", "--particles", args["particles"], "--seed", 3,
            "--grid", "18x12", "--transmission-masking", masking, "--physics", "bpb19",
            "--out", tmp_path / masking)
        r = lamina.simulate(SLAB, transmission_masking=masking, **args)
        r.write(tmp_path / ("py-" + masking))
        assert ((tmp_path / masking / "brdf.csv").read_bytes()
                == (tmp_path / ("py-" + masking) / "brdf.csv").read_bytes())
        tables[masking] = r.f
    assert not np.array_equal(tables["smith"], tables["pbrt"])
    with pytest.raises(lamina.InputError):
        lamina.simulate(SLAB, theta_i=[0], particles=1000, transmission_masking="walter")


def test_simulate_stops_on_ctrl_c():
    code = ("import lamina, sys\n"
            "print('start', flush=True)\n"
            "try:\n"
            f"    lamina.simulate({str(PLASTIC)!r}, theta_i=[0], particles=1e12, threads=1)\n"
            "except KeyboardInterrupt:\n"
            "    print('interrupted', flush=True); sys.exit(3)\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                         env=dict(os.environ))
    assert p.stdout.readline().strip() == "start"
    time.sleep(1.5)
    p.send_signal(signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        p.kill()
        raise AssertionError("simulate did not stop on SIGINT within 30 s")
    assert p.returncode == 3 and "interrupted" in out


# ---- models ---------------------------------------------------------------------------------------

def test_models_lists_the_registry():
    names = [m["name"] for m in lamina.models()]
    out = cli("models").stdout
    for n in names:
        assert n in out
    assert "ww-prime" in names


def test_model_eval_is_the_cli_point_evaluation():
    m = lamina.Model("ww-prime", PLASTIC)
    for ti, to, po in [(30, 45, 180), (0, 10, 0), (70, 80, 90)]:
        out = cli("eval", "--model", "ww-prime", "--stack", PLASTIC, "--theta-i", ti,
                  "--theta-o", to, "--phi-o", po).stdout.split()
        a, b, c = np.radians([ti, to, po])
        wi = np.array([np.sin(a), 0, np.cos(a)])
        wo = np.array([np.sin(b) * np.cos(c), np.sin(b) * np.sin(c), np.cos(b)])
        # numpy's sin/cos of the angles may differ from lamina's in the last bit of a direction.
        assert np.allclose(m.eval(wi, wo), [float(x) for x in out], rtol=1e-12, atol=0)


def test_model_eval_broadcasts_and_matches_single_evaluations():
    m = lamina.Model("ww-prime", PLASTIC)
    rng = np.random.default_rng(1)
    def dirs(n, lower=False):
        v = rng.normal(size=(n, 3))
        v[:, 2] = np.abs(v[:, 2]) * (-1 if lower else 1)
        return v / np.linalg.norm(v, axis=-1, keepdims=True)
    wi, wo = dirs(5)[:, None, :], dirs(4)[None, :, :]
    f = m.eval(wi, wo)
    assert f.shape == (5, 4, 3)
    for a in range(5):
        for b in range(4):
            assert np.array_equal(f[a, b], m.eval(wi[a, 0], wo[0, b]))
    assert np.all(np.isfinite(f)) and np.all(f >= 0)


def test_model_rejects_bad_directions_and_options():
    m = lamina.Model("ww-prime", PLASTIC)
    with pytest.raises(lamina.InputError):
        m.eval([0, 0, 2.0], [0, 0, 1.0])
    with pytest.raises(lamina.InputError):
        m.eval([0, 0, 1.0], [0, 1.0])
    with pytest.raises(lamina.InputError) as e:
        lamina.Model("ww-prime", PLASTIC, nosuchoption="on")
    assert "nosuchoption" in e.value.problem
    assert (e.value.file, e.value.field) == ("arguments", "nosuchoption")
    with pytest.raises(lamina.InputError) as e:
        lamina.Model("ww10", PLASTIC)
    assert (e.value.file, e.value.field) == ("arguments", "name")


def test_model_options_with_a_dash_are_keywords_with_an_underscore():
    # lamina-1's round-trip option: round_trip="series" is the CLI's lamina-1:round-trip=series.
    m = lamina.Model("lamina-1", PLASTIC, round_trip="series")
    assert m.options["round-trip"] == "series"
    assert lamina.Model("lamina-1", PLASTIC).options["round-trip"] == "lobe"
    with pytest.raises(lamina.InputError) as e:
        lamina.Model("lamina-1", PLASTIC, roundtrip="series")
    assert "round_trip" in e.value.problem  # the options listed as keywords
    with pytest.raises(lamina.InputError) as e:
        lamina.Model("lamina-1", PLASTIC, round_trip="sideways")
    assert e.value.file == "arguments" and "lobe, series" in e.value.problem


def test_model_without_sampler_says_so():
    m = lamina.Model("ww-prime", PLASTIC)
    if m.has_sampling:
        pytest.skip("ww-prime has a sampler now")
    with pytest.raises(AttributeError):
        m.sample([0, 0, 1.0], [0.5, 0.5, 0.5])


@pytest.mark.parametrize("name", ["lamina-1", "openpbr"])
def test_sample_weight_is_eval_cos_over_pdf(name):
    # Model.sample's contract (models/model.h): weight = eval·|cos θo|/pdf and pdf = Model.pdf at
    # the drawn direction; both checked here with lamina's own eval and pdf, sample by sample.
    m = lamina.Model(name, PLASTIC)
    assert m.has_sampling
    rng = np.random.default_rng(7)
    theta = np.radians(40.0)
    wi = np.array([np.sin(theta), 0.0, np.cos(theta)])
    u = rng.random((2000, 3))
    wo, weight, pdf, valid = m.sample(wi, u)
    assert valid.mean() > 0.5
    wo, weight, pdf = wo[valid], weight[valid], pdf[valid]
    assert np.all(np.isfinite(weight)) and np.all(weight >= 0) and np.all(pdf > 0)
    assert np.allclose(np.linalg.norm(wo, axis=-1), 1, atol=1e-9)
    f = m.eval(np.broadcast_to(wi, wo.shape), wo)
    assert np.allclose(weight, f * np.abs(wo[:, 2:3]) / pdf[:, None], rtol=1e-9, atol=1e-12)
    assert np.allclose(m.pdf(np.broadcast_to(wi, wo.shape), wo), pdf, rtol=1e-9)


def test_binned_is_the_cli_table(tmp_path):
    cli("eval", "--model", "ww-prime", "--stack", PLASTIC, "--binned", "--theta-i", "0,60",
        "--grid", "9x6", "--out", tmp_path / "t.csv")
    t = lamina.Model("ww-prime", PLASTIC).binned([0, 60], grid=(9, 6))
    assert t.to_csv() == (tmp_path / "t.csv").read_text()
    assert np.array_equal(lamina.Table.from_csv(tmp_path / "t.csv").f, t.f)


def test_binned_unfolds_for_an_anisotropic_stack_and_phi_i(tmp_path):
    # An anisotropic stack, or light from phi_i != 0, is binned on the simulator's unfolded grid
    # (phi over [0, 360): twice the phi bins), bitwise as `lamina eval --binned --phi-i`.
    brushed = ROOT / "examples" / "brushed-aluminium-lacquer.json"
    cli("eval", "--model", "openpbr", "--stack", brushed, "--binned", "--theta-i", "45",
        "--phi-i", "30", "--grid", "9x6", "--out", tmp_path / "t.csv")
    t = lamina.Model("openpbr", brushed).binned([45], grid=(9, 6), phi_i=30)
    assert t.to_csv() == (tmp_path / "t.csv").read_text()
    assert t.f.shape[-2:] == (12, 3)
    assert lamina.Model("ww-prime", PLASTIC).binned([45], grid=(9, 6), phi_i=90).f.shape[-2:] == (12, 3)
    with pytest.raises(lamina.InputError, match="phi_i"):
        lamina.Model("ww-prime", PLASTIC).binned([45], phi_i=-1)


def test_albedo_agrees_with_the_binned_table():
    # Two quadratures of the same integral: the adaptive one over the hemisphere and the sum of
    # bin averages times Ω⊥ (each good to ~1e-4 relative by construction, binned.h).
    m = lamina.Model("ww-prime", PLASTIC)
    t = m.binned([20], grid=(30, 30))
    from_bins = np.einsum("tpc,tp->c", t.f[0, 0], t.projected_solid_angle)
    assert np.allclose(m.albedo(20), from_bins, rtol=2e-3)
    assert m.albedo([20, 40]).shape == (2, 3)


def test_albedo_refuses_an_unsupported_side():
    # It returned zeros: a model that does not represent a thin film (or a side an opaque stack
    # lacks) evaluates to 0, and its quadrature was a silent 0 albedo.
    film = lamina.Model("ww-prime", ROOT / "examples" / "coated-lens.json")
    assert not film.support["brdf"]
    with pytest.raises(lamina.InputError, match="not supported: thin films"):
        film.albedo(30)
    with pytest.raises(lamina.InputError, match="BTDF"):
        lamina.Model("ww-prime", PLASTIC).albedo(30, "T")


# ---- study directories ----------------------------------------------------------------------------

def test_load_study_metrics_agree_with_the_tables(tmp_path):
    out = tmp_path / "cmp"
    cli("compare", PLASTIC, "--particles", 40_000, "--theta-i", "0,45", "--grid", "18x12",
        "--models", "ww-prime,ele10", "--tables", "full", "--no-figures", "--out", out)
    s = lamina.load_study(out, pandas=False)
    assert s.configs == ["plastic"] and s.models == ["ww-prime", "ele10"]
    m = s.metrics
    assert len(m) == 2 * 2 * 1 * 3 and m.dtype.names[0] == "config"
    tables = s.tables("plastic")
    assert list(tables) == ["reference", "ww-prime", "ele10"]
    omega = np.array(lamina.Model("ww-prime", PLASTIC).binned([0], grid=(18, 12))
                     .projected_solid_angle)
    # misplaced energy recomputed here from the float32 tables (docs/formats.md's definition).
    for row in m[m["supported"]]:
        i = s.theta_i.index(row["theta_i"])
        c = "rgb".index(row["channel"])
        ref = tables["reference"][i, 0, :, :, c].astype(np.float64)
        mod = tables[row["model"]][i, 0, :, :, c].astype(np.float64)
        me = np.sum(np.abs(mod - ref) * omega) / np.sum(ref * omega)
        assert me == pytest.approx(row["misplaced_energy"], rel=1e-4)
    assert s.reference_se("plastic").shape == (2, 1, 18, 12, 3)
    with pytest.raises(lamina.InputError):
        s.tables("nope")
    # A damaged study directory: each file named in one InputError, never a bare decoder error.
    import shutil
    for name, text in (("study.json", '{"configurations": ['), ("study.json", "[1, 2]"),
                       ("study.json", '{"configurations": [{"name": "x"}]}'),
                       ("metrics.csv", "config,model\nplastic"), ("metrics.csv", None),
                       ("configs/plastic/config.json", '{"sources"')):
        damaged = tmp_path / "damaged"
        shutil.rmtree(damaged, ignore_errors=True)
        shutil.copytree(out, damaged)
        if text is None:
            (damaged / name).unlink()
        else:
            (damaged / name).write_text(text)
        with pytest.raises(lamina.InputError, match=name.split("/")[-1]):
            lamina.load_study(damaged, pandas=False).config("plastic")


def test_reference_stokes_of_a_polarized_study(tmp_path):
    # The polarized reference's Stokes components (docs/formats.md): S0 is the reference's f, and
    # every bin's degree of polarization √(S1² + S2² + S3²)/f is at most 1 (a sum of states of
    # degree ≤ 1; float16 rounding aside). A study without --reference-stokes on has none.
    out = tmp_path / "pol"
    cli("compare", PLASTIC, "--particles", 20_000, "--theta-i", "0,60", "--grid", "18x12",
        "--models", "ww-prime", "--tables", "full", "--reference-stokes", "on", "--no-figures",
        "--out", out)
    s = lamina.load_study(out, pandas=False)
    st = s.reference_stokes("plastic")
    assert st.shape == (2, 2, 1, 3, 18, 12, 3)
    f = s.tables("plastic")["reference"].astype(np.float64)
    norm = np.sqrt((st[0].astype(np.float64) ** 2).sum(axis=2))
    lit = f > 0
    assert np.all(norm[lit] <= f[lit] * (1 + 1e-5))
    assert np.max(norm[lit] / f[lit]) > 0.1   # the coat polarizes what it reflects
    assert np.all(st[1] >= 0)
    assert s.config("plastic")["stokes"]["file"] == "reference_stokes.lza"
    plain = tmp_path / "plain"
    cli("compare", PLASTIC, "--particles", 2_000, "--theta-i", "0", "--grid", "18x12",
        "--models", "ww-prime", "--no-figures", "--out", plain)
    with pytest.raises(lamina.InputError, match="--reference-stokes on"):
        lamina.load_study(plain, pandas=False).reference_stokes("plastic")


# ---- exports read from numpy ------------------------------------------------------------------

def test_export_npz_of_a_simulation(tmp_path):
    cli("simulate", SLAB, "--theta-i", "0,45", "--particles", 50_000, "--grid", "18x12",
        "--out", tmp_path / "sim")
    cli("export", "--simulation", tmp_path / "sim", "--out", tmp_path / "slab.npz")
    z = np.load(tmp_path / "slab.npz")
    meta = json.loads(z["metadata.json"])
    f, se, thetas, sides = read_brdf_csv(tmp_path / "sim" / "brdf.csv")
    assert meta["sides"] == sides == ["R", "T"] and meta["theta_i"] == thetas
    assert np.array_equal(z["f"], f.astype(np.float32))
    assert np.array_equal(z["se"], se.astype(np.float32))
    assert np.allclose(z["theta_edges"], np.linspace(0, 90, 19))
    assert meta["result"]["particles"] == 50_000


def test_export_npz_of_unfolded_tables(tmp_path):
    # Light from φi = 30° unfolds the grid (φ over [0°, 360°), twice the bins): the .npz holds
    # the table as brdf.csv has it, with the φ edges of the unfolded grid.
    cli("simulate", PLASTIC, "--theta-i", "40", "--phi-i", 30, "--particles", 20_000,
        "--grid", "9x9", "--out", tmp_path / "sim")
    cli("export", "--simulation", tmp_path / "sim", "--out", tmp_path / "sim.npz")
    z = np.load(tmp_path / "sim.npz")
    meta = json.loads(z["metadata.json"])
    f, se, thetas, sides = read_brdf_csv(tmp_path / "sim" / "brdf.csv")
    assert z["f"].shape == (1, 1, 9, 18, 3) and meta["grid"]["unfolded"]
    assert np.array_equal(z["f"], f.astype(np.float32))
    assert np.allclose(z["phi_edges"], np.linspace(0, 360, 19))
    # An anisotropic stack's model on the unfolded grid at φi = 60°: the bins `lamina eval
    # --binned --phi-i` writes.
    cli("export", "--model", "openpbr", "--stack", BRUSHED, "--theta-i", "20,70", "--phi-i", 60,
        "--grid", "9x6", "--out", tmp_path / "m.npz")
    cli("eval", "--model", "openpbr", "--stack", BRUSHED, "--binned", "--theta-i", "20,70",
        "--phi-i", 60, "--grid", "9x6", "--out", tmp_path / "m.csv")
    z = np.load(tmp_path / "m.npz")
    f, _, thetas, _ = read_brdf_csv(tmp_path / "m.csv")
    meta = json.loads(z["metadata.json"])
    assert meta["phi_i"] == 60 and meta["grid"]["n_phi"] == 12 and thetas == [20, 70]
    assert np.array_equal(z["f"], f.astype(np.float32))
    # A MERL file cannot hold an anisotropic BRDF.
    r = cli("export", "--model", "openpbr", "--stack", BRUSHED, "--out", tmp_path / "m.binary",
            check=False)
    assert r.returncode == 1 and "isotropic" in r.stderr
    assert not (tmp_path / "m.binary").exists()
    with pytest.raises(lamina.InputError, match="isotropic"):
        lamina.export(lamina.Model("openpbr", BRUSHED), tmp_path / "m.binary")
    assert not (tmp_path / "m.binary").exists()


def test_export_bsdf_and_merl_files(tmp_path):
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--resolution", 8,
        "--out", tmp_path / "ww.bsdf")
    data = (tmp_path / "ww.bsdf").read_bytes()
    assert data[:12] == b"tensor_file\0" and data[12:14] == b"\x01\x00"
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--out", tmp_path / "ww.binary")
    raw = (tmp_path / "ww.binary").read_bytes()
    dims = np.frombuffer(raw[:12], dtype="<i4")
    assert dims.tolist() == [90, 90, 180] and len(raw) == 12 + 3 * 90 * 90 * 180 * 8
    # The MERL value at normal incidence and exit (θh = θd = 0) is f there over the red scale.
    red = np.frombuffer(raw[12:12 + 90 * 90 * 180 * 8], dtype="<f8")
    f0 = lamina.Model("ww-prime", PLASTIC).eval([0, 0, 1.0], [0, 0, 1.0])[0]
    # Bin (0, 0, 0)'s centre is θh ≈ 0.003°, θd = 0.5°: within 1e-3 of the normal value.
    assert red[0] / 1500 == pytest.approx(f0, rel=1e-3)
    r = cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--out", tmp_path / "x.txt",
            check=False)
    assert r.returncode == 1 and "--format" in r.stderr


def test_export_check_refuses_truncated_files(tmp_path):
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--resolution", 8,
        "--out", tmp_path / "ww.bsdf")
    assert "RGL .bsdf" in cli("export", "--check", tmp_path / "ww.bsdf").stdout
    data = (tmp_path / "ww.bsdf").read_bytes()
    (tmp_path / "cut.bsdf").write_bytes(data[: len(data) // 2])
    r = cli("export", "--check", tmp_path / "cut.bsdf", check=False)
    assert r.returncode == 1 and "cut.bsdf" in r.stderr and "truncated" in r.stderr
    (tmp_path / "junk.bsdf").write_bytes(b"not a tensor file at all")
    r = cli("export", "--check", tmp_path / "junk.bsdf", check=False)
    assert r.returncode == 1 and "not a tensor file" in r.stderr
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--out", tmp_path / "ww.binary")
    assert "MERL" in cli("export", "--check", tmp_path / "ww.binary").stdout
    raw = (tmp_path / "ww.binary").read_bytes()
    (tmp_path / "cut.binary").write_bytes(raw[:-16])
    r = cli("export", "--check", tmp_path / "cut.binary", check=False)
    assert r.returncode == 1 and "truncated" in r.stderr


def test_export_check_reports_how_close_a_renderer_gets(tmp_path):
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--out", tmp_path / "ww.bsdf")
    r = cli("export", "--check", tmp_path / "ww.bsdf", "--model", "ww-prime", "--stack", PLASTIC,
            "--strict")
    assert "directional albedo" in r.stdout and "85.0" in r.stdout
    assert "random direction pairs" in r.stdout and "meets the goals" in r.stdout
    # Eight sample nodes a side at 20° steps: far from the goals, which --strict turns into exit 2.
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--resolution", 8,
        "--theta-i", "0,20,40,60,80", "--out", tmp_path / "coarse.bsdf")
    r = cli("export", "--check", tmp_path / "coarse.bsdf", "--model", "ww-prime", "--stack",
            PLASTIC, "--strict", check=False)
    assert r.returncode == 2 and "misses the goals" in r.stdout and "over the goal" in r.stdout
    r = cli("export", "--check", tmp_path / "coarse.bsdf", "--model", "ww-prime", "--stack",
            PLASTIC)
    assert "misses the goals" in r.stdout
    r = cli("export", "--check", tmp_path / "ww.bsdf", "--strict", check=False)
    assert r.returncode == 1 and "--strict" in r.stderr


def test_export_from_python_takes_the_cli_defaults(tmp_path):
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--out", tmp_path / "cli.bsdf")
    lamina.export(lamina.Model("ww-prime", PLASTIC), tmp_path / "py.bsdf")
    describe = [cli("export", "--check", tmp_path / name).stdout for name in ("cli.bsdf", "py.bsdf")]
    # "NAME: RGL .bsdf (SIZE MB), N incidences, N × N samples, N wavelengths: DESCRIPTION"
    shapes = [d.split(", ", 1)[1].split(": ")[0] for d in describe]
    assert shapes[0] == shapes[1] and "incidences" in shapes[0]


def test_export_from_python_takes_one_angle_zero_included(tmp_path):
    # theta_i=0 is the incidence 0°, not "the default"; one number is a list of one.
    lamina.export(lamina.Model("ww-prime", PLASTIC), tmp_path / "zero.bsdf", theta_i=0,
                  resolution=8)
    lamina.export(lamina.Model("ww-prime", PLASTIC), tmp_path / "one.bsdf", theta_i=[30],
                  resolution=8)
    for name in ("zero.bsdf", "one.bsdf"):
        assert "1 incidences" in cli("export", "--check", tmp_path / name).stdout


def test_export_from_python_takes_the_azimuths_of_an_anisotropic_stack(tmp_path):
    # The φi slices of a brushed stack's file: the CLI's --azimuths. The files differ only in
    # their description text; 4 and 8 intervals give 5 and 9 slices, and each slice holds per
    # incidence vndf [2, 512], luminance [8, 8] and spectra [7, 8, 8], and its phi_i entry, in
    # float32 (docs/formats.md).
    common = dict(theta_i=[0, 40], resolution=8)
    cli("export", "--model", "openpbr", "--stack", BRUSHED, "--azimuths", 4, "--theta-i", "0,40",
        "--resolution", 8, "--out", tmp_path / "cli.bsdf")
    for n in (4, 8):
        lamina.export(lamina.Model("openpbr", BRUSHED), tmp_path / f"py{n}.bsdf", azimuths=n,
                      **common)
    size = {name: (tmp_path / name).stat().st_size for name in ("cli.bsdf", "py4.bsdf", "py8.bsdf")}
    assert abs(size["cli.bsdf"] - size["py4.bsdf"]) < 1000, size
    per_slice = (2 * (2 * 512 + 8 * 8 + 7 * 8 * 8) + 1) * 4
    assert size["py8.bsdf"] - size["py4.bsdf"] == 4 * per_slice, size


def test_export_from_python_is_the_cli_file(tmp_path):
    cli("export", "--model", "ww-prime", "--stack", PLASTIC, "--out", tmp_path / "cli.binary")
    lamina.export(lamina.Model("ww-prime", PLASTIC), tmp_path / "py.binary")
    assert (tmp_path / "cli.binary").read_bytes() == (tmp_path / "py.binary").read_bytes()
    r = lamina.simulate(PLASTIC, theta_i=[0, 40], particles=20_000, grid=(18, 12))
    lamina.export(r, tmp_path / "ref.bsdf", resolution=8)
    assert "2 incidences" in cli("export", "--check", tmp_path / "ref.bsdf").stdout
    with pytest.raises(lamina.InputError):
        lamina.export(r, tmp_path / "ref.txt")


def test_table_from_arrays_round_trips():
    t = lamina.Model("ww-prime", PLASTIC).binned([0, 60], grid=(9, 6))
    u = lamina.Table.from_arrays(t.f, t.theta_i, t.sides)
    assert u.to_csv() == t.to_csv()
    with pytest.raises(lamina.InputError):
        lamina.Table.from_arrays(t.f[:, :, :, :, :2], t.theta_i, t.sides)
    bad = t.f.copy()
    bad[0, 0, 0, 0, 0] = np.nan
    with pytest.raises(lamina.InputError):
        lamina.Table.from_arrays(bad, t.theta_i, t.sides)
    # The checks of a table read from its CSV: |f| <= 1e12, each θi once in [0, 90), one side once.
    bad[0, 0, 0, 0, 0] = 1e300
    with pytest.raises(lamina.InputError) as e:
        lamina.Table.from_arrays(bad, t.theta_i, t.sides)
    assert e.value.field == "f"
    with pytest.raises(lamina.InputError) as e:
        lamina.Table.from_arrays(t.f, [30, 30], t.sides)
    assert e.value.field == "theta_i" and "twice" in e.value.problem
    with pytest.raises(lamina.InputError) as e:
        lamina.Table.from_arrays(t.f, [0, 95], t.sides)
    assert e.value.field == "theta_i"
    with pytest.raises(lamina.InputError) as e:
        lamina.Table.from_arrays(np.concatenate([t.f, t.f], axis=1), t.theta_i, ["R", "R"])
    assert e.value.field == "sides"
    assert "sides T," in repr(lamina.Table.from_arrays(t.f[:, :1], t.theta_i, ["T"]))


def test_random_walk_microsurface_option():
    """microsurface="multiple" is the CLI's --option microsurface=multiple (the same estimate
    within its standard error) and adds the energy the single-scattering microsurface loses."""
    gold = ROOT / "examples" / "frosted-gold.json"
    ti, to, po = np.radians(30.0), np.radians(45.0), np.radians(180.0)
    wi = [np.sin(ti), 0.0, np.cos(ti)]
    wo = [np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)]
    args = ("eval", "--model", "random-walk", "--stack", gold, "--theta-i", 30, "--theta-o", 45,
            "--phi-o", 180, "--samples", 16384, "--seed", 3)
    values = {}
    for ms in ("single", "multiple"):
        m = lamina.Model("random-walk", gold, microsurface=ms, samples=16384, seed=3)
        assert m.options["microsurface"] == ms
        got = np.asarray(m.eval(wi, wo))
        out = cli(*args, "--option", f"microsurface={ms}").stdout.split()
        want, se = np.array(out[:3], float), np.array(out[3:6], float)
        assert np.all(np.abs(got - want) < 5 * np.sqrt(2) * se + 1e-12), (ms, got, want, se)
        values[ms] = (want, se)
    (f1, s1), (f2, s2) = values["single"], values["multiple"]
    # Red, where gold reflects most and the walk's higher orders add most.
    assert f2[0] - f1[0] > 4 * np.hypot(s1[0], s2[0]), (f1, f2)
    with pytest.raises(lamina.InputError):
        lamina.Model("random-walk", gold, microsurface="many")
    # Not tabulated: the bins' adaptive quadrature would read its noise as quadrature error.
    rw = lamina.Model("random-walk", gold)
    for call in (lambda: rw.binned(theta_i=[30], grid=(1, 1)), lambda: rw.albedo(30)):
        with pytest.raises(lamina.InputError) as e:
            call()
        assert e.value.field == "name" and "stochastic estimator" in e.value.problem
    with pytest.raises(lamina.InputError) as e:
        lamina.export(rw, "/tmp/never.bsdf")
    assert e.value.field == "source" and "stochastic estimator" in e.value.problem


def run_module(*args):
    """`python3 -m lamina ARGS` in a child interpreter that imports the package under test."""
    return subprocess.run([sys.executable, "-m", "lamina", *map(str, args)], capture_output=True,
                          text=True, env=dict(os.environ))


def test_python_m_lamina_runs_the_cli():
    """`python3 -m lamina` is the command line: the same output and exit codes as the executable."""
    version = run_module("--version")
    assert version.returncode == 0 and version.stdout == cli("--version").stdout
    validate = run_module("validate", PLASTIC)
    assert validate.returncode == 0 and validate.stdout == cli("validate", PLASTIC).stdout
    models = run_module("models")
    assert models.returncode == 0 and models.stdout == cli("models").stdout
    bad = run_module("simulate", ROOT / "no-such-stack.json", "--out", "unused")
    assert bad.returncode == 1 and bad.stderr.startswith("lamina: "), bad.stderr
    assert bad.stderr == cli("simulate", ROOT / "no-such-stack.json", "--out", "unused",
                             check=False).stderr
    assert "python3 -m lamina" in run_module("--help").stdout


def test_omp_num_threads_past_the_cap_runs_capped():
    # OMP_NUM_THREADS=100000 crashed OpenMP's runtime (a segmentation fault); the module caps
    # OpenMP's default at lamina's 1024 threads when it loads, and the tables are any thread
    # count's.
    code = ("import sys, lamina; r = lamina.simulate(sys.argv[1], theta_i=[30], particles=1000, "
            "grid=(9, 9)); print(r.f.tobytes().hex())")
    runs = []
    for threads in ("100000", "1"):
        env = dict(os.environ, OMP_NUM_THREADS=threads)
        r = subprocess.run([sys.executable, "-c", code, str(PLASTIC)], env=env,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert ("running at most 1024" in r.stderr) == (threads == "100000"), r.stderr
        runs.append(r.stdout)
    assert runs[0] == runs[1]


def test_a_bad_grid_and_a_bad_folder_are_named_as_python_gave_them(tmp_path):
    # A count past a 64-bit integer was shown wrapped around (-9223372036854775808).
    with pytest.raises(lamina.InputError) as e:
        lamina.simulate(PLASTIC, theta_i=[30], particles=100, grid=(2**63, 1))
    assert "'9223372036854775808x1' is not a grid" in e.value.problem
    # write()'s folder is its argument dir, not the CLI's --out.
    r = lamina.simulate(PLASTIC, theta_i=[30], particles=100, grid=(9, 9))
    (tmp_path / "a-file").write_text("not a folder")
    with pytest.raises(lamina.InputError) as e:
        r.write(tmp_path / "a-file" / "out")
    assert e.value.field == "dir" and "cannot create the output folder" in e.value.problem


def test_a_damaged_study_folder_is_named_with_file_and_field(tmp_path):
    # Every error of a study read from disk carries .file, .field and .problem, as the CLI's do
    # (some were built positionally: a tuple for a message and no attributes).
    with pytest.raises(lamina.InputError) as e:
        lamina.load_study(tmp_path / "nowhere")
    assert e.value.field == "study.json" and "not a study directory" in e.value.problem
    r = lamina.compare(PLASTIC, models="ww-prime", out=tmp_path / "c", particles=1000,
                       theta_i=[30], grid=(9, 9))
    with pytest.raises(lamina.InputError) as e:
        r.config("nope")
    assert e.value.field == "configurations" and "no configuration 'nope'" in e.value.problem
    # config.json naming fewer sources than tables.lza holds: refused, not silently cut.
    cfg_path = tmp_path / "c" / "configs" / "plastic" / "config.json"
    cfg = json.loads(cfg_path.read_text())
    assert len(r.tables("plastic")) == len(cfg["sources"])
    cfg_path.write_text(json.dumps(dict(cfg, sources=cfg["sources"][:1])))
    with pytest.raises(lamina.InputError) as e:
        r.tables("plastic")
    assert e.value.field == "sources"
    # A damaged packed array: one InputError naming the file, whatever the damage.
    lza = tmp_path / "c" / "configs" / "plastic" / "tables.lza"
    data = lza.read_bytes()
    for damaged in (data[: len(data) // 2], data.replace(b'"shape"', b'"shap"'),
                    data[:15] + b"[" + data[16:]):  # the header's JSON broken
        lza.write_bytes(damaged)
        with pytest.raises(lamina.InputError) as e:
            lamina.read_array(lza)
        assert e.value.file == str(lza)


def test_compare_without_tables_writes_no_page(tmp_path):
    # tables="none" keeps no tables for the explorer page to draw: the study is written without it,
    # as `lamina compare --tables none` does (it failed at the page).
    r = lamina.compare(PLASTIC, models="ww-prime", out=tmp_path / "c", particles=1000,
                       theta_i=[30], grid=(9, 9), tables="none")
    assert r.configs == ["plastic"]
    assert not (tmp_path / "c" / "index.html").exists()


def test_a_message_quoting_bytes_that_are_not_utf8_is_an_input_error(tmp_path):
    # A stack file in Latin-1: the parser's message quotes the byte; it reached Python as a
    # UnicodeDecodeError instead of the InputError naming the file.
    path = tmp_path / "latin1.json"
    path.write_bytes(PLASTIC.read_text().replace('"plastic"', '"pl\xe9stic"').encode("latin-1"))
    with pytest.raises(lamina.InputError) as e:
        lamina.Stack(path)
    assert e.value.file == str(path) and "\\xe9" in e.value.problem


def test_zero_incidences_are_refused_as_a_csv_is(tmp_path):
    with pytest.raises(lamina.InputError) as e:
        lamina.Table.from_arrays(np.zeros((0, 1, 3, 3, 3)), [], ["R"])
    assert e.value.field == "theta_i"


def test_a_failed_write_moves_no_file(tmp_path):
    # A folder where result.json goes failed the last rename, after brdf.csv and energy.csv had
    # moved into place: now nothing moves.
    r = lamina.simulate(PLASTIC, theta_i=[0], particles=500, threads=1, grid=(3, 3))
    (tmp_path / "out" / "result.json").mkdir(parents=True)
    with pytest.raises(lamina.InputError) as e:
        r.write(tmp_path / "out")
    assert "a folder of that name is there" in e.value.problem
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["result.json"]


def test_one_incidence_is_one_value_whatever_its_type():
    # A numpy scalar or a 0-d array is one incidence (one RGB albedo), as a Python float; it was a
    # [1, 3] array for float32 and int64 and an error for a 0-d array. A truth value is no angle.
    m = lamina.Model("lamina-1", PLASTIC)
    want = m.albedo(30.0)
    for one in (np.float64(30), np.float32(30), np.int64(30), np.array(30.0), 30):
        got = m.albedo(one)
        assert got.shape == (3,)
        np.testing.assert_array_equal(got, want)
    assert m.albedo([30]).shape == (1, 3)
    for truth in (True, np.bool_(False), [True]):
        with pytest.raises(lamina.InputError) as e:
            m.albedo(truth)
        assert e.value.field.startswith("theta_i") and "expected a number" in e.value.problem


def test_cli_without_a_program_name_runs():
    """The command line's argv[0] is the program's name: an empty argv is the bare program (its
    usage, exit 0 or 1), never a read past the list."""
    assert lamina._lamina.cli([]) in (0, 1)


@pytest.mark.parametrize("cls, call", [("Model", "o.eval([0, 0, 1], [0, 0, 1])"),
                                       ("Stack", "o.__eq__(o)"), ("Table", "o.to_csv()"),
                                       ("SimulationResult", "repr(o)")])
def test_an_object_made_without_init_is_refused_not_used(cls, call):
    # Cls.__new__ without __init__ gives an object with no C++ value behind it: every method and
    # property must raise TypeError, never crash the interpreter or read uninitialized memory.
    # Run in a child interpreter, so that a crash fails this test and not the whole session.
    code = f"""
import lamina
c = lamina.{cls}
o = c.__new__(c)
names = [n for n in dir(o) if not n.startswith("_")] + ["__repr__"]
assert len(names) > 2, names
for name in names:
    try:
        a = getattr(o, name)
        if callable(a):
            a()
        raise SystemExit(f"{{name}}: no error")
    except TypeError as e:
        # Methods that take arguments are refused for their missing arguments before self is
        # read; the call with arguments below reaches self.
        if "without its __init__" in str(e) or "incompatible function arguments" in str(e):
            continue
        raise
try:
    {call}
    raise SystemExit("{call}: no error")
except TypeError as e:
    assert "without its __init__" in str(e), str(e)
print("refused", len(names))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=os.environ.copy(), timeout=60)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.startswith("refused"), r.stdout
