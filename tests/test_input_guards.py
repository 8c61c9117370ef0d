"""Nothing silently wrong at the input: starts that are not rays are refused by the bulk trace
(not traced to "missed"), and an nd/vd model glass evaluated outside the band its model is
validated on warns as a catalog glass does outside its data."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
from support import CORPUS, TEST_DATA, run_cli

import orthoscope as osc
from raytrace.errors import PrescriptionError, TraceError
from raytrace.files import read_lens_file
from raytrace.glass import catalog_glasses
from raytrace.glass.catalog import RETIRED
from raytrace.glass.legacy import VISIBLE_NM
from raytrace.kernels.codes import STATUS_MISSED, STATUS_OK
from raytrace.lens import Aperture, Field
from raytrace.materials import (
    AIR,
    MODEL_RANGE_NM,
    MODELS,
    Material,
    OutOfRangeError,
    OutOfRangeWarning,
    fixed_index,
    model_glass,
)
from raytrace.packing import pack
from raytrace.trace import ray_paths, trace_rays
from raytrace.trace.rays import CHECK_BLOCK, CHUNK_RAYS, RAY_RULE

LENS = "cooke-triplet-f4"  # bundled, three nd/vd model glasses


@pytest.fixture(scope="module")
def packed():
    return pack(osc.load_lens(LENS))


@pytest.fixture(scope="module")
def mirror_lens():
    # a folded lens: every surface is traced in the general form (rays may run toward -z)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_lens_file(CORPUS / "optiland" / "one_mirror_up_45deg.zmx")


def _rays(n: int, seed: int = 0) -> list[np.ndarray]:
    """n rays toward +z through the front of the Cooke triplet (x, y, z, L, M, N)."""
    rng = np.random.default_rng(seed)
    r = 5.5 * np.sqrt(rng.uniform(0.0, 1.0, n))
    t = rng.uniform(0.0, 2.0 * np.pi, n)
    a, b = np.radians(rng.uniform(-20.0, 20.0, (2, n)))
    d = np.stack([np.tan(a), np.tan(b), np.ones(n)])
    d /= np.linalg.norm(d, axis=0)
    return [r * np.cos(t), r * np.sin(t), np.full(n, -1.0), d[0], d[1], d[2]]


# --------------------------------------------------------------------------------------------
# 1. starts that are not rays
# --------------------------------------------------------------------------------------------

BAD = [
    ("zero direction", (0.0, 1.0, -10.0), (0.0, 0.0, 0.0)),
    ("NaN direction", (0.0, 1.0, -10.0), (math.nan, 0.0, 1.0)),
    ("inf direction", (0.0, 1.0, -10.0), (0.0, math.inf, 1.0)),
    ("NaN origin", (0.0, math.nan, -10.0), (0.0, 0.0, 1.0)),
    ("inf origin", (-math.inf, 1.0, -10.0), (0.0, 0.0, 1.0)),
]


@pytest.mark.parametrize("what, origin, direction", BAD, ids=[b[0] for b in BAD])
@pytest.mark.parametrize("func", [trace_rays, ray_paths], ids=["trace_rays", "ray_paths"])
def test_a_start_that_is_no_ray_is_refused(packed, func, what, origin, direction):
    o = np.array([[0.0, 0.5, -10.0], origin, [0.0, -0.5, -10.0], origin])
    d = np.array([[0.0, 0.0, 1.0], direction, [0.0, 0.0, 1.0], direction])
    with pytest.raises(TraceError) as e:
        func(packed, o, d)
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(f"{func.__name__}: 2 of 4 rays are not valid rays (first: index 1,")
    assert msg.endswith(RAY_RULE)
    assert "directions must be nonzero, finite vectors pointing toward +z" in msg


@pytest.mark.parametrize("func", [trace_rays, ray_paths], ids=["trace_rays", "ray_paths"])
def test_the_guard_holds_in_the_general_trace(mirror_lens, func):
    # the bulk guard tests only MISSED rays: the general (mirror, tilt) path must send a start
    # that is not a ray to MISSED as the coaxial one does
    with pytest.raises(TraceError, match=r"1 of 2 rays are not valid rays \(first: index 0,"):
        func(mirror_lens, ([0.0, 0.0], [0.5, 0.5], [-5.0, -5.0]), ([0, 0], [0, 0], [0.0, 1.0]))


def test_one_bad_ray_in_a_large_batch_is_found_in_every_path(packed):
    n = CHUNK_RAYS + 4 * CHECK_BLOCK  # two chunks
    x, y, z, L, M, N = _rays(n)
    # a few MISSED rays (valid, travelling toward -z): the gathered test ...
    N = N.copy()
    N[::5000] *= -1.0
    ok = trace_rays(packed, (x, y, z), (L, M, N))
    assert np.all(ok.status[::5000] == STATUS_MISSED) and np.all(ok.surface[::5000] == 1)
    bad = CHUNK_RAYS + 7  # in the second chunk
    Lb = L.copy()
    Lb[bad] = math.nan
    with pytest.raises(TraceError, match=rf"1 of {n} rays .* index {bad}, origin"):
        trace_rays(packed, (x, y, z), (Lb, M, N))
    # ... and most rays MISSED: the test block by block
    Nm = -N
    Nm[bad + 1] = 0.0
    Lm = L.copy()
    Lm[bad + 1] = 0.0
    Mm = M.copy()
    Mm[bad + 1] = 0.0
    with pytest.raises(TraceError, match=rf"1 of {n} rays .* index {bad + 1}, .*\(0, 0, 0\)\)"):
        trace_rays(packed, (x, y, z), (Lm, Mm, Nm))


def _trace_as_before(packed, rays):
    """What trace_rays did before the guard: the kernel over the chunks, nothing else."""
    from raytrace.kernels import bulk

    n = rays[0].size
    out = [np.empty(n) for _ in range(6)]
    st = np.empty(n, dtype=np.int8)
    sf = np.empty(n, dtype=np.int32)
    for i0 in range(0, n, CHUNK_RAYS):
        i1 = min(n, i0 + CHUNK_RAYS)
        bulk.trace_batch_serial(
            *packed.arrays,
            True,
            *(a[i0:i1] for a in rays),
            *(a[i0:i1] for a in out),
            st[i0:i1],
            sf[i0:i1],
        )
    return (*out, st, sf)


def test_valid_rays_are_traced_bit_identically(packed):
    rays = _rays(4000, seed=3)
    rays[5][::97] *= -1.0  # valid directions toward -z: traced, MISSED at surface 1
    rays[5][5] = 0.0  # N = 0, L or M not zero: valid, MISSED at surface 1
    ref = _trace_as_before(packed, rays)
    got = trace_rays(packed, rays[:3], rays[3:], threads=1)
    names = ("x", "y", "z", "L", "M", "N", "status", "surface")
    for name, a in zip(names, ref, strict=True):
        b = getattr(got, name)
        assert b.dtype == a.dtype and np.array_equal(a, b, equal_nan=True), name
    back = rays[5] <= 0.0
    assert np.all(got.status[back] == STATUS_MISSED) and np.all(got.surface[back] == 1)
    assert np.count_nonzero(got.status == STATUS_OK) > 2000
    # ray_paths: the same statuses
    p = ray_paths(packed, [a[:200] for a in rays[:3]], [a[:200] for a in rays[3:]], clip=True)
    assert np.array_equal(p.status, got.status[:200]) and np.array_equal(
        p.surface, got.surface[:200]
    )


# --------------------------------------------------------------------------------------------
# 2. model glasses outside the band their model is validated on
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("law", MODELS)
def test_model_glass_inside_its_range_does_not_warn(law):
    m = model_glass(1.62, 60.3, law)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m.index(MODEL_RANGE_NM[0])
        m.index(MODEL_RANGE_NM[1])
        m.index(np.linspace(*MODEL_RANGE_NM, 31))
        m.index(np.array([486.1327, 587.5618, 656.2725]), strict=True)
        assert m.in_range(435.8343) and not m.in_range([500.0, 5000.0])
        # air and a fixed index have no range (a fixed-index lens at 193 nm is fine)
        AIR.index(193.368)
        fixed_index(1.5603).index(193.368, strict=True)


@pytest.mark.parametrize("law", MODELS)
@pytest.mark.parametrize("wl", [5000.0, 250.0, [550.0, 1550.0]])
def test_model_glass_outside_its_range_warns_and_strict_refuses(law, wl):
    m = model_glass(1.62, 60.3, law)
    with pytest.warns(OutOfRangeWarning) as rec:
        n = m.index(wl)
    assert np.all(np.isfinite(n))
    msg = str(rec[0].message)
    first = wl if np.ndim(wl) == 0 else wl[1]
    assert msg.startswith(
        f"model glass {m.describe()} evaluated at {first:g} nm, outside the range "
        "365.01–1013.98 nm its nd/vd model is validated over"
    )
    assert "the index is an extrapolation of the model; use a catalog glass" in msg
    with pytest.raises(OutOfRangeError, match="use wavelengths inside the range"):
        m.index(wl, strict=True)


def test_the_warning_says_how_to_find_a_catalog_glass():
    # the hint is a call, not a catalog search inside every evaluation (a search per new model
    # glass made each out-of-range index ~70 times slower, in the optimizer's glass fitting)
    with pytest.warns(OutOfRangeWarning, match=r"search_glass\(1\.62, 60\.3\) lists the nearest"):
        model_glass(1.62, 60.3).index(1550.0)


def test_a_buchdahl_model_near_its_pole_has_no_index():
    # ω = Δλ / (1 + 2.5 Δλ) has a pole at λd − 0.4 µm = 187.56 nm; before it the laws leave
    # the indices: optiland's cubic gives n = −4.27 at 200 nm (returned silently before)
    with pytest.raises(OutOfRangeError, match="has no index at 200 nm: .* breaks down"):
        model_glass(1.62, 60.3, "buchdahl-optiland").index(200.0)
    with pytest.raises(OutOfRangeError, match="has no index at 150 nm"):
        model_glass(1.62, 60.3, "buchdahl-rayoptics").index(150.0)


@pytest.mark.parametrize("wl", [math.nan, 0.0, -5.0, [500.0, math.inf]])
def test_no_wavelength_is_refused_for_model_and_catalog_glasses(wl):
    # a model glass gave NaN or inf here, a catalog glass an IndexError or a ValueError
    from raytrace.glass import lookup_glass

    for m in (model_glass(1.5, 60.0), lookup_glass("N-BK7").material):
        with pytest.raises(OutOfRangeError, match="a wavelength is a positive finite number"):
            m.index(wl)


def test_a_lens_of_model_glasses_warns_outside_the_range():
    from raytrace.lens import _indices
    from raytrace.paraxial import paraxial

    lens = osc.load_lens(LENS)
    _indices.cache_clear()  # a lens's indices are cached per process
    with pytest.warns(OutOfRangeWarning) as rec:
        paraxial(lens, wavelength=1550.0)
    texts = [str(w.message) for w in rec]
    # each surface of model glass, with the lens file and the surface in front (as a catalog
    # glass outside its data range), every time (not once per process)
    glass = {"1.61659/36.63": 0, "1.62041/60.32": 0}
    for t in texts:
        m = re.match(
            r".*cooke-triplet-f4[^:]*: surface \d+: model glass (\S+) evaluated at 1550 nm", t
        )
        assert m, t
        glass[m.group(1)] += 1
    assert all(glass.values()), texts
    with pytest.warns(OutOfRangeWarning) as again:
        paraxial(lens, wavelength=1550.0)
    assert len(again) == len(rec)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        paraxial(lens, wavelength=486.1327)


def test_the_cli_says_it_in_one_line_per_glass_and_strict_fails():
    from raytrace.lens import _indices

    argv = ["trace", LENS, "--fields", "0,10", "--wavelength", "1550"]
    _indices.cache_clear()
    rc, out, err = run_cli(argv)
    lines = [ln for ln in err.splitlines() if "compiling" not in ln]
    assert rc == 0 and out and lines  # one line per surface of model glass (printed once)
    assert len(set(lines)) == len(lines)
    assert all(
        re.match(r"orthoscope: warning: .*cooke-triplet-f4[^:]*: surface \d+: model glass ", ln)
        for ln in lines
    ), lines
    _indices.cache_clear()
    rc, out, err = run_cli([*argv, "--strict"])
    lines = [ln for ln in err.splitlines() if "compiling" not in ln]
    assert rc == 2 and out == "" and len(lines) == 1
    assert re.match(
        r"orthoscope trace: error: .*cooke-triplet-f4[^:]*: surface \d+: model glass .* evaluated",
        lines[0],
    )
    assert "Traceback" not in err


# --------------------------------------------------------------------------------------------
# the range is what the shipped catalogs show
# --------------------------------------------------------------------------------------------


def _model_error_stats(wavelengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per wavelength: the median and the 95th percentile, over the current Schott and Ohara
    glasses whose data cover it, of |n_model − n_vendor| (each glass's cauchy2 model from its
    own catalog nd/vd)."""
    rows = []
    for g in (g for c in ("Schott", "Ohara") for g in catalog_glasses(c)):
        if g.status in RETIRED or not (math.isfinite(g.nd) and math.isfinite(g.vd)):
            continue
        lo, hi = g.wavelength_range_nm
        m = model_glass(g.nd, g.vd)
        d = np.full(wavelengths.size, np.nan)
        inside = (wavelengths >= lo) & (wavelengths <= hi)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", OutOfRangeWarning)  # the model, outside its span
            w = wavelengths[inside]
            d[inside] = np.abs(m.index(w) - g.material.index(w))
        rows.append(d)
    d = np.array(rows)
    return np.nanmedian(d, axis=0), np.nanpercentile(d, 95, axis=0)


