"""Configurations that change thicknesses (focus positions): reading Zemax THIC operands and CODE V
ZOO THI, the TOML block, and the focus study of distortion.variation.focus (issue 13 item 4).

Sources of the reference numbers are named beside them. No multi-configuration .zmx or zoom .seq
file exists in the corpus or in the optiland / rayoptics distributions (searched: every .zmx /
.seq there has MNUM 1 or none, no ZOO), so the readers are tested on hand cases and on real
single-configuration files with operand rows appended (said so in each test).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from distortion.variation.focus import (
    focus_configurations,
    focus_study,
    solve_focus,
    track_length,
    unit_focus_configurations,
)
from raytrace.errors import PrescriptionError
from raytrace.files.codev import loads_seq
from raytrace.files.configurations import (
    Configuration,
    Configurations,
    apply_configuration,
    configurations_from_toml,
    dumps_with_configurations,
    parse_seq_configurations,
    parse_toml_configurations,
    parse_zmx_configurations,
    read_configurations,
    read_configured,
    write_lens_with_configurations,
)
from raytrace.files.library import load_lens
from raytrace.files.native import loads
from raytrace.files.zemax import dumps_zmx, loads_zmx
from raytrace.paraxial import paraxial

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
INNER = "tessar-fr1066698-inner-focus"
DISTANCES = [math.inf, 10000.0, 5000.0, 3000.0, 2000.0]  # mm from the image plane

# ------------------------------------------------------------------------------- Zemax reader

HAND_ZMX = """VERS 140124 258 36214
MODE SEQ
UNIT CM X W X CM MR CPMM
SURF 0
  DISZ INFINITY
SURF 1
  CURV 0.1
  DISZ 0.5
  GLAS ___BLANK 1 0 1.5 60
SURF 2
  DISZ 3
