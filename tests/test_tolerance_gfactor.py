"""Fraser & Shortis's variation factor g_ss' per tolerancing instance (distortion.tolerance,
docs/tolerance.md "Fraser & Shortis's g"): the nominal instance's g equals what
distortion.variation.trace_variation — the code users call for g of a prescription — computes
for the same lens and distances; for small tolerances the Monte Carlo spread of g equals the root
sum of squares of its sensitivities; the spec key, the flag and the errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from support import run_cli

from distortion.errors import DataError
from distortion.tolerance import evaluate, monte_carlo, prepare, sensitivity
from distortion.variation import Conjugate, trace_variation
from distortion.variation.traced import DEFAULT_N_FIELDS
from raytrace.files.library import load_lens
from raytrace.paraxial import paraxial, resolve_object_distance
from raytrace.tolerance import ToleranceSpecError, spec_from_dict

CENTRED_ITEM = {"type": "TRAD", "surface": 1, "limit": 0.05}


def _conjugate(v) -> Conjugate:
    if isinstance(v, str):
        return Conjugate.scale(float(v[:-1]))
    assert math.isinf(v)
    return Conjugate.metres(math.inf)


@pytest.mark.parametrize(
    "name, focus, obj",
    [
        ("cooke-triplet-f4", math.inf, "10x"),
        ("cooke-triplet-f4", "20x", "10x"),
        ("topogon-like-pestrecov", "10x", math.inf),
    ],
)
def test_nominal_g_equals_trace_variation(name, focus, obj):
    """Zero perturbation, paraxial refocus (the unit focusing of distortion.variation.traced:
    the Gaussian plane of each focus): the instance's g_ss' is the g of
    trace_variation(lens, focus, [object]) — same fields (121 from 0 to the lens's field), same
    grid of 25 radii, same estimate_g. Bound: the two paths aim their chief rays with different
    kernels to 1e-12 × max(1 mm, stop radius) and compute K0 by different paraxial traces, so
    y' agrees to ~1e-12 mm, i.e. δr to ~1e-9 µm against |δr_s' − δr_s| of tens of µm: g to
    ~1e-10. Measured: |Δg| ≤ 5e-13."""
    lens = load_lens(name)
    spec = spec_from_dict({"tolerances": [CENTRED_ITEM]})
    od = resolve_object_distance(lens, object_distance=focus)
    fields = np.linspace(0.0, lens.field.value, DEFAULT_N_FIELDS)
    st = prepare(lens, spec, fields_deg=fields, object_distance=od, g_object_distance=obj,
                 grid_rings=())  # fmt: skip
    ours = evaluate(st, np.zeros((1, 1)), parallel=False).g[0]
    tv = trace_variation(lens, _conjugate(focus), [_conjugate(obj)])
    (summary,) = tv.analysis.focus_summaries
    (plane,) = summary.planes
    ref = plane.estimate.g
    assert plane.estimate.determined and 0.1 < ref < 2.0  # a real, determined g
    assert abs(ours - ref) <= 1e-10


def test_fixed_sensor_nominal_g_is_the_unit_focusing_g(cooke):
    """With nothing adjusted the lens is racked by the nominal lens's extension from s to s'
    (gfactor module docstring): for the nominal lens whose file puts the image surface at the
    Gaussian plane of s, that is the Gaussian plane of s' — the same g as paraxial refocus."""
    par = paraxial(cooke)
    assert abs(par.z_image_file - par.z_gauss) < 1e-9  # the premise, from the lens file
    spec = spec_from_dict({"tolerances": [CENTRED_ITEM]})
    g = {}
    for comp in ("paraxial-refocus", "fixed-sensor"):
        st = prepare(cooke, spec.with_compensator(comp), g_object_distance="10x", grid_rings=())
        g[comp] = evaluate(st, np.zeros((1, 1)), parallel=False).g[0]
    assert np.isfinite(g["fixed-sensor"])
    assert g["fixed-sensor"] == pytest.approx(g["paraxial-refocus"], abs=1e-9)


def _small_spec(compensator: str = "paraxial-refocus"):
    return spec_from_dict({
        "compensator": compensator,
        "tolerances": [
            {"type": "TRAD", "surface": 1, "limit": 0.05},
            {"type": "TTHI", "surface": 2, "adjust": 4, "limit": 0.02},
            {"type": "TIND", "surface": 3, "limit": 2e-4},
            {"type": "TEDY", "surfaces": [5, 6], "limit": 0.01},
            {"type": "TETX", "surfaces": [3, 4], "limit": 0.02, "distribution": "uniform"},
        ],
    })  # fmt: skip


@pytest.mark.parametrize("compensator", ["paraxial-refocus", "fixed-sensor"])
def test_small_tolerance_spread_of_g_is_the_rss_of_its_sensitivities(cooke, compensator):
    """As for the other outputs (tests/test_tolerance_montecarlo.py): for small tolerances g is
    linear in the perturbations, so its Monte Carlo standard deviation equals the root sum of
    squares of the one-at-a-time sensitivities. n = 600: the sample std has a relative standard
    error of 1/√(2n) = 2.9 %; the bound is 4 of those."""
    spec = _small_spec(compensator)
    st = prepare(cooke, spec, fields_deg=np.linspace(0.0, 20.0, 40), g_object_distance="10x")
    s = sensitivity(cooke, spec, setup=st)
    r = monte_carlo(cooke, spec, 600, seed=5, chunk_size=300, setup=st)
    g = r.outputs.g
    assert np.all(np.isfinite(g))
    pred = float(s.rss("g"))
    assert pred > 1e-4  # the tolerances move g visibly
    assert np.std(g, ddof=1) == pytest.approx(pred, rel=4.0 / np.sqrt(2 * 600))
    assert "g" in r.stats and r.stats["g"]["n"] == 600
    assert r.summary()["units"]["g"] == "1"
    assert r.summary()["g_object_distance_mm"] == pytest.approx(st.g.object_distance)
    # the sensitivity table has a g row per item, ranked
    rows = s.table("g")
    assert len(rows) == spec.n_items
    assert [r_["worst_abs"] for r_ in rows] == sorted([r_["worst_abs"] for r_ in rows])[::-1]


def test_g_is_nan_and_absent_from_stats_when_not_asked(cooke):
    spec = spec_from_dict({"tolerances": [CENTRED_ITEM]})
    r = monte_carlo(cooke, spec, 8, seed=1, fields_deg=np.linspace(0, 20, 6), grid_rings=())
    assert np.all(np.isnan(r.outputs.g))
    assert "g" not in r.stats and "g_object_distance_mm" not in r.summary()


def test_spec_outputs_key_gives_the_same_g_as_the_keyword(cooke):
    fields = np.linspace(0, 20, 30)
    by_key = spec_from_dict({"tolerances": [CENTRED_ITEM],
                             "outputs": {"g_object_distance": "10x"}})  # fmt: skip
    plain = spec_from_dict({"tolerances": [CENTRED_ITEM]})
    v = np.array([[0.03], [-0.04]])
    a = evaluate(prepare(cooke, by_key, fields_deg=fields, grid_rings=()), v, parallel=False)
    b = evaluate(prepare(cooke, plain, fields_deg=fields, grid_rings=(), g_object_distance="10x"),
                 v, parallel=False)  # fmt: skip
    assert np.all(np.isfinite(a.g)) and np.array_equal(a.g, b.g)
    assert a.g[0] != a.g[1]  # the radius change moves g


@pytest.mark.parametrize(
    "kw, err, words",
    [
        ({"g_object_distance": math.inf}, DataError, "other than the focus"),
        ({"g_object_distance": "3q"}, ToleranceSpecError, "unknown length unit"),
        ({"g_object_distance": -5.0}, ToleranceSpecError, "positive"),
        ({"g_object_distance": "10x", "fields_deg": [5.0, 10.0, 15.0, 20.0]}, DataError, "0 deg"),
        ({"g_object_distance": 30.0}, DataError, "no real image"),
    ],
)
def test_g_errors_are_one_clear_line(cooke, kw, err, words):
    spec = spec_from_dict({"tolerances": [CENTRED_ITEM]})
    with pytest.raises(err) as e:
        prepare(cooke, spec, grid_rings=(), **kw)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_cli_reports_g_spread_histogram_and_json(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[[tolerances]]\ntype = "TRAD"\nsurface = 1\nlimit = 0.05\n'
        '[[tolerances]]\ntype = "TEDY"\nsurfaces = [5, 6]\nlimit = 0.01\n'
    )
    base = ["tolerance", "cooke-triplet-f4", str(spec), "--fields", "0,5,10,15,20", "--quiet",
            "--samples", "24", "--seed", "2"]  # fmt: skip
    rc, out, err = run_cli(base)
    assert rc == 0, err
    assert "g: not computed" in out
    rc, out, err = run_cli(base + ["--g-object-distance", "10x"])
    assert rc == 0, err
    assert "variation factor g_ss'" in out and "determined for 24 of 24 lenses" in out
    assert "histogram" in out and "p50" in out
    rc, out, err = run_cli(base + ["--g-object-distance", "10x", "--json"])
    assert rc == 0, err
    mc = json.loads(out)["monte_carlo"]
    assert mc["stats"]["g"]["n"] == 24 and 0.1 < mc["stats"]["g"]["mean"] < 2.0
    assert mc["units"]["g"] == "1"
    rc, out, err = run_cli(base[:-4] + ["--sensitivity", "--g-object-distance", "10x", "--json"])
    assert rc == 0, err
    s = json.loads(out)["sensitivity"]
    assert "g" in s["outputs"] and len(s["outputs"]["g"]["items"]) == 2
    rc, out, err = run_cli(base + ["--g-object-distance", "inf"])
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "focus" in err


def test_unknown_outputs_key_is_refused_with_a_suggestion():
    with pytest.raises(ToleranceSpecError) as e:
        spec_from_dict({"tolerances": [CENTRED_ITEM], "outputs": {"g_object_distanc": "10x"}},
                       path="spec.toml")  # fmt: skip
    msg = str(e.value)
    assert msg.startswith("spec.toml") and "[outputs]" in msg and "g_object_distance" in msg
