"""The streamed Monte Carlo summary (distortion.tolerance.summary): computed chunk by chunk, never
holding all instances, bit-identical across chunk sizes, completion orders, a resume and Dask
workers; against the exact summary of the same instances: counts, min, max and yields equal,
means and standard deviations to round-off, every percentile within one histogram bin of
numpy.percentile (the bound the module states)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import interrupt_after, run_cli

from distortion.tolerance import monte_carlo, prepare
from distortion.tolerance.summary import StreamingSummary
from raytrace.tolerance import spec_from_dict

FIELDS = np.linspace(0.0, 20.0, 6)
N = 300
BLOCK = 64  # small blocks and bins so that a short run has many of each
BINS = 512
LIMITS = [(115.0, 20.0), (20.0, 13.0)]  # µm at deg: each cuts the batch (D@20° ≈ 96..125 µm)


def _spec():
    return spec_from_dict({"tolerances": [
        {"type": "TRAD", "surface": 1, "limit": 0.05},
        {"type": "TTHI", "surface": 2, "adjust": 4, "limit": 0.02},
        {"type": "TEDX", "surfaces": [1, 2], "limit": 0.01},
        {"type": "TEDY", "surfaces": [5, 6], "limit": 0.01},
        {"type": "TETX", "surfaces": [3, 4], "limit": 0.02, "distribution": "uniform"},
    ]})  # fmt: skip


@pytest.fixture(scope="module")
def setup(cooke):
    return prepare(cooke, _spec(), fields_deg=FIELDS, g_object_distance="10x")


def _run(cooke, setup, summary, chunk, **kw):
    return monte_carlo(cooke, _spec(), N, seed=7, chunk_size=chunk, setup=setup, limits=LIMITS,
                       summary=summary, summary_block=BLOCK, summary_bins=BINS, **kw)  # fmt: skip


@pytest.fixture(scope="module")
def exact(cooke, setup):
    return _run(cooke, setup, "exact", 50)


@pytest.fixture(scope="module")
def streamed(cooke, setup):
    return _run(cooke, setup, "streaming", 50)


def test_streamed_run_holds_no_instances(streamed):
    assert streamed.outputs is None and streamed.values is None
    assert streamed.summary_method == "streaming"
    assert streamed.summary()["summary_method"] == "streaming"
    with pytest.raises(ValueError, match="limits="):
        streamed.yield_fraction(12.0, 20.0)


@pytest.mark.parametrize("chunk", [7, 64, 300])
def test_streamed_summary_is_bit_identical_across_chunk_sizes(cooke, setup, streamed, chunk):
    other = _run(cooke, setup, "streaming", chunk)
    assert json.dumps(other.summary()) == json.dumps(streamed.summary())


def test_streamed_summary_after_resume_is_bit_identical(cooke, setup, streamed, tmp_path):
    with pytest.raises(KeyboardInterrupt):
        _run(cooke, setup, "streaming", 40, out_dir=tmp_path, progress=interrupt_after(3))
    r = _run(cooke, setup, "streaming", 40, out_dir=tmp_path)
    assert r.resumed_chunks == 3
    assert json.dumps(r.summary()) == json.dumps(streamed.summary())


def test_streamed_summary_with_dask_workers_is_bit_identical(cooke, setup, streamed):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:  # fmt: skip
        with distributed.Client(cluster) as client:
            r = _run(cooke, setup, "streaming", 16, executor=client)
    assert json.dumps(r.summary()) == json.dumps(streamed.summary())


def test_any_completion_order_gives_the_same_summary(exact):
    """Chunks fed in a shuffled order (block 0 last) reduce to the same arrays bit for bit as
    in instance order: blocks wait for the histogram range and merge in block order."""
    o = exact.outputs
    arrays = o.arrays()
    cuts = [0, 13, 50, 64, 100, 171, 200, 256, 299, N]
    spans = zip(cuts[:-1], cuts[1:], strict=True)
    parts = [(a, {k: v[a:b] for k, v in arrays.items()}) for a, b in spans]

    def summarise(order):
        acc = StreamingSummary(N, FIELDS, 3, LIMITS, block=BLOCK, bins=BINS)
        for i in order:
            acc.add(*parts[i])
        return acc.result()

    a = summarise(range(len(parts)))
    rng = np.random.default_rng(0)
    order = list(rng.permutation(np.arange(1, len(parts)))) + [0]
    b = summarise(order)
    for f in ("count", "mean", "std", "min", "max", "lo", "width", "hist", "yields_raw",
              "yields_cal"):  # fmt: skip
        assert np.array_equal(getattr(a, f), getattr(b, f), equal_nan=True), f


def _finite(mc, name):
    o = mc.outputs
    v = o.K[:, int(name[1:]) - 1] if name in ("K1", "K2", "K3") else getattr(o, name)
    v = v[o.ok]
    return v[np.isfinite(v)]


def test_streamed_statistics_against_the_exact_ones(exact, streamed):
    """Counts, min, max, n_ok and yields exact; mean and std to round-off (the pairwise merge
    sums in another order than numpy: bound 1e-12 relative); every percentile within one bin
    width of numpy.percentile over the same instances."""
    ss = streamed.streamed
    assert streamed.n_ok == exact.n_ok == N
    checked = 0
    for name, st in exact.stats.items():
        sv = streamed.stats[name]
        v = _finite(exact, name)
        assert ss.count[ss.index(name)] == v.size
        if v.size == 0:
            continue
        assert sv["min"] == st["min"] and sv["max"] == st["max"], name
        scale = max(abs(st["mean"]), st["std"], 1e-300)
        assert abs(sv["mean"] - st["mean"]) <= 1e-12 * scale, name
        assert sv["std"] == pytest.approx(st["std"], rel=1e-12), name
        w = sv["bin_width"] * (1 + 1e-9)
        levels = (0.5, 2.5, 16.0, 50.0, 84.0, 97.5, 99.5)
        got = streamed.percentile_values(name, levels)
        want = np.percentile(v, levels)
        assert np.all(np.abs(got - want) <= w), name
        assert sv["outside"] == 0.0
        checked += 1
    assert checked >= 15  # efl .. g, K1..K3
    # the envelopes of the curves, per field
    for key, env in (("D_um", "envelope_um"), ("D_cal_um", "envelope_cal_um")):
        for j in range(FIELDS.size):
            wj = ss.width[ss.index(f"{key}[{j}]")] * (1 + 1e-9)
            d = getattr(streamed, env)[:, j] - getattr(exact, env)[:, j]
            assert np.all(np.abs(d) <= wj), (key, j)
    for lim, deg in LIMITS:
        for cal in (False, True):
            assert streamed.yield_fraction(lim, deg, cal) == exact.yield_fraction(lim, deg, cal)
    assert all(0.0 < exact.yield_fraction(*lim) < 1.0 for lim in LIMITS)  # limits that cut


def test_values_outside_the_first_block_range_are_counted_not_guessed():
    """Block 0 fixes the histogram range; later outliers go to the underflow / overflow counts;
    percentiles whose order statistics lie there are NaN, min and max stay exact, the others
    keep their bound."""
    rng = np.random.default_rng(3)
    n, F = 400, 2
    efl = rng.normal(50.0, 0.01, n)
    efl[300:304] = (60.0, 61.0, 40.0, 39.0)  # far outside block 0's range (±~0.15 about 50)
    arrays = {k: np.full(n, np.nan) for k in ("image_z", "focus_shift", "k0", "c", "x0", "y0",
              "P1", "P2", "S1", "S2", "P1_raw", "P2_raw", "fit_rms_um", "g")}  # fmt: skip
    arrays.update(efl=efl, K=np.full((n, 1), np.nan), D_um=np.zeros((n, F)),
                  D_cal_um=np.zeros((n, F)), ok=np.ones(n, dtype=bool))  # fmt: skip
    acc = StreamingSummary(n, np.array([0.0, 10.0]), 1, block=100, bins=256)
    acc.add(0, arrays)
    ss = acc.result()
    st = ss.stats("efl")
    assert st["outside"] == 4.0 and st["min"] == 39.0 and st["max"] == 61.0
    p = ss.percentiles("efl", (0.0, 0.3, 50.0, 99.7, 100.0))
    assert p[0] == 39.0 and p[-1] == 61.0  # the exact min and max
    # ranks 1.197 and 397.803 interpolate toward order statistics in the under / overflow
    assert np.isnan(p[1]) and np.isnan(p[3])
    assert abs(p[2] - np.percentile(efl, 50.0)) <= st["bin_width"]
    assert np.all(np.isnan(ss.percentiles("g", (50.0,))))  # no values


def test_cli_streaming_run_reports_and_plots(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[[tolerances]]\ntype = "TRAD"\nsurface = 1\nlimit = 0.05\n'
        '[[tolerances]]\ntype = "TEDY"\nsurfaces = [5, 6]\nlimit = 0.01\n'
    )
    png = tmp_path / "s.png"
    argv = ["tolerance", "cooke-triplet-f4", str(spec), "--fields", "0,5,10,15,20", "--quiet",
            "--samples", "40", "--seed", "2", "--summary", "streaming", "--limit", "30@20",
            "--g-object-distance", "10x", "--plot", str(png)]  # fmt: skip
    rc, text, err = run_cli(argv)
    assert rc == 0, err
    assert "streamed chunk by chunk" in text and "% of lenses have |D| < 30 µm at 20°" in text
    assert "variation factor g_ss'" in text and "histogram" in text
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