SURF 3
MNUM 3 2
MOFF   0   1 "" 0 0 0 1 1 0 0.0 ""
MOFF   0   2 "" 0 0 0 1 1 0 0.0 ""
MOFF   0   3 "" 0 0 0 1 1 0 0.0 ""
THIC   0   1 1.0E+10 0 0 0 1 1 0 0.0 ""
THIC   0   2 100 0 0 0 1 1 0 0.0 ""
THIC   0   3 50 0 0 0 1 1 0 0.0 ""
THIC   2   1 3 0 0 0 1 1 0 0.0 ""
THIC   2   2 3.3 0 0 0 1 1 0 0.0 ""
THIC   2   3 3.6 0 0 0 1 1 0 0.0 ""
THIC   3   1 7 0 0 0 1 1 0 0.0 ""
YFIE   1   1 5 0 0 0 1 1 0 0.0 ""
"""


def test_zmx_thic_hand_case() -> None:
    c = parse_zmx_configurations(HAND_ZMX, path="hand.zmx")
    assert len(c) == 3 and c.current == 2
    # UNIT CM: lengths x 10 (OpticStudio's lens unit); THIC 0 >= 1e10 is infinity
    a, b, d = c.configurations
    assert a.object_distance == math.inf and a.thicknesses == ((2, 30.0),)
    assert b.object_distance == 1000.0 and b.thicknesses == ((2, 33.0),)
    assert d.object_distance == 500.0 and d.thicknesses == ((2, 36.0),)
    # the image surface's thickness (surface 3 of 0-3) and other operands are listed, not read
    assert any("image surface" in s for s in c.ignored)
    assert any(s.startswith("YFIE") for s in c.ignored)
    assert c.surfaces == (0, 2)


@pytest.mark.parametrize(
    "row, match",
    [
        ('THIC   2   4 3 0 0 0 1 1 0 0.0 ""', "outside 1–3"),
        ('THIC   2   1 3 0 0 0 1 1 0 0.0 ""', "given twice"),
        ('THIC   2   1 abc 0 0 0 1 1 0 0.0 ""', "not a number"),
    ],
)
def test_zmx_thic_errors_name_the_line(row: str, match: str) -> None:
    with pytest.raises(PrescriptionError, match=match) as e:
        parse_zmx_configurations(HAND_ZMX + row + "\n", path="hand.zmx")
    assert e.value.line == HAND_ZMX.count("\n") + 1


def test_zmx_real_file_with_thic_rows_appended() -> None:
    # tests/data/topogon-us2031792-fig1.zmx (UTF-16, a real OpticStudio-format file, one
    # configuration) with a multi-configuration block appended by hand: the normal reader gives
    # the base lens, this module the configurations, and applying one changes exactly that gap.
    raw = (DATA / "topogon-us2031792-fig1.zmx").read_bytes()
    text = raw.decode("utf-16")
    assert parse_zmx_configurations(text).configurations == (Configuration("1"),)
    block = (
        "MNUM 2 1\n"
        'THIC   4   1 2.5 0 0 0 1 1 0 0.0 ""\n'
        'THIC   4   2 3.0 0 0 0 1 1 0 0.0 ""\n'
        'THIC   0   2 500 0 0 0 1 1 0 0.0 ""\n'
    )
    text2 = text.rstrip("\r\n") + "\r\n" + block
    with pytest.warns(UserWarning):
        base = loads_zmx(text2.encode("utf-16"))
    c = parse_zmx_configurations(text2.encode("utf-16"))
    lens2 = apply_configuration(base, c.configurations[1])
    assert lens2.surfaces[3].thickness == 3.0 and lens2.object_distance == 500.0
    for i, (s, t) in enumerate(zip(base.surfaces, lens2.surfaces, strict=True)):
        if i != 3:
            assert s == t


def test_configuration_of_a_missing_surface_is_refused() -> None:
    lens = load_lens("cooke-triplet-f4")
    with pytest.raises(PrescriptionError, match="surface 9 does not exist"):
        apply_configuration(lens, Configuration("x", ((9, 1.0),)))


# ------------------------------------------------------------------------------- CODE V reader


def test_seq_zoom_real_file_with_zoo_appended() -> None:
    # tests/data/corpus/optiland/cooke_triplet.seq (optiland 0.6.3 test file) with zoom rows
    # appended by hand: S4 is the air space 4.750246, S6 the image distance 42.20170.
    text = (DATA / "corpus" / "optiland" / "cooke_triplet.seq").read_text(encoding="utf-8")
    assert parse_seq_configurations(text).configurations == (Configuration("1"),)
    text2 = text + "ZOO THI S4 4.750246 5.0 5.5 ; ZOO THI SO 1e10 2000 &\n 1000\nZOO YAN F2 7 6 5\n"
    with pytest.warns(UserWarning):
        base = loads_seq(text2)
    c = parse_seq_configurations(text2, path="z.seq")
    assert len(c) == 3
    assert [cf.thickness(4) for cf in c.configurations] == [4.750246, 5.0, 5.5]
    assert [cf.object_distance for cf in c.configurations] == [math.inf, 2000.0, 1000.0]
    assert any(s.startswith("ZOO YAN") for s in c.ignored)
    third = apply_configuration(base, c.configurations[2])
    assert third.surfaces[3].thickness == 5.5 and third.object_distance == 1000.0


def test_seq_zoom_value_count_must_agree() -> None:
    with pytest.raises(PrescriptionError, match="3 zoom positions"):
        parse_seq_configurations("ZOO THI S2 1 2 3\nZOO THI S4 1 2\n", path="z.seq")


# ------------------------------------------------------------------------------- TOML


def test_toml_round_trip_exact(tmp_path: Path) -> None:
    lens = load_lens("cooke-triplet-f4")
    confs = Configurations(
        (
            Configuration("far", ((6, 43.1),), math.inf),
            Configuration('near "1 m"', ((4, 0.1 + 0.2), (6, 45.123456789012345)), 950.0),
        )
    )
    text = dumps_with_configurations(lens, confs)
    assert loads(text) == lens  # the native reader reads the base lens and skips the block
    again = parse_toml_configurations(text)
    assert again.configurations == confs.configurations  # every float bit for bit
    p = tmp_path / "c.toml"
    p.write_text(text, encoding="utf-8")
    lens2, confs2 = read_configured(p)
    assert lens2 == lens and confs2.configurations == confs.configurations


def test_scale_to_efl_scales_the_configurations_with_the_lens(tmp_path: Path) -> None:
    # the bundled inner-focus Tessar with scale_to_efl = 50: every configuration length is the
    # unscaled one times the lens's factor ("inf" stays), so each focus position is the same
    # conjugate scaled (before the fix the configurations kept the 100 mm lens's thicknesses:
    # the "inf" position gave EFL 47.74 mm, not 50)
    text = (ROOT / "lenses" / f"{INNER}.toml").read_text(encoding="utf-8")
    scaled_text = text.replace('units      = "mm"\n', 'units      = "mm"\nscale_to_efl = 50.0\n')
    assert scaled_text != text
    p = tmp_path / "tessar50.toml"
    p.write_text(scaled_text, encoding="utf-8")
    lens0, confs0 = read_configured(INNER)
    lens, confs = read_configured(p)
    factor = lens.surfaces[0].thickness / lens0.surfaces[0].thickness
    assert paraxial(lens).efl == pytest.approx(50.0, rel=1e-14)
    assert factor == pytest.approx(50.0 / paraxial(lens0).efl, rel=1e-14)
    # the infinity position is the scaled base lens itself, bit for bit
    assert apply_configuration(lens, confs.configurations[0]) == lens
    for c0, c in zip(confs0.configurations, confs.configurations, strict=True):
        assert c.name == c0.name
        assert [k for k, _ in c.thicknesses] == [k for k, _ in c0.thicknesses]
        for (_, t0), (_, t) in zip(c0.thicknesses, c.thicknesses, strict=True):
            assert t == pytest.approx(t0 * factor, rel=1e-14)
        if math.isinf(c0.object_distance):
            assert c.object_distance == math.inf
        else:
            assert c.object_distance == pytest.approx(c0.object_distance * factor, rel=1e-14)
        cl0, cl = apply_configuration(lens0, c0), apply_configuration(lens, c)
        par0, par = paraxial(cl0), paraxial(cl)
        assert par.efl == pytest.approx(par0.efl * factor, rel=1e-12)
        # the Gaussian image of the scaled object distance: the scaled image distance, on the
        # scaled lens's image plane (the unscaled positions were solved to 1e-10 mm)
        assert par.gaussian_image_distance == pytest.approx(
            par0.gaussian_image_distance * factor, rel=1e-12
        )
        assert abs(par.gaussian_image_distance - cl.surfaces[-1].thickness) < 1e-9
        if math.isfinite(cl.object_distance):
            assert cl.object_distance + track_length(cl) == pytest.approx(
                float(c.name.split()[0]) * 1000.0 * factor, rel=1e-13
            )
    # the lens-less readers scale the same way
    assert parse_toml_configurations(scaled_text).configurations == confs.configurations
    assert configurations_from_toml(tomllib.loads(scaled_text)).configurations == (
        confs.configurations
    )
    # written back: the scaled numbers without scale_to_efl; read again, the same lens and
    # configurations
    out = tmp_path / "out.toml"
    write_lens_with_configurations(lens, confs, out)
    assert "scale_to_efl" not in tomllib.loads(out.read_text(encoding="utf-8"))
    lens2, confs2 = read_configured(out)
    assert lens2 == lens and confs2.configurations == confs.configurations


def test_read_configured_builds_a_scaled_lens_once(tmp_path: Path, monkeypatch) -> None:
    # with scale_to_efl, read_configured built the lens twice: once to read it, once more for
    # the factor its configurations are scaled by; once is enough, for the same result (the
    # result itself: test_scale_to_efl_scales_the_configurations_with_the_lens)
    import raytrace.files.native as native

    text = (ROOT / "lenses" / f"{INNER}.toml").read_text(encoding="utf-8")
    p = tmp_path / "tessar50.toml"
    p.write_text(text.replace('units      = "mm"\n', 'units      = "mm"\nscale_to_efl = 50.0\n'))
    real, builds = native._build, []

    def build(*a, **k):
        builds.append(1)
        return real(*a, **k)

    monkeypatch.setattr(native, "_build", build)
    lens, confs = read_configured(p)
    assert len(builds) == 1
    assert paraxial(lens).efl == pytest.approx(50.0, rel=1e-14)
    # the same lens and configurations as read apart (each builds it once)
    assert lens == native.read_lens(p)
    assert confs.configurations == read_configurations(p).configurations
    assert len(builds) == 3


def test_toml_bad_configuration_is_refused() -> None:
    text = '[[configurations]]\nname = "a"\nthickness = { x = 1.0 }\n'
    with pytest.raises(PrescriptionError, match="not a surface number"):
        parse_toml_configurations(text)
    with pytest.raises(PrescriptionError, match="unknown key"):
        parse_toml_configurations("[[configurations]]\nthick = { 1 = 1.0 }\n")


def test_bundled_inner_focus_lens_reads_and_focuses() -> None:
    lens, confs = read_configured(INNER)
    assert [c.name for c in confs.configurations] == ["inf", "10 m", "5 m", "3 m", "2 m"]
    for c in confs.configurations:
        cl = apply_configuration(lens, c)
        # constant track (inner focus): surfaces 2 + 4 keep the patent's 6.10 + 3.95
        assert cl.surfaces[1].thickness + cl.surfaces[3].thickness == pytest.approx(
            10.05, abs=1e-12
        )
        par = paraxial(cl)
        # in focus: the Gaussian image on the image plane (solve tolerance 1e-10 mm)
        assert abs(par.gaussian_image_distance - cl.surfaces[-1].thickness) < 1e-9
        if math.isfinite(cl.object_distance):
            assert cl.object_distance + track_length(cl) == pytest.approx(
                float(c.name.split()[0]) * 1000.0, abs=1e-9
            )


def test_each_configuration_agrees_with_optiland(tmp_path: Path) -> None:
    # referee: optiland 0.6.3 reading each configuration written as a single-configuration .zmx;
    # EFL, Gaussian magnification and the real chief ray (aimed at the real stop centre by its
    # iterative aimer) in the file's image plane. Finite objects get an object-height field (the
    # nominal 20 deg, y = |p0| tan 20 deg) so that both programs start from the same point.
    pytest.importorskip("optiland")
    from dataclasses import replace

    from optiland.fileio import load_zemax_file

    from distortion.characteristic import characteristic_distortion
    from raytrace.lens import Field

    lens, confs = read_configured(INNER)
    for k, c in enumerate(confs.configurations):
        cl = apply_configuration(lens, c)
        par = paraxial(cl)
        finite = math.isfinite(cl.object_distance)
        if finite:
            h = abs(par.p0) * math.tan(math.radians(20.0))
            cl = replace(cl, field=Field("height", h))
        p = tmp_path / f"c{k}.zmx"
        p.write_text(dumps_zmx(cl), encoding="utf-8")
        op = load_zemax_file(str(p))
        assert op.paraxial.f2() == pytest.approx(par.efl, rel=1e-12)
        if finite:
            assert float(op.paraxial.magnification()) == pytest.approx(par.m0, rel=1e-9)
        # optiland's aimer stops at its tolerance (1e-10 for the finite objects, whose
        # coordinates are ~1e4 mm; it does not converge at 1e-14 there)
        op.ray_tracer.set_aiming("iterative", max_iter=100, tol=1e-10 if finite else 1e-14)
        for hy in (0.5, 1.0):
            rays = op.trace_generic(Hx=0.0, Hy=hy, Px=0.0, Py=0.0, wavelength=cl.wavelength / 1e3)
            y_ref = float(np.asarray(rays.y).ravel()[0])
            if finite:
                cd = characteristic_distortion(cl, object_heights_mm=[hy * h], plane="file")
            else:
                cd = characteristic_distortion(cl, [hy * cl.field.value], plane="file")
            # measured: <= 3.5e-10 mm (10 m), 1.8e-14 mm at infinity
            assert abs(float(cd.yp[0][0]) - y_ref) < (1e-9 if finite else 1e-12), (c.name, hy)


def test_zmx_block_of_the_bundled_configurations_reads_back() -> None:
    # the bundled lens as a .zmx (orthoscope's writer) with its configurations as THIC rows in
    # the layout the reader documents: the .zmx route gives the TOML's configurations exactly
    lens, confs = read_configured(INNER)
    rows = [f"MNUM {len(confs)} 1"]
    for k in confs.surfaces:
        for j, c in enumerate(confs.configurations, start=1):
            v = c.object_distance if k == 0 else c.thickness(k)
            v = 1e10 if math.isinf(v) else v
            rows.append(f'THIC {k:3d} {j:3d} {v!r} 0 0 0 1 1 0 0.0 ""')
    text = dumps_zmx(lens) + "\n".join(rows) + "\n"
    again = parse_zmx_configurations(text)
    assert [(c.thicknesses, c.object_distance) for c in again.configurations] == [
        (c.thicknesses, c.object_distance) for c in confs.configurations
    ]


# ------------------------------------------------------------------------------- focus study


@pytest.fixture(scope="module")
def studies():
    base = load_lens("tessar-fr1066698")
    unit = focus_study(base, unit_focus_configurations(base, DISTANCES), focus_index=2)
    lens, confs = read_configured(INNER)
    inner = focus_study(lens, confs, focus_index=2)
    return unit, inner


def test_unit_focusing_reproduces_browns_gamma_to_round_off(studies) -> None:
    unit, _ = studies
    # analytic: moving a thick lens in air as a whole, Newton's equation gives the image plane
    # at c = f (1 + 1/N) from H' exactly, which is Brown's Eq. (2) c_s'/c_s in image scales
    for s in unit.settings:
        assert s.efl_mm == unit.settings[0].efl_mm
        n = s.image_scale
        assert s.principal_distance_mm == pytest.approx(
            s.efl_mm * (1 + (0 if math.isinf(n) else 1 / n)), rel=1e-13
        )
        assert abs(s.defocus_mm) < 1e-9 and s.principal_point_mm == 0.0
    for g in unit.gamma:
        assert abs(g.relative_error) < 1e-12
        assert abs(g.error_um_at_edge) < 1e-6


def test_unit_focus_profiles_equal_the_unit_focusing_trace() -> None:
    # the same Gaussian profiles through the other code path: trace_variation's unit focusing
    # (image plane placed by the paraxial Gaussian solve, object given as an image scale)
    from distortion.variation import Conjugate, trace_variation

    base = load_lens("tessar-fr1066698")
    st = focus_study(base, unit_focus_configurations(base, DISTANCES[:3]), n_fields=41)
    n_near = st.settings[2].image_scale
    tv = trace_variation(
        base, Conjugate.scale(n_near), [Conjugate.scale(60.0)], n_fields=41, max_field_deg=25.0
    )
    trace = next(t for t in tv.settings if t.gaussian and t.focus.value == n_near)
    np.testing.assert_allclose(trace.r_mm, st.settings[2].r_mm, rtol=0, atol=1e-9)
    np.testing.assert_allclose(trace.dr_um, st.settings[2].dr_um, rtol=0, atol=1e-6)


def test_inner_focus_breaks_gamma_by_the_stated_amount(studies) -> None:
    unit, inner = studies
    # the focal length changes with focus (99.8866 mm at infinity, 99.3895 mm at 2 m: regression
    # pins of this study), so Brown's c = f(1 + 1/N) with the infinity f misses the principal
    # distance. Measured (regression pins): relative γ error 4.94e-4 at 10 m, 1.22e-3 at 5 m,
    # 2.57e-3 at 3 m, 5.00e-3 at 2 m; at the edge radius 46.46 mm that is 23, 56, 120, 232 µm.
    rel = [g.relative_error for g in inner.gamma[1:]]
    np.testing.assert_allclose(rel, [4.943e-4, 1.2155e-3, 2.5731e-3, 5.0014e-3], rtol=2e-3)
    edge = [g.error_um_at_edge for g in inner.gamma[1:]]
    np.testing.assert_allclose(edge, [22.96, 56.47, 119.54, 232.36], rtol=2e-3)
    assert inner.settings[-1].efl_mm == pytest.approx(99.389463, abs=1e-5)
    assert all(abs(g.relative_error) < 1e-12 for g in unit.gamma)


def test_brown_interpolation_between_two_calibrations(studies) -> None:
    unit, inner = studies
    # Eq. (3)-(4) from the calibrations at infinity and 2 m, each intermediate focus predicted.
    # Regression pins (this study, 25 radii up to the common edge 46.46 mm, largest error at the
    # edge; 10 m / 5 m / 3 m): unit focusing 2.42 / 3.66 / 3.41 µm, inner focus 26.9 / 40.9 /
    # 38.5 µm, about 11 times more each time.
    for u, i in zip(unit.interpolation, inner.interpolation, strict=True):
        assert u.name == i.name
        assert i.max_abs_um > 5 * u.max_abs_um
        assert i.r_at_max_mm == pytest.approx(i.r_mm[-1])
    np.testing.assert_allclose(
        [t.max_abs_um for t in inner.interpolation], [26.92, 40.87, 38.47], rtol=5e-3
    )
    np.testing.assert_allclose(
        [t.max_abs_um for t in unit.interpolation], [2.4243, 3.6551, 3.4101], rtol=5e-3
    )


def test_fraser_shortis_analysis_runs_on_both(studies) -> None:
    unit, inner = studies
    # Fraser & Shortis with the lens focused at 5 m and object planes at the other distances.
    # Regression pins of this study: Brown's Eq. (1) misses δr_ss' by at most 15.1 µm under unit
    # focusing but 761 µm under inner focus (its γ assumes the distortion scales with c only);
    # Eq. (6) fits both within 1.4 µm RMS with one mean g, but g is 1.33 (unit) and -0.051
    # (inner): with a moving group δr_ss' no longer lies between δr_s and δr_s' (g < 0), the
    # regularity the paper's Eq. (6) rests on (F&S 1992: "fall between ... regardless of the sign").
    a_u, a_i = unit.analysis, inner.analysis
    assert a_u is not None and a_i is not None and len(a_u.brown) == len(a_i.brown) == 3
    assert max(b.max_abs_um for b in a_u.brown) == pytest.approx(15.12, rel=5e-3)
    assert max(b.max_abs_um for b in a_i.brown) == pytest.approx(761.4, rel=5e-3)
    g_u, g_i = a_u.focus_summaries[0], a_i.focus_summaries[0]
    assert g_u.summary.n == g_i.summary.n == 3
    assert g_u.summary.mean == pytest.approx(1.3271, abs=2e-3)
    assert g_i.summary.mean == pytest.approx(-0.0514, abs=2e-3)
    for fs in (g_u, g_i):
        assert max(p.rms_mean_g_um for p in fs.planes) < 1.4


def test_solve_focus_refuses_impossible_requests() -> None:
    from distortion.errors import DataError

    lens = load_lens("tessar-fr1066698")
    with pytest.raises(DataError, match="moving and compensating"):
        solve_focus(lens, 1000.0, moving=2, compensating=2)
    with pytest.raises(DataError, match="surfaces 1–8"):
        focus_configurations(lens, [1000.0], moving=9)
    with pytest.raises(DataError, match="focus distance 10 mm is inside the lens"):
        solve_focus(lens, 10.0, moving=8)
    # a lens the paraxial trace refuses is refused with the request's context from the
    # first evaluation on (not only inside the secant loop)
    from dataclasses import replace

    from raytrace.frames import Placement

    tilted = replace(lens, image_placement=Placement(tilt=(1.0, 0.0, 0.0)))
    with pytest.raises(DataError, match="cannot focus on 1000 mm by moving surface 8: .*centred"):
        solve_focus(tilted, 1000.0, moving=8)


def test_cli_variation_configurations(capsys) -> None:
    import json

    from orthoscope.cli import main

    assert main(["variation", "--lens", INNER, "--configurations", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [c["name"] for c in d["configurations"]] == ["inf", "10 m", "5 m", "3 m", "2 m"]
    # the same numbers as the API (pinned above)
    assert d["gamma"][-1]["relative_error"] == pytest.approx(5.0014e-3, rel=2e-3)
    assert main(["variation", "--lens", INNER, "--configurations"]) == 0
    assert "Brown Eq. (2)" in capsys.readouterr().out
