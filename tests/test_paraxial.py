"""Paraxial optics against analytic cases and Pestrecov's Eqs. (5)-(8)."""

import math

import pytest
from support import benchmark_module

from raytrace import AIR, Aperture, Field, Lens, LensError, Surface, fixed_index, model_glass
from raytrace.paraxial import paraxial
from raytrace.paraxial.orthoscopy import paraxial_chief_heights, pestrecov_constants

F4 = Aperture("fnumber", 4.0)
FIELD10 = Field("angle", 10.0)


def make(rows, stop, ap=F4, fld=FIELD10, od=math.inf):
    ss = []
    for i, (r, t, m) in enumerate(rows):
        ss.append(Surface(0.0 if r == 0 else 1.0 / r, t, m or AIR, stop=(i == stop)))
    return Lens("test", tuple(ss), ap, fld, od)


def test_ball_lens_efl():
    # Analytic: a ball of diameter D and index n has EFL = n D / (4 (n - 1)) from its centre.
    n, R = 1.7, 5.0
    g = fixed_index(n)
    lens = make([(R, R, g), (0, R, g), (-R, 10.0, None)], stop=1)
    p = paraxial(lens)
    assert p.efl == pytest.approx(n * 2 * R / (4 * (n - 1)), rel=1e-13)
    # principal planes of a ball coincide with its centre (z = R)
    assert p.z_H == pytest.approx(R, abs=1e-12)
    assert p.z_Hp == pytest.approx(R, abs=1e-12)


def test_thin_lens_limit():
    # Lensmaker's equation for a thin lens: 1/f = (n-1)(1/R1 - 1/R2).
    n, r1, r2 = 1.5168, 40.0, -60.0
    lens = make([(r1, 1e-9, fixed_index(n)), (r2, 50.0, None)], stop=0)
    p = paraxial(lens)
    f = 1.0 / ((n - 1) * (1 / r1 - 1 / r2))
    assert p.efl == pytest.approx(f, rel=1e-9)
    assert p.bfl == pytest.approx(f, rel=1e-9)
    assert p.ffl == pytest.approx(-f, rel=1e-9)
    # Gaussian conjugates 1/s' - 1/s = 1/f (Pestrecov Eq. 1) and m0 = f/(f+s) (Eq. 5)
    pf = paraxial(lens, 150.0)
    assert 1 / pf.s_prime_gauss - 1 / pf.s == pytest.approx(1 / f, rel=1e-9)
    assert pf.m0 == pytest.approx(f / (f + pf.s), rel=1e-9)
    # stop on the lens: entrance pupil = stop, so m_e = 1 and HE0 = 0
    assert pf.m_e == pytest.approx(1.0, abs=1e-9)
    assert pf.HE0 == pytest.approx(0.0, abs=1e-8)


def test_single_refracting_sphere_conjugates():
    # n'/s' - n/s = (n' - n)/R, distances from the vertex, image in the glass.
    n1, R, d = 1.6, 20.0, 100.0
    lens = make([(R, 80.0, fixed_index(n1))], stop=0, od=d)
    p = paraxial(lens)
    s_img = n1 / ((n1 - 1.0) / R + 1.0 / (-d))
    assert p.gaussian_image_distance == pytest.approx(s_img, rel=1e-12)
    # magnification of a single surface: m = (n s') / (n' s)
    assert p.m0 == pytest.approx((1.0 * s_img) / (n1 * -d), rel=1e-12)
    # focal lengths in different media: f' = n'/Φ, f = -n/Φ
    phi = (n1 - 1.0) / R
    assert p.f_image == pytest.approx(n1 / phi, rel=1e-12)
    assert p.f_object == pytest.approx(-1.0 / phi, rel=1e-12)
    # nodal points are at the centre of curvature of a single surface
    assert p.z_N == pytest.approx(R, rel=1e-12)
    assert p.z_Np == pytest.approx(R, rel=1e-12)


def test_stop_at_first_surface_pupil_is_stop():
    lens = make(
        [(30.0, 3.0, model_glass(1.6, 50.0)), (-80.0, 45.0, None)], stop=0, ap=Aperture("epd", 10.0)
    )
    p = paraxial(lens)
    assert p.z_E0 == pytest.approx(0.0, abs=1e-12)
    assert p.stop_radius == pytest.approx(5.0, rel=1e-12)


def _two_menisci(r3: float) -> Lens:
    """Two meniscus elements (glass 1.62/60, radii 25 / 60 and ``r3`` / -25 mm, 4 mm thick) 3 mm
    either side of a central stop, 40 mm to the image: ``r3`` = -60 makes it symmetric."""
    g = model_glass(1.62, 60.0)
    return make(
        [(25.0, 4.0, g), (60.0, 3.0, None), (0, 3.0, None), (r3, 4.0, g), (-25.0, 40.0, None)],
        stop=2,
    )


