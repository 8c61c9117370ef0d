"""Tolerancing, the Monte Carlo side: the spread against the sensitivity analysis (root sum of
squares), determinism over chunking, resume and Dask workers, the files and the outputs."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import interrupt_after

from distortion.tolerance import monte_carlo, prepare, sensitivity
from raytrace.errors import OutputError
from raytrace.tolerance import spec_from_dict

FIELDS = np.linspace(0.0, 20.0, 6)


def _spec(scale=1.0, compensator="paraxial-refocus"):
    return spec_from_dict({
        "compensator": compensator,
        "tolerances": [
            {"type": "TRAD", "surface": 1, "limit": 0.05 * scale},
            {"type": "TTHI", "surface": 2, "adjust": 4, "limit": 0.02 * scale},
            {"type": "TIND", "surface": 3, "limit": 2e-4 * scale},
            {"type": "TEDX", "surfaces": [1, 2], "limit": 0.01 * scale},
            {"type": "TEDY", "surfaces": [5, 6], "limit": 0.01 * scale},
            {"type": "TETX", "surfaces": [3, 4], "limit": 0.02 * scale, "distribution": "uniform"},
            {"type": "TSTY", "surface": 6, "limit": 0.02 * scale},
        ],
    })  # fmt: skip


@pytest.fixture(scope="module")
def setup(cooke):
    return prepare(cooke, _spec(), fields_deg=FIELDS)


@pytest.fixture(scope="module")
def mc64(cooke, setup):
    return monte_carlo(cooke, _spec(), 150, seed=11, chunk_size=64, setup=setup)


def test_small_tolerance_spread_is_the_rss_of_the_sensitivities(cooke, setup):
    """For small tolerances the outputs are linear in the perturbations, so the Monte Carlo
    standard deviation of each output equals the root sum of squares of the one-at-a-time
    sensitivities (each scaled to its item's standard deviation). With n = 600 the sample std
    has a relative standard error of 1/√(2n) = 2.9 %; the bound is 4 of those."""
    spec = _spec()
    s = sensitivity(cooke, spec, setup=setup)
    r = monte_carlo(cooke, spec, 600, seed=5, chunk_size=300, setup=setup)
    ok = r.outputs.ok
    assert ok.all()
    tol = 4.0 / np.sqrt(2 * 600)
    checked = 0
    for name in ("efl", "focus_shift", "k0", "c", "x0", "y0", "P1", "P2", "P1_raw", "P2_raw"):
        mc = np.std(getattr(r.outputs, name), ddof=1)
        pred = s.rss(name)
        assert mc == pytest.approx(pred, rel=tol), name
        checked += 1
    for name in ("D_um", "D_cal_um", "Dx_um"):
        mc = np.std(getattr(r.outputs, name)[:, -1], ddof=1)
        assert mc == pytest.approx(s.rss(name)[-1], rel=tol), name
    assert checked == 10
    # the ranking puts an element decenter first for P2 (only decenters and tilts make it)
    top = s.table("P2")[0]["name"]
    assert top.startswith(("TEDY", "TETX", "TSTY", "TEDX"))


def test_chunk_size_does_not_change_any_instance(cooke, setup, mc64):
    r7 = monte_carlo(cooke, _spec(), 150, seed=11, chunk_size=7, setup=setup)
    for k, a in mc64.outputs.arrays().items():
        assert np.array_equal(a, r7.outputs.arrays()[k], equal_nan=True), k
    assert np.array_equal(mc64.values, r7.values)
    assert json.dumps(mc64.summary()) == json.dumps(r7.summary())


def test_resume_after_an_interruption_gives_the_same_summary(cooke, setup, mc64, tmp_path):
    with pytest.raises(KeyboardInterrupt):
        monte_carlo(cooke, _spec(), 150, seed=11, chunk_size=64, setup=setup, out_dir=tmp_path,
                    progress=interrupt_after(2))  # fmt: skip
    m = json.loads((tmp_path / "manifest.json").read_text())
    assert m["done"] == [0, 1] and m["n"] == 150 and m["seed"] == 11
    assert not (tmp_path / "summary.json").exists()
    r = monte_carlo(cooke, _spec(), 150, seed=11, chunk_size=64, setup=setup, out_dir=tmp_path)
    assert r.resumed_chunks == 2
    assert json.dumps(r.summary()) == json.dumps(mc64.summary())
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk == json.loads(json.dumps(mc64.summary()))
    # another seed in the same folder is refused without overwrite
    with pytest.raises(OutputError, match="another run"):
        monte_carlo(cooke, _spec(), 150, seed=12, chunk_size=64, setup=setup, out_dir=tmp_path)


def test_outputs_and_yield(mc64):
    o = mc64.outputs
    assert o.D_um.shape == (150, FIELDS.size) and o.ok.all()
    # on the axis (tan α = 0) the raw D is the boresight y', the calibrated one y' − y0
    assert np.all(np.abs(o.D_cal_um[:, 0] - (o.D_um[:, 0] - o.y0 * 1e3)) < 1e-9)
    assert np.std(o.D_um[:, 0]) > 0.1  # decenters move the axial image point (µm)
    env = mc64.envelope_um
    assert env.shape == (len(mc64.percentiles), FIELDS.size)
    assert np.all(np.diff(env, axis=0) >= 0)  # percentiles ordered
    lim = float(np.percentile(np.abs(o.D_um[:, -1]), 50))
    y = mc64.yield_fraction(lim, FIELDS[-1])
    assert 0.4 <= y <= 0.6
    assert mc64.yield_fraction(1e9, 13.0) == 1.0


def test_compensators_differ_as_pestrecov_says(cooke):
    """Fixed sensor vs paraxial refocus: a thickness error moves the Gaussian plane, and only the
    refocused instance follows it (focus_shift 0 for fixed sensor with no last-thickness change);
    best focus lands near the paraxial plane for a well-corrected axial bundle."""
    spec = spec_from_dict({"tolerances": [{"type": "TTHI", "surface": 2, "limit": 0.05}]})
    out = {}
    for comp in ("paraxial-refocus", "fixed-sensor", "best-focus"):
        s = sensitivity(cooke, spec.with_compensator(comp), fields_deg=FIELDS, grid_rings=())
        out[comp] = s
    assert np.all(out["fixed-sensor"].delta("image_z") != 0.0)  # TTHI moves the stack end
    fs = out["fixed-sensor"].delta("image_z")[0]
    assert fs == pytest.approx([-0.05, 0.05], abs=1e-12)
    assert np.all(np.abs(out["paraxial-refocus"].delta("image_z")[0]) > 1e-3)
    d_par = out["paraxial-refocus"].delta("image_z")[0]
    d_best = out["best-focus"].delta("image_z")[0]
    assert np.all(np.sign(d_par) == np.sign(d_best))
    # the distortion change differs between compensators (Pestrecov §V)
    a = out["paraxial-refocus"].delta("D_um")[0, 1, -1]
    b = out["fixed-sensor"].delta("D_um")[0, 1, -1]
    assert abs(a - b) > 1e-3


def test_dask_local_cluster_is_bit_identical(cooke, setup, mc64):
    """Two runs in a row on one client (a notebook re-running a cell; benchmarks/tolerance.py
    warms the workers this way): each is bit-identical to the local run. The second run
    scattered the setup under the same content-hashed key that the first run's release was
    deleting, and failed with "lost dependencies"."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:  # fmt: skip
        with distributed.Client(cluster) as client:
            runs = [monte_carlo(cooke, _spec(), 150, seed=11, chunk_size=32, setup=setup,
                                executor=client) for _ in range(2)]  # fmt: skip
    for r in runs:
        for k, a in mc64.outputs.arrays().items():
            assert np.array_equal(a, r.outputs.arrays()[k], equal_nan=True), k
        assert json.dumps(r.summary()) == json.dumps(mc64.summary())


def test_batched_fit_equals_solve_linear(cooke, setup, mc64):
    """The batched least squares (one pseudo-inverse for all instances) gives the numbers of
    distortion.grid.decompose.solve_linear on the same instance's chief rays traced through its
    perturbed Lens by raytrace.trace.chief2d (another kernel and packing path)."""
    import math

    from distortion.grid.decompose import solve_linear
    from raytrace.tolerance import perturbed_lens
    from raytrace.trace.chief2d import aim_2d

    F = FIELDS.size
    P = setup.points_deg[F:]
    t = np.tan(np.radians(P))
    for i in (0, 1):
        pl = perturbed_lens(cooke, _spec(), mc64.values[i])
        cr = aim_2d(pl, P[:, 0], P[:, 1], "angle", math.inf, clip=False)
        img = cr.positions_at(float(mc64.outputs.image_z[i])).reshape(-1, 2)
        v = solve_linear(t, img).values
        o = mc64.outputs
        assert o.c[i] == pytest.approx(v["c"], rel=1e-12)
        for k in ("x0", "y0"):
            assert getattr(o, k)[i] == pytest.approx(v[k], abs=1e-11)
        for k in ("P1", "P2", "S1", "S2"):
            assert getattr(o, k)[i] == pytest.approx(v[k], abs=1e-9 * abs(v["P2"]) + 1e-14)
        assert o.K[i, 0] == pytest.approx(v["K1"], rel=1e-8)


@pytest.mark.parametrize("levels", [(150,), (-1, 50), (50, float("nan")), (), ("median",)], ids=str)
def test_percentiles_outside_0_to_100_are_refused_naming_them(cooke, setup, levels):
    # percentiles=(150,) ran the whole Monte Carlo and then failed in numpy ("Percentiles must
    # be in the range [0, 100]"), naming no argument; it is refused first, in one line
    from distortion.tolerance.checks import ToleranceInputError

    with pytest.raises(ToleranceInputError, match=r"^percentiles .*0 to 100") as e:
        monte_carlo(cooke, _spec(), 4, setup=setup, percentiles=levels)
    assert "\n" not in str(e.value)
