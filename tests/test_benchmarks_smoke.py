"""Smoke test of the benchmark suite (benchmarks/run.py) at toy sizes, and its agreement checks.

The agreement limit (1e-9 mm on image heights) is the one issue 6 sets for the comparison
tracers; here the two in-suite baselines (plain numpy, hand-written numba loop) must meet it
against the project's tracer on the suite's own benchmark rays.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture(scope="module")
def run():
    sys.path.insert(0, str(BENCH))
    spec = importlib.util.spec_from_file_location("bench_run", BENCH / "run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_agreement_logic(run):
    a = (np.array([1.0, 2.0, np.nan]), np.array([0.0, 1.0, 5.0]))
    b = (np.array([1.0, 2.0 + 3e-9, 7.0]), np.array([0.0, 1.0, 5.0]))
    d, n = run.agreement(a, b)
    assert n == 2  # the NaN ray is not compared
    assert d == pytest.approx(3e-9, rel=1e-6)
    assert d > run.AGREE_TOL  # would print VOID
    d, n = run.agreement(a, a)
    assert d == 0.0 and n == 2
    d, n = run.agreement((np.full(2, np.nan),) * 2, (np.zeros(2),) * 2)
    assert math.isinf(d) and n == 0  # nothing comparable is a failure, not a pass


@pytest.mark.parametrize("name", ["cooke-triplet-f4", "cooke-asphere-bench"])
def test_numpy_baseline_agrees_with_project(run, name):
    from raytrace.files.library import load_lens
    from raytrace.packing import pack

    lens = load_lens(run.LENSES[name])
    p = pack(lens)
    rays = run.bench_rays(lens, 3000, seed=3)
    pxy, rb = run.project_image(p, rays)
    assert rb.ok.mean() > 0.99
    d, n = run.agreement(pxy, run.numpy_image(p, rays))
    assert n == int(rb.ok.sum())
    assert d <= run.AGREE_TOL


def test_handwritten_loop_agrees_with_project(run):
    from raytrace.files.library import load_lens
    from raytrace.packing import pack

    lens = load_lens("cooke-triplet-f4")
    p = pack(lens)
    rays = run.bench_rays(lens, 3000, seed=4)
    pxy, rb = run.project_image(p, rays)
    hx, hy, st = run.hw.run(p, *rays)
    assert np.array_equal(st == 0, rb.ok)
    d, _ = run.agreement(pxy, (hx, hy))
    assert d <= run.AGREE_TOL


def test_workloads_toy_size(run, tmp_path):
    log = lambda msg: None  # noqa: E731
    res = {"machine": {"cpu": "test", "cpus": 1, "load_start": [0], "load_end": [0]}}
    res["bulk"] = run.bulk([1000], True, False, log)
    assert {r["impl"] for r in res["bulk"]["rows"]} >= {"orthoscope", "numpy", "handwritten-numba"}
    for a in res["bulk"]["agreement"]:
        assert a["numpy_max_dmm"] <= run.AGREE_TOL
    res["scaling"] = {
        "exponent_rays": 1.0,
        "rays": [1, 2],
        "exponent_surfaces": 1.0,
        "surfaces": [2, 4],
        "surfaces_rays": 1,
    }
    res["chief"] = run.chief(True, False, log)
    assert all(r["all_ok"] for r in res["chief"]["rows"])
    res["map"] = run.through_focus(True, log)
    assert res["map"]["shape"] == [200, 200] and res["map"]["finite_fraction"] == 1.0
    res["optimizer"] = run.optimizer(log)
    res["cli"] = {
        "command": "x",
        "warm_s": 0.5,
        "python_startup_s": 0.0,
        "import_numpy_numba_s": 0.0,
        "import_project_s": 0.0,
    }
    res["memory"] = run.memory(10_000, log)
    assert res["memory"]["peak_rss_mb"] > 0
    res["targets"] = run.targets(res)
    text = "\n".join(run.summarize(res))
    assert "through-focus map" in text and "VOID" not in text


def test_tolerance_benchmark_toy_size(tmp_path, capsys):
    """benchmarks/tolerance.py --quick (64 instances, no optiland, no Dask): runs, every chief
    ray of every instance traced, the JSON written."""
    import json

    spec = importlib.util.spec_from_file_location("bench_tolerance", BENCH / "tolerance.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = tmp_path / "tolerance.json"
    assert mod.main(["--quick", "--no-optiland", "--no-dask", "--out", str(out)]) == 0
    res = json.loads(out.read_text())
    assert res["orthoscope"]["instances"] == 64
    assert res["orthoscope"]["ok_fraction"] == 1.0
    assert res["orthoscope"]["instances_per_s_per_core"] > 0
    assert "instances/s/core" in capsys.readouterr().out


def test_startup_benchmark_one_round(tmp_path):
    """benchmarks/startup.py at one round on the paraxial command: wall and CPU time measured,
    the warm-up ran, the probe saw no kernels and no numba; the summary prints the target."""
    spec = importlib.util.spec_from_file_location("bench_startup", BENCH / "startup.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cmd = [("paraxial", ["paraxial", "cooke-triplet-f4"], 0.35)]
    res = mod.measure(1, commands=cmd, breakdown=False, log=lambda m: None)
    r = res["commands"]["paraxial"]
    assert r["rc"] == 0 and not r["notice_after_warm_up"]
    assert 0 < r["cpu_median_s"] and 0 < r["wall_median_s"]
    assert r["loaded"]["kernels"] == {} and not r["loaded"]["imported"]["numba"]
    assert "<= 0.35" in "\n".join(mod.summarize(res))
    # the warm-up knows a compiling run by the command line's notice (the notice's words changed
    # once and the benchmark no longer saw it)
    from orthoscope.cli import COMPILE_NOTICE

    assert COMPILE_NOTICE.startswith(mod.NOTICE)
