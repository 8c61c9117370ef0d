"""The "best-focus" compensator (distortion.tolerance.compensators: the plane of least RMS spot
radius of the axial object point's rays) against an outside referee: optiland 0.6.3's own RMS
spot radius (``optiland.analysis.SpotDiagram.rms_spot_radius``) scanned over image distances,
and the minimum of the parabola through the scan.

Same definition on both sides, so the comparison is exact up to round-off:

* rays: the axial object point (field (0, 0)) through a hexapolar pattern of the paraxial
  entrance pupil — the centre plus 6k rays on ring k = 1..rings at radius k/rings · EPD/2, evenly
  spaced from azimuth 0 (ours: ``pupil_bundle``; optiland: ``HexagonalDistribution``, the
  "hexapolar" distribution of SpotDiagram with ``num_rings = rings``, aimed at the paraxial
  entrance pupil — its default aiming), unclipped on both sides. Our compensator fills the
  *nominal* lens's entrance pupil with the same rays for every instance; optiland computes the
  pupil of the lens it is given, so it gets the nominal EPD, and the perturbations of the
  finite-object case (where the pupil's position matters) lie behind the stop, so that the
  instance's entrance pupil is the nominal one (for an object at infinity the rays are parallel
  to the axis and only the diameter matters);
* one wavelength, the lens's reference wavelength; every ray weighs the same;
* RMS radius about the spot's centroid (optiland: ``reference="centroid"``).

With straight rays after the last surface the mean square radius about the centroid is exactly
a quadratic in the plane's position z, so a parabola fitted through RMS² at 9 planes has its
vertex at the least-RMS plane exactly (fitting RMS itself would only approximate it). The bound,
1e-9 mm, is round-off of the two traces (the rays' final segments agree to ~1e-14 mm, see
tests/test_tolerance_operands.py) amplified by the fit, far below any focus tolerance; measured
differences are ~1e-12 mm. The perturbed instance (a radius and a thickness change) is centred,
so optiland gets it as an ordinary lens with the changed values written here.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from distortion.tolerance import evaluate, prepare
from raytrace.files.library import load_lens
from raytrace.paraxial import paraxial
from raytrace.tolerance import spec_from_dict

RINGS = 6
SCAN_DEPTH = 0.1  # mm per unit of working F-number: the scan's half width about our best focus
SCAN_PLANES = 9


def _optiland_rms(lens, wavelength_nm: float, epd: float, last_gaps: np.ndarray) -> np.ndarray:
    """optiland's RMS spot radius (mm, about the centroid) of the axial field at the image
    distances ``last_gaps`` (mm after the last vertex), with the entrance pupil diameter
    ``epd`` (mm)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import optiland_adapter as ola
    from optiland.analysis import SpotDiagram

    op = ola.build_optic(lens, wavelength_nm)
    op.set_aperture(aperture_type="EPD", value=float(epd))
    n = lens.n_surfaces
    out = []
    for gap in last_gaps:
        op.updater.set_thickness(float(gap), n)
        spot = SpotDiagram(op, fields=[(0.0, 0.0)], wavelengths=[wavelength_nm / 1000.0],
                           num_rings=RINGS, distribution="hexapolar",
                           reference="centroid")  # fmt: skip
        out.append(float(spot.rms_spot_radius()[0][0]))
    return np.array(out)


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize(
    "name, items, values",
    [
        ("cooke-triplet-f4", [], []),
        ("cooke-triplet-f4",
         [{"type": "TRAD", "surface": 3, "limit": 0.2},
          {"type": "TTHI", "surface": 2, "adjust": 4, "limit": 0.1}],
         [0.15, -0.08]),
        ("twinplex-like-55-525", [], []),
        ("twinplex-like-55-525",
         [{"type": "TRAD", "surface": 10, "limit": 0.05},
          {"type": "TTHI", "surface": 9, "adjust": 11, "limit": 0.01}],
         [0.04, 0.01]),
    ],
    ids=["cooke-nominal", "cooke-instance", "twinplex-nominal", "twinplex-instance"],
)  # fmt: skip
def test_best_focus_is_optilands_least_rms_plane(name, items, values):
    pytest.importorskip("optiland")
    lens = load_lens(name)
    zero = [{"type": "TCON", "surface": 1, "limit": 1.0}]  # a no-op item for the nominal lens
    spec = spec_from_dict({"compensator": {"type": "best-focus", "rings": RINGS},
                           "tolerances": items or zero})  # fmt: skip
    v = np.atleast_2d(np.array(values if items else [0.0]))
    st = prepare(lens, spec, fields_deg=np.linspace(0.0, float(lens.field.value), 4),
                 grid_rings=())  # fmt: skip
    ours = float(evaluate(st, v, parallel=False).image_z[0])
    # the same instance as an ordinary lens, written here from the items' meanings
    surfaces = list(lens.surfaces)
    for it, x in zip(items, values, strict=True):
        j = it["surface"] - 1
        if it["type"] == "TRAD":
            surfaces[j] = replace(surfaces[j], curvature=1.0 / (surfaces[j].radius + x))
        else:  # TTHI with adjust
            surfaces[j] = replace(surfaces[j], thickness=surfaces[j].thickness + x)
            k = it["adjust"] - 1
            surfaces[k] = replace(surfaces[k], thickness=surfaces[k].thickness - x)
    inst = replace(lens, surfaces=tuple(surfaces), image_solve=None)
    z_last = sum(s.thickness for s in inst.surfaces[:-1])
    half = SCAN_DEPTH * paraxial(lens).working_fnumber  # the depth of focus grows with F#
    gaps = (ours - z_last) + np.linspace(-half, half, SCAN_PLANES)
    rms = _optiland_rms(inst, lens.wavelength, paraxial(lens).epd, gaps)
    u = gaps - gaps[SCAN_PLANES // 2]  # centred abscissa: a well-conditioned fit
    a, b, c = np.polyfit(u, rms**2, 2)
    resid = rms**2 - np.polyval([a, b, c], u)
    assert np.max(np.abs(resid)) <= 1e-12 * np.max(rms**2)  # RMS² is a parabola in z
    theirs = z_last + gaps[SCAN_PLANES // 2] - b / (2.0 * a)
    assert np.min(rms) > 0.0 and a > 0.0
    print(f"{name}: ours {ours:.12f}, optiland's least-RMS plane {theirs:.12f}, "
          f"difference {ours - theirs:.2e} mm")  # fmt: skip
    assert abs(ours - theirs) <= 1e-9
    # the scan brackets a real minimum: the planes at its ends are visibly worse
    assert min(rms[0], rms[-1]) > 1.05 * np.min(rms)
