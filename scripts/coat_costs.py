#!/usr/bin/env python3
"""Measures the production coats' cost per evaluation and writes data/coat_costs.json.

`make coat-costs` runs it. It runs the benchmarks that evaluate each production coat as shipped,
with lamina's exact leaves (`NAME:leaves=exact`) and lamina-coat, side by side in one run of
lamina_bench (BM_CoatEval: random direction pairs, one evaluation per pair through the Model
interface, on the plastic and the coated gold of bench/models_bench.cpp), and records the median
CPU time per evaluation with the machine, the date and the command. The study's summary quotes
this file ("For engine developers", "Cost per evaluation"); re-run it on a quiet machine after a
change to a coat's code.

usage: scripts/coat_costs.py BUILD_DIR [OUT]   (OUT: data/coat_costs.json)
"""

import datetime
import json
import os
import platform
import subprocess
import sys
from pathlib import Path


def cpu_name():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    build = Path(sys.argv[1])
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else (
        Path(__file__).resolve().parents[1] / "data" / "coat_costs.json")
    bench_filter = "BM_CoatEval/"
    command = [str(build / "lamina_bench"), f"--benchmark_filter={bench_filter}",
               "--benchmark_min_time=0.3", "--benchmark_repetitions=3",
               "--benchmark_report_aggregates_only=true", "--benchmark_format=json"]
    run = subprocess.run(command, capture_output=True, text=True, check=True)
    report = json.loads(run.stdout)
    costs = {}
    for b in report["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        # BM_CoatEval/SPEC/STACK_median
        _, spec, stack = b["run_name"].split("/")
        scale = {"ns": 1, "us": 1e3, "ms": 1e6}[b["time_unit"]]
        costs.setdefault(spec, {})[stack] = round(b["cpu_time"] * scale, 1)
    if not costs:
        sys.exit(f"{command[0]}: no BM_CoatEval benchmark ran")
    load = os.getloadavg()[0]
    data = {
        "what": "CPU time per evaluation f(wi, wo) of each production coat (as shipped, and "
                "NAME:leaves=exact) and lamina-coat, through lamina's Model interface, on random "
                "direction pairs; median of three repetitions, one thread, side by side in one "
                "run; in nanoseconds",
        "command": " ".join(["lamina_bench"] + command[1:-1]) + " (scripts/coat_costs.py)",
        "machine": f"{cpu_name()}, {os.cpu_count()} logical CPUs, load average {load:.1f} at "
                   "the end of the run",
        "date": datetime.date.today().isoformat(),
        "stacks": {"plastic": "a rough clear coat (eta 1.5, alpha 0.1, tau_a (0.05, 0.1, 0.2)) "
                              "over a Lambertian of albedo 0.8",
                   "coated-gold": "the same coat over rough gold (alpha 0.2)"},
        "ns_per_evaluation": dict(sorted(costs.items())),
    }
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(out)
    print(f"wrote {out} ({len(costs)} models)")


if __name__ == "__main__":
    main()
