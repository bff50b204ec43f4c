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