def test_the_range_is_where_the_model_error_is_as_in_the_visible():
    # criterion (raytrace.materials.MODEL_RANGE_NM): over the i to t lines the model's typical
    # error is no larger than at the blue end of the visible (400-700 nm, where every nd/vd
    # model glass is used): median within 10 % of its worst there (measured: 1.125e-3 at 370
    # nm against 1.066e-3 at 405 nm), 95th percentile within its worst there (7.29e-3 at 405
    # nm); beyond, the error grows (measured median: 1.84e-3 at 1200 nm, 4.1e-3 at 1500 nm,
    # 2.5e-3 at 300 nm)
    lo, hi = MODEL_RANGE_NM
    assert (lo, hi) == (365.01, 1013.98)  # Schott's i and t lines (TIE-29)
    vis_med, vis_p95 = _model_error_stats(np.arange(VISIBLE_NM[0], VISIBLE_NM[1] + 1, 5.0))
    med, p95 = _model_error_stats(np.append(np.arange(370.0, 1013.0, 5.0), [lo, hi]))
    assert np.all(med <= 1.1 * vis_med.max()), med.max() / vis_med.max()
    assert np.all(p95 <= vis_p95.max()), p95.max() / vis_p95.max()
    out_med, _ = _model_error_stats(np.array([300.0, 1200.0, 1500.0, 2300.0]))
    assert np.all(out_med > 1.5 * vis_med.max()), out_med / vis_med.max()


