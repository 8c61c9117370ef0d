"""``orthoscope glass``: one catalog glass (formula, range, nd, vd, indices) and the nd/vd search;
the cubic-spline formula of tabulated private glasses.

Reference numbers: the SCHOTT N-BK7 data sheet (Sellmeier coefficients and the printed indices
nF 1.52238, nd 1.51680, nC 1.51432; SCHOTT optical glass catalog as packaged in opticalglass
1.1.1, SCHOTT.xls); scipy's ``interp1d(kind="cubic")`` as an independent spline.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from orthoscope.cli import main
from raytrace.glass import search_glass
from raytrace.glass.formulas import evaluate

NBK7_B = (1.03961212, 0.231792344, 1.01046945)  # SCHOTT N-BK7 data sheet
NBK7_C = (0.00600069867, 0.0200179144, 103.560653)


def nbk7(nm: float) -> float:
    l2 = (nm / 1000.0) ** 2
    return math.sqrt(1.0 + sum(b * l2 / (l2 - c) for b, c in zip(NBK7_B, NBK7_C, strict=True)))


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_glass_text(capsys):
    rc, out, _ = run(capsys, "glass", "N-BK7")
    assert rc == 0
    assert "N-BK7 (Schott)" in out and "formula 2 (Sellmeier 1)" in out
    assert "nd 1.516800   vd 64.170" in out
    assert "1.03961212, 0.00600069867" in out  # coefficients in the catalog's order
    # the d line: computed and as the catalog prints it
    line = next(x for x in out.splitlines() if x.strip().startswith("587.5618"))
    assert line.split()[1:4] == ["d", "1.516800", "1.51680"]


def test_glass_json_indices_match_the_data_sheet(capsys):
    rc, out, _ = run(capsys, "glass", "N-BK7", "--wavelengths", "F,d,C,0.4047um", "--json")
    assert rc == 0
    d = json.loads(out)
    assert d["catalog"] == "Schott" and d["formula"] == 2
    got = {round(r["wavelength_nm"], 4): r["n"] for r in d["indices"]}
    for w, printed in ((486.1327, 1.52238), (587.5618, 1.51680), (656.2725, 1.51432)):
        assert got[w] == pytest.approx(nbk7(w), abs=1e-12)
        assert round(got[w], 5) == printed  # the data sheet's printed digits
    assert got[404.7] == pytest.approx(nbk7(404.7), abs=1e-12)
    lo, hi = d["wavelength_range_nm"]
    assert lo < 404.7 < hi


def test_glass_search(capsys):
    rc, out, _ = run(capsys, "glass", "--search", "nd=1.62,vd=60", "--count", "5", "--json")
    assert rc == 0
    d = json.loads(out)
    assert len(d["matches"]) == 5
    dist = [m["distance"] for m in d["matches"]]
    assert dist == sorted(dist)
    for m in d["matches"]:
        want = math.hypot(1000.0 * (m["nd"] - 1.62), 10.0 * (m["vd"] - 60.0))
        assert m["distance"] == pytest.approx(want, rel=1e-12)
    # nothing left out is nearer (current glasses of every catalog)
    everything = search_glass(1.62, 60.0, 10**6)
    assert dist[-1] <= everything[5].distance
    rc2, out2, _ = run(capsys, "glass", "--search", "620603", "--count", "3")
    assert rc2 == 0 and "nearest to nd 1.62, vd 60.3" in out2


def test_glass_search_by_price(capsys):
    # --max-price: the nearest glasses among those whose vendor prints a relative price <= P
    rc, out, _ = run(capsys, "glass", "--search", "nd=1.62,vd=60", "--max-price", "1.2", "--json")
    assert rc == 0
    got = json.loads(out)["matches"]
    assert len(got) == 10 and all(0 < m["relative_price"] <= 1.2 for m in got)
    assert {m["catalog"] for m in got} <= {"Schott", "CDGM"}
    # the same as filtering the whole distance-ordered list by the catalog records' prices
    every = [m for m in search_glass(1.62, 60.0, 10**6) if m.glass.price <= 1.2]
    assert [(m["name"], m["catalog"]) for m in got] == [
        (m.glass.name, m.glass.catalog) for m in every[:10]
    ]
    rc, out, _ = run(capsys, "glass", "--search", "nd=1.62,vd=60", "--max-price", "1.2")
    assert "glasses with a relative price <= 1.2 nearest to" in out
    assert f"{every[0].glass.price:>6.3g}" in out.splitlines()[2]
    rc, out, _ = run(capsys, "glass", "--search", "nd=1.62,vd=60", "--count", "1", "--json")
    assert json.loads(out)["matches"][0]["relative_price"] is None  # Hikari prints none
    for argv, msg in (
        (("--search", "nd=1.62,vd=60", "--max-price", "0"), "a positive relative price"),
        (("N-BK7", "--max-price", "2"), "--max-price goes with --search"),
    ):
        rc, _, err = run(capsys, "glass", *argv)
        assert rc == 2 and msg in err and err.count("\n") == 1


def test_glass_errors_are_one_line(capsys):
    rc, _, err = run(capsys, "glass")
    assert rc == 2 and "give a glass NAME or --search" in err and err.count("\n") == 1
    rc, _, err = run(capsys, "glass", "N-BK7", "--wavelengths", "0.5876")
    assert rc == 2 and "looks like micrometres: write 0.5876um or 587.6nm" in err
    rc, _, err = run(capsys, "glass", "N-SF5", "--wavelengths", "300", "--strict")
    assert rc == 2 and "outside its data range" in err
    rc, _, err = run(capsys, "glass", "BK7")
    assert rc == 2 and "unknown glass 'BK7'" in err and "N-BK7 (Schott)" in err
    rc, _, err = run(capsys, "glass", "--search", "nd=1.62")
    assert rc == 2 and "needs both nd= and vd=" in err


def test_glass_review_refusals(capsys):
    # review 2026-11-27: an unknown catalog was "not in the Foo catalog (Schott)" for a name and
    # an empty list (exit 0) for --search; vd 0.6 listed glasses 270 code units away
    for argv in (["N-BK7", "--catalog", "Foo"], ["--search", "nd=1.62,vd=60", "--catalog", "Foo"]):
        rc, out, err = run(capsys, "glass", *argv)
        assert (rc, out) == (2, "") and "unknown catalog 'Foo': the shipped catalogs are" in err
    with pytest.raises(Exception, match="unknown catalog 'Foo'"):
        search_glass(1.62, 60.0, catalogs=["Foo"])
    rc, _, err = run(capsys, "glass", "--search", "nd=1.62,vd=0.6")
    assert rc == 2 and "vd 0.6 are not glass values" in err


def test_no_index_beyond_a_pole_of_the_formula(capsys):
    # N-BK7's Sellmeier term 3 has its pole at sqrt(103.560653) um = 10.18 um (data sheet
    # coefficients above): at 10.6 um the formula gives 3.895, at 10 um NaN; neither is an index.
    # Inside the pole the extrapolation is kept (warned) and flagged in the JSON
    assert nbk7(10600.0) == pytest.approx(3.895422, abs=1e-6)
    rc, out, err = run(capsys, "glass", "N-BK7", "--wavelengths", "10.6um")
    assert (rc, out) == (2, "") and "has no index at 10600 nm" in err
    rc, out, _ = run(capsys, "glass", "N-BK7", "--wavelengths", "2500,587.5618", "--json")
    ix = json.loads(out)["indices"]
    assert rc == 0 and [i["extrapolated"] for i in ix] == [True, False]
    assert ix[0]["n"] == pytest.approx(nbk7(2500.0), abs=1e-12)


def test_spline_formula_matches_scipy_cubic():
    interpolate = pytest.importorskip("scipy.interpolate")
    x = np.array([0.4, 0.4047, 0.44, 0.48, 0.4861, 0.5461, 0.5876, 0.65, 0.7, 0.8, 1.0, 1.6])
    y = 1.5 + 0.004 / x**2 + 0.0002 / x**4 - 0.002 * x**2
    lam = np.linspace(0.38, 1.7, 500)  # inside and (a little) outside the table
    ours = evaluate("spline", [*x, *y], lam)
    theirs = interpolate.interp1d(x, y, kind="cubic", fill_value="extrapolate")(lam)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-13)
    np.testing.assert_allclose(evaluate("spline", [*x, *y], x), y, rtol=0, atol=1e-15)
