"""OSLO ``.len`` files (raytrace.files.oslo) against an independent reader: optiland 0.6.3's OSLO
reader (``optiland.fileio.load_oslo_file``) on the real .len files of the corpus
(tests/data/corpus/SOURCES.md: ``cox3_07.len`` is Cox problem 3-07 as saved by OSLO and
published on lens-designs.com, MIT licence; the ``test_*.len`` files are optiland's OSLO test
files).

Checked: the prescription (radii, vertex positions, conics, the stop), the aperture and the
wavelengths (OSLO's wavelength 1 is the primary: cox3_07.len lists d, F, C in OSLO's order);
the paraxial EFL at every wavelength of the file; and real chief rays on a 3 × 3 field grid
(benchmarks/referees.py, optiland's iterative aim at the real stop centre) to 1e-9 mm. For the
ray and EFL comparisons optiland's media are replaced by the indices orthoscope computed: the
two tools take catalog glasses from different data (opticalglass 1.1.1's vendor catalogs;
refractiveindex.info in optiland), which differ by up to 1.5e-5 in n for F2 and SF5 — this
test is about reading the file and tracing it, not about glass data (tests/test_glass_* are).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from support import benchmark_module

from raytrace.errors import PrescriptionError
from raytrace.files.oslo import read_len
from raytrace.paraxial import paraxial

ROOT = Path(__file__).resolve().parents[1]
LEN_DIR = ROOT / "tests" / "data" / "corpus" / "optiland"
READ = ["cox3_07", "test_achromat", "test_asphere_singlet", "test_cassegrain",
        "test_cooke_triplet", "test_petzval"]  # fmt: skip
#: optiland 0.6.3 returns NaN for every off-axis chief ray of cox3_07 (its aim fails there,
#: with or without its apertures); the file's prescription and EFL are still compared
NO_RAY_REFEREE = {"cox3_07"}


def _ours(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_len(LEN_DIR / f"{name}.len")


def _theirs(name: str, lens, wavelength: float):
    """optiland's reading, its media replaced by orthoscope's indices at ``wavelength``."""
    from optiland.fileio import load_oslo_file
    from optiland.materials import IdealMaterial

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        op = load_oslo_file(str(LEN_DIR / f"{name}.len"))
    n = lens.indices(wavelength)[0]
    for i, s in enumerate(benchmark_module("optiland_adapter").surface_group(op).surfaces):
        s.material_post = IdealMaterial(float(n[min(i, len(n) - 1)]))
    return op


def test_every_real_len_file_reads_or_is_refused_in_one_line():
    names = sorted(p.stem for p in LEN_DIR.glob("*.len"))
    assert set(READ) < set(names)
    for name in names:
        if name in READ:
            assert len(_ours(name).surfaces) >= 2
            continue
        with pytest.raises(PrescriptionError) as e:
            _ours(name)
        msg = str(e.value)
        assert "\n" not in msg
        # test_glass_fallback.len: LAKN6 is in none of the shipped catalogs
        assert name == "test_glass_fallback" and "LAKN6" in msg


@pytest.mark.parametrize("name", READ)
def test_prescription_equals_optilands_reading(name):
    pytest.importorskip("optiland")
    lens = _ours(name)
    op = _theirs(name, lens, lens.wavelength)
    sg = benchmark_module("optiland_adapter").surface_group(op)
    body = sg.surfaces[1:-1]
    assert len(body) == len(lens.surfaces)
    radii = [float(np.ravel(s.geometry.radius)[0]) for s in body]
    np.testing.assert_allclose(radii, [s.radius for s in lens.surfaces], rtol=1e-14)
    conics = [float(np.ravel(getattr(s.geometry, "k", 0.0))[0]) for s in body]
    assert conics == [s.conic for s in lens.surfaces]
    z = np.ravel(np.asarray(sg.positions, dtype=float))[1:-1]
    np.testing.assert_allclose(z, lens.vertex_z[: len(z)], rtol=0, atol=1e-12)
    assert sg.stop_index == lens.stop_index + 1
    wl = [float(w.value) * 1000.0 for w in op.wavelengths.wavelengths]
    assert wl == pytest.approx(list(lens.wavelengths), rel=1e-12)
    assert float(op.wavelengths.primary_wavelength.value) * 1000.0 == pytest.approx(
        lens.wavelength, rel=1e-12
    )
    assert float(op.paraxial.EPD()) == pytest.approx(paraxial(lens).epd, rel=1e-10)


@pytest.mark.parametrize("name", READ)
def test_efl_equals_optiland_at_every_wavelength(name):
    pytest.importorskip("optiland")
    lens = _ours(name)
    for w in lens.wavelengths:
        op = _theirs(name, lens, w)
        assert float(op.paraxial.f2()) == pytest.approx(paraxial(lens, wavelength=w).efl, rel=1e-12)


@pytest.mark.parametrize("name", [n for n in READ if n not in NO_RAY_REFEREE])
def test_chief_rays_equal_optilands(name):
    pytest.importorskip("optiland")
    pytest.importorskip("scipy")
    R = benchmark_module("referees")

    lens = _ours(name)
    op = _theirs(name, lens, lens.wavelength)
    half = lens.field.value / math.sqrt(2.0) if lens.field.value > 0 else 0.5
    X, Y = R.grid(half)
    ours = R.ours_grid(lens, X, Y)
    theirs, res = R.optiland_grid(op, lens, X, Y)
    assert res <= 1e-11
    assert np.max(np.abs(ours - theirs)) <= 1e-9