# --------------------------------------------------------------------------------------------
# 3. indices and Abbe numbers that no optical material has are refused where they are built
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("build", "says"),
    [
        (lambda: fixed_index(0.5), "fixed index nd=0.5 is below 1: a refractive index (d "
         "line) is 1 (air) to 4.1 (germanium, ~4.0 in the infrared, has the highest); give e.g. "
         "1.5168"),
        (lambda: fixed_index(15), "fixed index nd=15 is above 4.1: a refractive index (d line)"),
        (lambda: model_glass(15, 60), "model glass nd=15 is above 4.1: a refractive index (d "
         "line) is 1 (air) to 4.1"),
        (lambda: model_glass(0.99, 60), "model glass nd=0.99 is below 1: a refractive index"),
        (lambda: model_glass(64.17, 1.5168), "give e.g. 1.5168; nd and vd swapped? give nd "
         "1.5168, vd 64.17"),
        (lambda: model_glass(1.5168, 250), "model glass vd=250 is above 120: an Abbe number is "
         "above 0 and at most 120 (MgF2, 106, is among the highest); give e.g. 64.17"),
        (lambda: Material("model", 1.5, 121.0, model="buchdahl-optiland"), "model glass vd=121"),
        (lambda: fixed_index(1.5j), "nd: expected a refractive index such as 1.5168, got 1.5j "
         "(a complex number)"),
        (lambda: fixed_index(True), "got True (a bool, not a number)"),
        (lambda: model_glass(1.5, [60]), "vd: expected an Abbe number such as 64.17, got [60]"),
    ],
)  # fmt: skip
def test_an_index_or_abbe_number_no_material_has_is_refused(build, says):
    # fixed_index(0.5) and model_glass(15, 60) were built (and traced); fixed_index(1.5j) raised
    # float()'s bare TypeError
    with pytest.raises(ValueError) as e:
        build()
    assert says in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_the_ends_of_the_ranges_and_numpy_numbers_are_materials():
    # air (n = 1 exactly: dummy surfaces, index-matched gaps) and germanium-like indices stay
    # legal, as do the Abbe numbers of CaF2 (95), MgF2 (106.2, the Misc catalog) and the ends
    for n in (1.0, np.float64(1.5168), 4.0, 4.1, np.int64(2), "1.6"):
        assert fixed_index(n).nd == float(n)
    for nd, vd in (
        (1.0, 0.5),
        (4.1, 120.0),
        (1.4338, 94.99),
        (1.377744, 106.2176),
        (np.float32(1.62), 60),
    ):
        m = model_glass(nd, vd)
        assert (m.nd, m.vd) == (float(nd), float(vd))


