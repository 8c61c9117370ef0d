"""Polychromatic lenses: wavelengths, weights and the reference wavelength in the Lens and the
file formats; paraxial data and solves at the reference wavelength; chief rays and distortion at
several wavelengths from one kernel call; real-file reader fixes; the optiland referee.

Sources of reference numbers (beside each test): the real lens files of tests/data/corpus
(package, version and path in tests/data/corpus/SOURCES.md), the SCHOTT N-BK7 data sheet
(Sellmeier coefficients B1..C3, SCHOTT optical glass catalog as packaged in opticalglass 1.1.1,
SCHOTT.xls), closed-form paraxial optics of a thick lens, and optiland 0.6.3 as an independent
tracer (benchmarks/glass_referee.py).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import orthoscope as osc
from distortion.characteristic import ChromaticDistortion, characteristic_distortion
from raytrace.errors import LensError, PrescriptionError, TraceError
from raytrace.files import native
from raytrace.files.codev import loads_seq
from raytrace.files.zemax import dumps_zmx, loads_zmx
from raytrace.glass import lookup_glass
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import LAMBDA_C, LAMBDA_D, LAMBDA_F, fixed_index
from raytrace.packing import pack
from raytrace.paraxial import paraxial
from raytrace.trace import ChromaticChiefRays, chief_rays

CORPUS = Path(__file__).parent / "data" / "corpus"
AC254 = CORPUS / "raytracing" / "AC254-100-A-Zemax(ZMX).zmx"  # Thorlabs AC254-100-A
FDC = (LAMBDA_F, LAMBDA_D, LAMBDA_C)

# SCHOTT N-BK7 data sheet: Sellmeier B1, B2, B3, C1, C2, C3 (µm²)
NBK7_B = (1.03961212, 0.231792344, 1.01046945)
NBK7_C = (0.00600069867, 0.0200179144, 103.560653)


def nbk7(nm: float) -> float:
    """N-BK7 index from the SCHOTT data-sheet Sellmeier coefficients (written out here)."""
    l2 = (nm / 1000.0) ** 2
    return math.sqrt(1.0 + sum(b * l2 / (l2 - c) for b, c in zip(NBK7_B, NBK7_C, strict=True)))


def read(path: Path) -> Lens:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return osc.load_lens(path)


def singlet(r1=50.0, r2=-50.0, t=5.0, od=math.inf, **kw) -> Lens:
    glass = lookup_glass("N-BK7", ["Schott"]).material
    return Lens(
        "N-BK7 singlet",
        (
            Surface(1.0 / r1, t, glass, stop=True),
            Surface(1.0 / r2, 45.0),
        ),
        Aperture("epd", 10.0),
        Field("angle", 5.0),
        object_distance=od,
        **kw,
    )


# ----------------------------------------------------------------------------- the Lens
def test_single_wavelength_lens_normalizes():
    lens = singlet()
    assert lens.wavelengths == (LAMBDA_D,) and lens.weights == (1.0,)
    assert lens.reference_wavelength == LAMBDA_D
    assert lens == singlet(wavelengths=(LAMBDA_D,), weights=(1.0,))


def test_reference_must_be_among_wavelengths():
    with pytest.raises(LensError, match="not among the wavelengths"):
        singlet(wavelength=550.0, wavelengths=FDC)
    with pytest.raises(LensError, match="one non-negative weight per wavelength"):
        singlet(wavelengths=FDC, weights=(1.0, 2.0))
    lens = singlet().with_wavelengths(FDC, weights=(1, 2, 1))
    assert lens.wavelengths == FDC and lens.weights == (1.0, 2.0, 1.0)
    assert lens.wavelength == LAMBDA_D  # the reference is kept when it is among them
    assert singlet().with_wavelengths([500.0, 600.0]).wavelength == 500.0


def test_wavelength_in_micrometres_is_refused_with_the_fix():
    with pytest.raises(LensError, match="looks like micrometres: write 0.5876um or 587.6nm"):
        singlet(wavelength=0.5876)
    with pytest.raises(TraceError, match="looks like micrometres"):
        chief_rays(singlet(), [1.0], wavelength=0.5876)
    with pytest.raises(TraceError, match="looks like micrometres"):
        characteristic_distortion(singlet(), [1.0], wavelengths=[0.4861, 0.6563])
    with pytest.raises(TraceError, match="looks like micrometres"):  # as chief_rays says it
        paraxial(singlet(), wavelength=0.5876)


def test_fixed_index_lens_at_193_nm():
    # real-file fix: the wavelength range check must not refuse a lens of fixed indices at 193
    # nm (ArF lithography); only catalog data have a range
    lens = Lens(
        "fused silica at 193 nm (fixed index)",
        (Surface(0.02, 5.0, fixed_index(1.5603), stop=True), Surface(-0.02, 45.0)),
        Aperture("epd", 10.0),
        Field("angle", 1.0),
        wavelength=193.368,
    )
    par = paraxial(lens)
    # thick lens, closed form: 1/f = (n-1)(c1 - c2 + (n-1) t c1 c2 / n)
    n, c1, c2, t = 1.5603, 0.02, -0.02, 5.0
    assert par.efl == pytest.approx(1.0 / ((n - 1) * (c1 - c2 + (n - 1) * t * c1 * c2 / n)), 1e-12)
    text = native.dumps(lens)
    assert native.loads(text) == lens


# ----------------------------------------------------------------------------- files
def test_zmx_reads_active_wavelengths_weights_and_primary():
    lens = read(AC254)  # WAVM 1..3 = 0.4861, 0.5876, 0.6563 µm, PWAV 2 (the file)
    assert lens.wavelengths == (486.1, 587.6, 656.3)
    assert lens.wavelength == 587.6
    # FTYP 0 0 3 1: one active wavelength of the 24 WAVM slots (the file)
    one = read(CORPUS / "optiland" / "circular_aperture_example_with_aperture.zmx")
    assert one.wavelengths == (587.0,)


def test_seq_reads_wl_wtw_ref():
    lens = read(CORPUS / "opticspy" / "ag_triplet.seq")  # WL 656.3 546.1 486.1; REF 2; WTW 1 2 1
    assert lens.wavelengths == (656.3, 546.1, 486.1)
    assert lens.weights == (1.0, 2.0, 1.0)
    assert lens.wavelength == 546.1


def test_toml_keys_and_round_trip():
    lens = read(AC254)
    text = native.dumps(lens)
    assert "wavelengths = [486.1, 587.6, 656.3]" in text
    assert "reference_wavelength = 587.6" in text
    assert native.loads(text) == lens
    weighted = lens.with_wavelengths(lens.wavelengths, weights=(1.0, 2.0, 0.5))
    assert native.loads(native.dumps(weighted)) == weighted
    back = loads_zmx(dumps_zmx(weighted))
    assert (back.wavelengths, back.weights, back.wavelength) == (
        weighted.wavelengths,
        weighted.weights,
        weighted.wavelength,
    )


def _toml(extra: str) -> str:
    return (
        'name = "t"\n' + extra + "\naperture = { epd = 10 }\nfield = { angle = 5 }\n"
        'surfaces = [\n  { r = 50, t = 5, glass = "N-BK7", catalog = "Schott", stop = true },\n'
        '  { r = -50, t = "gaussian" },\n]\n'
    )


def test_toml_wavelength_errors():
    ok = native.loads(_toml("wavelength = 550.0"))
    assert ok.wavelengths == (550.0,)
    with pytest.raises(PrescriptionError, match="need reference_wavelength"):
        native.loads(_toml("wavelengths = [486.1327, 656.2725]"))
    with pytest.raises(PrescriptionError, match="not in wavelengths"):
        native.loads(_toml("wavelengths = [486.1327, 656.2725]\nreference_wavelength = 550"))
    with pytest.raises(PrescriptionError, match="disagree"):
        native.loads(_toml("wavelength = 550\nwavelengths = [550.0]\nreference_wavelength = 560"))
    with pytest.raises(PrescriptionError, match="looks like micrometres"):
        native.loads(_toml("wavelengths = [0.4861, 0.5876]\nreference_wavelength = 0.5876"))
    # the fix that message gives, written in the file, is read (it was refused: "must be a number")
    um = native.loads(_toml('wavelengths = ["0.4861um", "587.6nm"]\nwavelength = "0.5876um"'))
    assert um.wavelengths == pytest.approx((486.1, 587.6)) and um.wavelength == pytest.approx(587.6)


def test_gaussian_solve_and_scale_to_efl_use_the_reference_wavelength():
    # the image-distance solve is the paraxial back focus at the reference wavelength, whatever
    # other wavelengths the lens lists (thick-lens closed form with the SCHOTT N-BK7 index)
    for ref in (LAMBDA_F, LAMBDA_D, LAMBDA_C):
        text = _toml(f"wavelengths = [486.1327, 587.5618, 656.2725]\nreference_wavelength = {ref}")
        lens = native.loads(text)
        n, c1, c2, t = nbk7(ref), 0.02, -0.02, 5.0
        f = 1.0 / ((n - 1) * (c1 - c2 + (n - 1) * t * c1 * c2 / n))
        bfl = f * (1.0 - (n - 1) * t * c1 / n)
        assert lens.surfaces[-1].thickness == pytest.approx(bfl, rel=1e-12)
        scaled = native.loads(text.replace('name = "t"', 'name = "t"\nscale_to_efl = 100.0'))
        assert paraxial(scaled).efl == pytest.approx(100.0, rel=1e-12)
        other = LAMBDA_C if ref == LAMBDA_F else LAMBDA_F
        assert abs(paraxial(scaled, wavelength=other).efl - 100.0) > 0.1


def test_negative_image_distance_round_trips_through_toml():
    # real-file fix: a lens whose file image plane lies before the last vertex (negative last
    # thickness) written as TOML could not be read back
    lens = read(AC254).with_image_distance(-3.5)
    assert native.loads(native.dumps(lens)) == lens


# ----------------------------------------------------------------------------- real-file fixes
def test_wfno_line_is_not_an_aperture_type():
    # rayoptics US05831776-1.zmx: OBNA aperture and a "WFNO 0 0 ..." line (line 502): the
    # aperture is the object-space NA of its OBNA line
    assert read(CORPUS / "rayoptics" / "US05831776-1.zmx").aperture == Aperture("na", 0.15)
    text = dumps_zmx(singlet()).replace("ENPD", "WFNO 0 0 0 0 0 0 0 0 0 0\r\nENPD")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert loads_zmx(text).aperture == Aperture("epd", 10.0)
    # a paraxial working F/# is FNUM with flag 1 (OpticStudio "Paraxial Working F/#")
    lens = loads_zmx(dumps_zmx(singlet()).replace("ENPD 10.0", "FNUM 4.0 1"))
    assert lens.aperture == Aperture("working_fnumber", 4.0)


def test_fixed_diam_zero_on_a_dummy_surface_reads():
    # optiland circular_aperture_example_with_aperture.zmx line 90: "DIAM 0 1 ..." on surface 1
    lens = read(CORPUS / "optiland" / "circular_aperture_example_with_aperture.zmx")
    assert math.isinf(lens.surfaces[0].semi_diameter)
    # CLAP 0 0.45 on surface 10, lens units inches (UNIT IN)
    assert lens.surfaces[9].semi_diameter == pytest.approx(0.45 * 25.4, rel=1e-15)


def test_glass_messages_name_the_glass_and_the_file(tmp_path):
    # unknown glass in each format: the message names the glass and the file
    bad = tmp_path / "bad.toml"
    bad.write_text(_toml("").replace('"N-BK7", catalog = "Schott"', '"NOSUCHGLASS"'))
    with pytest.raises(PrescriptionError) as e:
        osc.load_lens(bad)
    assert "NOSUCHGLASS" in str(e.value) and "bad.toml" in str(e.value)
    with pytest.raises(PrescriptionError) as e:
        read(CORPUS / "otk" / "US08934179-4.zmx")  # GLAS COC (line 91 of the file)
    assert "COC" in str(e.value) and "US08934179-4.zmx" in str(e.value)
    # a catalog glass used outside its data range: the warning names the lens file and surface
    lens = read(AC254)
    from raytrace.materials import OutOfRangeWarning

    with pytest.warns(OutOfRangeWarning, match=r"AC254-100-A.*surface 2: glass SF5"):
        paraxial(lens, wavelength=340.0)  # N-BK7 data from 312.6 nm, SF5 from 365.0 nm


def test_codev_private_glass_is_read():
    # rayoptics CODV_65988_noDOE.seq: PRV block, 'E48' indices at 20 PWL wavelengths (the file)
    lens = read(CORPUS / "rayoptics" / "CODV_65988_noDOE.seq")
    m = lens.surfaces[0].material
    assert m.name == "E48" and m.catalog == "private"
    for w, n in ((587.6, 1.53116), (486.1, 1.5378), (1000.0, 1.5231), (400.0, 1.5484)):
        assert m.index(w) == pytest.approx(n, abs=1e-12)  # the table's own points
    with pytest.raises(PrescriptionError, match="cannot hold"):
        dumps_zmx(lens)
    assert native.loads(native.dumps(lens)) == lens


def test_codev_private_laurent_glass():
    # CODE V PRV with the Laurent form (rayoptics CODV_35571.seq: NOA61):
    # n² = A0 + A1 λ² + A2 λ⁻² + A3 λ⁻⁴ + A4 λ⁻⁶ + A5 λ⁻⁸ (λ µm)
    a = (2.36390625, 0.0, 0.025493134, -0.000580235, -0.349933e-5, 0.445404e-7)
    text = (
        "RDM\nWL 550\nEPD 10\nYAN 0 5\nPRV\n  PWL 550.0\n  'NOA61' LAU "
        + " ".join(repr(v) for v in a)
        + "\nEND\nSO 0 1e20\nS 50 5 'NOA61'\nSTO\nS -50 45\nSI 0 0\nGO\n"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lens = loads_seq(text)
    lam = 0.55
    n = math.sqrt(sum(c * lam**p for c, p in zip(a, (0, 2, -2, -4, -6, -8), strict=True)))
    assert pack(lens).n_out[0] == pytest.approx(n, abs=1e-15)


def test_envd_environment_is_applied():
    from raytrace.glass.thermal import index_at

    plain = read(AC254)  # ENVD 2.0E+1 1 0: catalog conditions, read as before
    assert plain.temperature_c is None and plain.pressure_atm is None
    text = dumps_zmx(plain).replace("UNIT MM", "ENVD 35.0 0.95 0\r\nUNIT MM")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hot = loads_zmx(text)
    assert (hot.temperature_c, hot.pressure_atm) == (35.0, 0.95)
    m = hot.surfaces[0].material
    got = hot.indices(FDC)[:, 1]
    want = index_at(m, np.array(FDC), 35.0, 0.95)
    np.testing.assert_array_equal(got, want)
    assert not np.allclose(got, plain.indices(FDC)[:, 1], rtol=0, atol=1e-6)
    assert native.loads(native.dumps(hot)) == hot
    assert loads_zmx(dumps_zmx(hot)).temperature_c == 35.0


def test_environment_matches_optiland_thermal_model():
    # optiland's MaterialFile applies the same Schott dn/dT model to its catalog N-BK7
    optiland = pytest.importorskip("optiland.materials")
    lens = singlet(temperature_c=40.0, pressure_atm=1.0)
    om = optiland.Material("N-BK7", "schott")
    for w in FDC:
        ours = lens.indices(w)[0, 1]
        theirs = float(np.asarray(om.n(w / 1000.0, temperature=40.0, pressure=1.0)).ravel()[0])
        assert ours == pytest.approx(theirs, abs=2e-6)


# ----------------------------------------------------------------------------- traces
def test_chromatic_chief_rays_equal_single_wavelength_calls():
    lens = read(AC254).with_wavelengths((450.0, *read(AC254).wavelengths, 700.0))
    f = np.array([0.0, 0.5, 1.0, 2.0, -1.5])
    many = chief_rays(lens, f, wavelengths="lens")
    assert isinstance(many, ChromaticChiefRays)
    assert many.y_last.shape == (5, 5) and many.heights_at([90.0, 97.0]).shape == (5, 2, 5)
    for i, w in enumerate(lens.wavelengths):
        one = chief_rays(lens, f, wavelength=w)
        np.testing.assert_array_equal(many[i].y_last, one.y_last)
        np.testing.assert_array_equal(many[i].M_last, one.M_last)
        np.testing.assert_array_equal(many.at(w).status, one.status)
    # finite object, nominal angles: every wavelength traces the same object points
    fin = chief_rays(lens, [1.0, 2.0], object_distance=500.0, wavelengths=[450.0, 700.0])
    np.testing.assert_array_equal(fin[0].y_start, fin[1].y_start)


def test_plate_chief_ray_is_snell_at_each_wavelength():
    # a plane-parallel N-BK7 plate with the stop on its first face: the chief ray enters at the
    # vertex and leaves at height t·tan(asin(sin α / n(λ))) (Snell; n from the data sheet)
    glass = lookup_glass("N-BK7", ["Schott"]).material
    plate = Lens(
        "plate",
        (Surface(0.0, 10.0, glass, stop=True), Surface(0.0, 5.0)),
        Aperture("epd", 4.0),
        Field("angle", 20.0),
    )
    alpha = np.array([5.0, 12.0, 20.0])
    cr = chief_rays(plate, alpha, wavelengths=[404.6561, *FDC, 1013.98])
    for r in cr:
        n = nbk7(r.wavelength)
        want = 10.0 * np.tan(np.arcsin(np.sin(np.radians(alpha)) / n))
        np.testing.assert_allclose(r.y_last, want, rtol=0, atol=1e-12)


def test_chromatic_distortion_scales():
    lens = osc.load_lens("cooke-triplet-f4")
    f = [0.0, 5.0, 10.0, 20.0]
    ref = characteristic_distortion(lens, f, wavelengths=FDC)
    assert isinstance(ref, ChromaticDistortion) and ref.D0.shape == (3, 1, 4)
    # reference scale: one F0 (the reference wavelength's) for every wavelength
    mono = characteristic_distortion(lens, f)
    np.testing.assert_allclose(ref.constant, np.broadcast_to(mono.constant, (3, 1)), rtol=1e-15)
    np.testing.assert_array_equal(ref.at(LAMBDA_D).D0, mono.D0)
    assert "reference wavelength's F0" in ref.scale_description
    # own scale: each wavelength against its own F0 in the same physical plane
    own = characteristic_distortion(lens, f, wavelengths=FDC, scale="own")
    z = ref.z_planes[0]
    for w in FDC:
        m = characteristic_distortion(
            lens, f, wavelength=w, from_last_vertex=z - mono.paraxial.z_last
        )
        np.testing.assert_allclose(own.at(w).D0, m.D0, rtol=0, atol=1e-13)
        np.testing.assert_allclose(own.at(w).constant, m.constant, rtol=1e-14)
    # the heights are the same in both scales; only the reference differs
    np.testing.assert_array_equal(ref.yp, own.yp)
    assert ref[0].retrace([7.0]).wavelength == LAMBDA_F


def test_multi_wavelength_chief_rays_match_paraxial_colour_near_the_axis():
    # paraxial limit of real rays: at 0.01° the real chief-ray heights of each wavelength in the
    # reference Gaussian plane equal the paraxial chief ray of that wavelength (z − z_E0')tanα/m_e
    from raytrace.paraxial import paraxial_chief_heights

    lens = osc.load_lens("cooke-triplet-f4")
    z = paraxial(lens).z_gauss
    cr = chief_rays(lens, [0.01], wavelengths=FDC)
    for r in cr:
        par = paraxial(lens, wavelength=r.wavelength)
        want = paraxial_chief_heights(par, [0.01], "angle", z)
        assert r.heights_at(z)[0] == pytest.approx(want[0], rel=1e-7)


# ----------------------------------------------------------------------------- referee
def test_optiland_referee_on_real_files():
    pytest.importorskip("optiland")
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import glass_referee

    for name in (
        "raytracing/AC254-100-A-Zemax(ZMX).zmx",
        "optiland/lens1.zmx",
        "rayoptics/CODV_32327.seq",
    ):
        r = glass_referee.compare_file(CORPUS / name)
        assert "error" not in r, r.get("error")
        assert r["geometry_max_rel_diff"] <= 1e-12
        for i in r["indices"]:
            assert i["max_abs_dn_same_coefficients"] <= 1e-12
        waves = {round(row["wavelength_nm"], 4) for row in r["rows"]}
        assert {486.1327, 587.5618, 656.2725} <= waves
        for row in r["rows"]:
            assert row["efl_rel"] <= 1e-6 and row["bfl_rel"] <= 1e-6
            assert row["chief_rel"] <= 1e-6
            assert row["stop_height_optiland_max_mm"] <= 1e-9