def test_pestrecov_constants_gaussian_plane_equal_m0_and_f():
    # Pestrecov Eqs. (7)-(8): in the Gaussian plane M0 = m0 and F0 = f.
    lens = _two_menisci(-60.0)  # symmetric about its stop
    pi = paraxial(lens)
    c = pestrecov_constants(pi, pi.s_prime_gauss)
    assert c.infinite and c.scale == pytest.approx(pi.efl, rel=1e-12)
    pf = paraxial(lens, 300.0)
    c = pestrecov_constants(pf, pf.s_prime_gauss)
    assert not c.infinite and c.scale == pytest.approx(pf.m0, rel=1e-12)
    # Eq. (7): P0g' = m_e m0 p0
    assert c.p0p == pytest.approx(pf.m_e * pf.m0 * pf.p0, rel=1e-12)
    # A lens symmetric about its stop has m_e = 1 and the nodal points on the pupils (HE0 = 0
    # is not implied, but HE0 = -H'E0' by symmetry).
    assert pi.m_e == pytest.approx(1.0, abs=1e-12)
    assert pi.HE0 == pytest.approx(-pi.HpE0p, abs=1e-12)


def test_paraxial_chief_heights_linear_in_tan():
    p = paraxial(_two_menisci(-50.0))
    h = paraxial_chief_heights(p, [0.0, 5.0], "angle", p.z_Fp)
    # at the focal plane the paraxial image height is f tan(alpha)
    assert h[1] == pytest.approx(p.efl * math.tan(math.radians(5.0)), rel=1e-12)
    assert h[0] == 0.0


def test_afocal_lens_is_an_error():
    # Two thin lenses f=50 and f=50 separated by 100 mm: a Keplerian telescope (zero power).
    n = 1.5
    r = 2 * (n - 1) * 50.0
    lens = make(
        [
            (r, 1e-9, fixed_index(n)),
            (-r, 100.0, None),
            (0, 0.0, None),
            (r, 1e-9, fixed_index(n)),
            (-r, 30.0, None),
        ],
        stop=2,
    )
    with pytest.raises(LensError, match="afocal"):
        paraxial(lens)


def test_object_space_na_follows_optiland():
    """Object-space NA → entrance-pupil diameter: the project's convention is optiland's
    (ObjectNAAperture.compute_epd, optiland 0.6.3): EPD = 2 |z_E0 − z_obj| tan(asin(NA/n)).
    Checked against optiland's own paraxial EPD for the same lens and object."""
    from dataclasses import replace

    ola = benchmark_module("optiland_adapter", needs="optiland")

    from raytrace.files.library import load_lens
    from raytrace.lens import Aperture

    lens = replace(load_lens("cooke-triplet-f4"), object_distance=200.0)
    lens = replace(lens, aperture=Aperture("na", 0.2))
    ours = paraxial(lens)
    op = ola.build_optic(lens)
    op.set_aperture(aperture_type="objectNA", value=0.2)
    theirs = float(op.paraxial.EPD())
    assert ours.epd == pytest.approx(theirs, rel=1e-12)
    assert ours.epd == pytest.approx(
        2 * abs(ours.z_E0 - ours.z_object) * math.tan(math.asin(0.2)), rel=1e-14
    )


@pytest.mark.parametrize("text", ["587.5618nm", "0.5875618um", "d"])
def test_element_power_takes_the_wavelength_strings_of_every_keyword(text):
    # was numpy's "could not convert string to float: '587.6nm'", no keyword named
    from raytrace.files.library import load_lens
    from raytrace.paraxial import element_power

    cooke = load_lens("cooke-triplet-f4")
    assert element_power(cooke, 1, 2, wavelength=text) == element_power(
        cooke, 1, 2, wavelength=587.5618
    )


@pytest.mark.parametrize(
    ("value", "says"),
    [
        ("abc", "wavelength: 'abc' is not a number"),
        ("5mm", "wavelength: 5e+06 nm is outside 100-30000 nm"),
        (0.5876, "wavelength 0.5876 nm looks like micrometres: write 0.5876um or 587.6nm"),
    ],
)
def test_element_power_refuses_a_wavelength_naming_it(value, says):
    from raytrace.errors import TraceError
    from raytrace.files.library import load_lens
    from raytrace.paraxial import element_power

    with pytest.raises(TraceError) as e:
        element_power(load_lens("cooke-triplet-f4"), 1, 2, wavelength=value)
    assert str(e.value).startswith(says), str(e.value)