def test_a_lens_file_with_an_impossible_model_glass_says_where(tmp_path):
    # the Material's refusal reaches the reader's one line with the file and line (a Zemax
    # model glass of nd 15 went through as one: GLAS ___BLANK only checked nd > 0)
    good = (TEST_DATA / "cooke-triplet-f4.zmx").read_text()
    line = "  GLAS ___BLANK 1 0 1.61659 3.663E+1 0 0 0 0 0 0"
    assert good.splitlines()[73] == line
    path = tmp_path / "bad-glass.zmx"
    path.write_text(good.replace(line, "  GLAS ___BLANK 1 0 15 3.663E+1 0 0 0 0 0 0"))
    with pytest.raises(PrescriptionError) as e:
        read_lens_file(path)
    msg = str(e.value)
    assert "bad-glass.zmx:74" in msg and "GLAS ___BLANK: model glass nd=15 is above 4.1" in msg, msg
    assert "\n" not in msg


@pytest.mark.parametrize(
    "build,says",
    [
        (lambda: Field("angle", True), "field angle: expected a number, got True (a bool"),
        (lambda: Field("height", 2j), "field height: expected a number, got 2j (a complex"),
        (lambda: Aperture("fnumber", True), "aperture fnumber: expected a number, got True"),
        (lambda: Aperture("epd", [10.0]), "aperture epd: expected a number, got [10.0]"),
    ],
)
def test_a_field_or_aperture_value_that_is_no_number_is_refused(build, says):
    # a Field or Aperture built in Python: True was a half-field of 1 deg and f/1 (the lens
    # files' readers refuse a bool themselves, with their file:line error)
    with pytest.raises(ValueError, match=re.escape(says)):
        build()
    assert Field("angle", np.float32(20)).value == 20.0 and Aperture("fnumber", 4).value == 4.0
