"""System apertures and fields as the source programs define them (issue 15 item 3), and clear
apertures that vignette rays.

Sources: OpticStudio's aperture types (ENPD, FNUM flag 0 image-space F/# and flag 1 paraxial
working F/#, OBNA flag 0 object NA and flag 1 object cone angle, FLOA float by stop size: the
paraxial marginal ray fills the stop's semi-diameter, DIAM being a semi-diameter) and field types
(FTYP 0 angle, 1 object height, 2 paraxial image height, 3 real image height); CODE V's YIM / YRI;
optiland 0.6.3 as a referee for the float-by-stop-size pupil and the offset circular clear
aperture (``OffsetRadialAperture``) of the corpus file optiland/lens_offset_aperture.zmx.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from raytrace.files import read_lens_file
from raytrace.files.codev import loads_seq
from raytrace.files.library import load_lens
from raytrace.files.native import dumps, loads
from raytrace.lens import Aperture, ClearAperture, Field
from raytrace.paraxial import paraxial
from raytrace.trace import chief_rays, trace_rays

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT / "tests" / "data" / "corpus"


def _read(rel):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_lens_file(CORPUS / rel)


def test_float_by_stop_size_fills_the_stop():
    lens = _read("optiland/lens_floa.zmx")  # FLOA; the stop's DIAM 8.5 (a semi-diameter)
    assert lens.aperture == Aperture("float", 8.5)
    p = paraxial(lens)
    assert p.stop_radius == pytest.approx(8.5, rel=1e-14)


def test_float_by_stop_size_pupil_equals_optiland():
    pytest.importorskip("optiland")
    from optiland.fileio import load_zemax_file

    for rel in ("optiland/lens_floa.zmx", "zospy/simple_system.zmx"):
        lens = _read(rel)
        op = load_zemax_file(str(CORPUS / rel))
        # optiland takes the stop's DIAM as a diameter; OpticStudio's DIAM is a semi-diameter
        op.set_aperture("float_by_stop_size", 2.0 * lens.aperture.value)
        theirs = float(np.asarray(op.paraxial.EPD()).ravel()[0])
        assert paraxial(lens).epd == pytest.approx(theirs, rel=1e-12)


def test_working_fnumber_and_cone_angle():
    lens = load_lens("cooke-triplet-f4")
    # object at infinity: the paraxial working F/# of a lens in air is EFL/EPD
    w = replace(lens, aperture=Aperture("working_fnumber", 4.0))
    assert paraxial(w).epd == pytest.approx(paraxial(lens).epd, rel=1e-12)
    # finite object: 1/(2 |n' u'|) of the marginal ray is the working F/# asked for
    fin = replace(w, object_distance=300.0).with_image_distance(50.0)
    assert paraxial(fin).working_fnumber == pytest.approx(4.0, rel=1e-12)
    # object cone angle U: the marginal ray leaves the axial object point at slope tan U
    ca = replace(fin, aperture=Aperture("cone_angle", 2.0))
    p = paraxial(ca)
    assert (p.epd / 2.0) / (p.z_E0 - p.z_object) == pytest.approx(
        math.tan(math.radians(2.0)), rel=1e-13
    )
    # written and read back exactly
    for x in (w, fin, ca):
        assert loads(dumps(x)) == x


def test_zemax_aperture_flags():
    from raytrace.files.zemax import dumps_zmx, loads_zmx

    lens = load_lens("cooke-triplet-f4")
    for ap in (Aperture("working_fnumber", 5.0), Aperture("float", 4.0)):
        x = replace(lens, aperture=ap)
        back = loads_zmx(dumps_zmx(x))
        assert back.aperture == ap


def test_field_points_in_x_and_y():
    lens = _read("zospy/simple_system_field_x10_y20.zmx")
    assert lens.field.kind == "angle"
    assert (10.0, 20.0) in lens.field.points
    assert lens.field.value == pytest.approx(math.hypot(10.0, 20.0), rel=1e-15)


def test_paraxial_image_height_is_the_paraxial_chief_ray():
    # rayoptics/landscape_lens.seq: YIM 0 3 (object at infinity). The field is the angle whose
    # paraxial chief ray reaches 3 mm in the Gaussian plane: checked with a near-axis real chief
    # ray (real rays tend to the paraxial ones), not with the formula that produced it
    # (rayoptics writes curvatures without 'RDM N'; the reader refuses the file without it)
    text = (
        (CORPUS / "rayoptics" / "landscape_lens.seq").read_text().replace("dim m", "dim m\nrdm n")
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lens = loads_seq(text)
    assert lens.field.given == ("paraxial_image_height", 3.0)
    p = paraxial(lens)
    eps = 1e-4
    cr = chief_rays(lens, [eps], clip=False)
    per_tan = float(cr.heights_at(p.z_gauss)[0]) / math.tan(math.radians(eps))
    assert abs(per_tan) * math.tan(math.radians(lens.field.value)) == pytest.approx(3.0, rel=1e-6)


@pytest.mark.parametrize("rel", ["rayoptics/US05831776-1.zmx"])
def test_real_image_height_is_reached_by_the_real_chief_ray(rel):
    # FTYP 3 (real image height 12 mm; finite object): the real chief ray of the solved object
    # height reaches 12 mm on the file's image surface
    lens = _read(rel)
    kind, h = lens.field.given
    assert kind == "real_image_height" and h == 12.0
    cr = chief_rays(lens, object_heights_mm=[lens.field.value], clip=False)
    assert abs(abs(float(cr.heights_at(lens.image_z)[0])) - h) <= 1e-11 * h


def test_real_image_height_in_toml():
    text = dumps(load_lens("cooke-triplet-f4")).replace(
        "field    = { angle = 20.0 }", "field    = { real_image_height = 18.0 }"
    )
    assert "real_image_height = 18.0" in text
    lens = loads(text)
    assert lens.field.kind == "angle" and lens.field.given == ("real_image_height", 18.0)
    cr = chief_rays(lens, [lens.field.value], clip=False)
    assert float(cr.heights_at(lens.image_z)[0]) == pytest.approx(18.0, abs=1e-11)
    assert loads(dumps(lens)) == lens


def test_rectangle_and_ellipse_apertures_vignette_by_their_shape():
    lens = load_lens("cooke-triplet-f4")
    rng = np.random.default_rng(1)
    x = rng.uniform(-5, 5, 400)
    y = rng.uniform(-5, 5, 400)
    for ap in (ClearAperture("rectangle", 3.0, 1.5, 0.5, -0.5), ClearAperture("ellipse", 3.0, 2.0)):
        ss = list(lens.surfaces)
        ss[0] = replace(ss[0], aperture=ap)
        lx = replace(lens, surfaces=tuple(ss))
        free = trace_rays(lx, (x, y, -1.0), (0.0, 0.0, 1.0), clip=False)
        clipped = trace_rays(lx, (x, y, -1.0), (0.0, 0.0, 1.0), clip=True)
        from raytrace.trace import ray_paths

        pts = ray_paths(lx, (x, y, -1.0), (0.0, 0.0, 1.0))
        inside = ap.contains(pts.x[:, 0], pts.y[:, 0])
        assert np.all(free.ok)
        assert np.array_equal(clipped.ok, inside)
        assert np.all(clipped.surface[~inside] == 1) and 0 < inside.sum() < inside.size


def test_offset_circular_aperture_vignettes_like_optiland():
    # optiland/lens_offset_aperture.zmx: CLAP 1.5 12.5 with OBDC 2.25 -3.5 (an off-centre circle);
    # its 1.5 mm inner radius is ignored here (a warning says so): compare outside it
    pytest.importorskip("optiland")
    from optiland.fileio import load_zemax_file
    from optiland.rays import RealRays

    lens = _read("optiland/lens_offset_aperture.zmx")
    ap = lens.surfaces[0].aperture
    assert ap == ClearAperture("circle", 12.5, 12.5, 2.25, -3.5)
    g = np.linspace(-16.0, 16.0, 41)
    X, Y = (a.ravel() for a in np.meshgrid(g, g))
    keep = np.hypot(X - 2.25, Y + 3.5) > 1.6
    X, Y = X[keep], Y[keep]
    ours = trace_rays(lens, (X, Y, -1.0), (0.0, 0.0, 1.0), clip=True).ok
    op = load_zemax_file(str(CORPUS / "optiland/lens_offset_aperture.zmx"))
    n = X.size
    r = RealRays(X, Y, np.full(n, -1.0), np.zeros(n), np.zeros(n), np.ones(n), np.ones(n),
                 np.full(n, lens.wavelength / 1000.0))  # fmt: skip
    op.surfaces.trace(r, skip=1)
    theirs = np.asarray(r.i) > 0.0
    assert np.array_equal(ours, theirs)
    assert 0 < ours.sum() < ours.size


def test_field_and_aperture_descriptions():
    assert Aperture("float", 2.0).describe().startswith("float by stop size")
    f = Field("angle", 20.5, (), ("real_image_height", 21.6))
    assert "real image height" in f.describe()
    with pytest.raises(ValueError):
        Field("angle", 1.0, (), ("image", 2.0))
