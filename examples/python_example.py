#!/usr/bin/env python3
"""lamina from Python: simulate a stack, evaluate a model into numpy, compare them, and put a
model of your own into the comparison (docs/python.md). Run from the repository root:

    PYTHONPATH=build/python python3 examples/python_example.py [OUT_DIR]
"""

import sys
from pathlib import Path

import numpy as np

import lamina

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python-example")
stack = lamina.Stack("examples/plastic.json")
print(stack.describe())

# 1. The reference: f and its standard error as [incidence, side, θ bin, φ bin, channel].
ref = lamina.simulate(stack, theta_i=[30], particles=200_000, grid=(30, 30), seed=1)
print("reference albedo (R, G, B):", ref.energy["reflected"][0])

# 2. A model, evaluated at directions (vectorized) and on the same bins.
ww = lamina.Model("ww-prime", stack)
theta_o = np.radians(np.linspace(0, 85, 18))
wi = np.array([np.sin(np.radians(30)), 0, np.cos(np.radians(30))])
wo = np.stack([-np.sin(theta_o), np.zeros_like(theta_o), np.cos(theta_o)], axis=-1)
print("WW' in the incident plane (red):", np.round(ww.eval(wi, wo)[:, 0], 4))
binned = ww.binned([30], grid=(30, 30))
omega = binned.projected_solid_angle
misplaced = np.sum(np.abs(binned.f - ref.f)[0, 0, :, :, 0] * omega) / np.sum(ref.f[0, 0, :, :, 0] * omega)
print(f"WW' misplaced energy against the reference (red): {misplaced:.4f}")


# 3. Your own model beside the built-in ones: a class with a vectorized eval.
class Lambert:
    name = "my-lambert"

    def __init__(self, stack):
        self.rho = ref.energy["reflected"][0]  # the reference's albedo, spread uniformly

    def eval(self, wi, wo):
        return np.broadcast_to(self.rho / np.pi, wo.shape).copy()


study = lamina.compare(stack, models=["ww-prime", Lambert], theta_i=[30], particles=200_000,
                       grid=(30, 30), out=out)
m = study.metrics
for name in study.models:
    rows = m[(m["model"] == name) & (m["channel"] == "r")]
    print(f"{name:>12}: misplaced energy {rows['misplaced_energy'][0]:.4f}")
print(f"explorer: {out}/index.html")
