"""Old and ambiguous glass names in real lens files (raytrace.glass.legacy).

The files are real ones from the corpus (tests/data/corpus/SOURCES.md names each source). Before
raytrace.glass.legacy they were refused for their glass names only: Schott names whose lead-free
successors carry the ``N-`` prefix (``BK7``, ``LAF2``, ``SK4``, ``BAF4``, ``KF9``, ``PSK3``;
``BK7_SCHOTT`` in a .seq) and names that several vendors use (``LAF2``: Hoya, Hikari) in files
whose ``GCAT`` line names Schott.

Referee: optiland 0.6.3 reading the same file with its own reader and its own glass resolution
(refractiveindex.info data, name matching of its own). Two comparisons per file:

* with orthoscope's indices put into optiland's optic, the paraxial EFLs agree to 1e-12
  relative (the files are read alike);
* with optiland's own glasses, the EFLs differ by what the glass data differ by: orthoscope's
  lens given optiland's indices reproduces optiland's own EFL to 1e-12 relative, so all of the
  difference is glass data (measured: Doublet −7.2e-7, optiland's Hikari F2 for Schott F2;
  Tessar −3.1e-4, Hikari SK4 / BAF4 for N-SK4 / N-BAF4; Double Gauss −1.2e-5, Hikari LAF2 for
  N-LAF2; zmax_55278 +1.3e-5, N-SF5 for SF5; telescope_objective.seq −2.0e-4, CaF2 data of
  Daimon & Masumura at 20 °C (refractiveindex.info main/CaF2/Daimon-20.yml, n_d 2.8e-5 higher)
  for the shipped Malitson data).
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from raytrace.errors import PrescriptionError
from raytrace.files.library import load_lens
from raytrace.glass import find_glass, printed_nd_vd, resolve_glass
from raytrace.glass.legacy import ND_TOLERANCE, VD_TOLERANCE
from raytrace.materials import fixed_index
from raytrace.paraxial import paraxial

CORPUS = Path(__file__).resolve().parents[1] / "tests" / "data" / "corpus"

#: real files refused before for their glass names → the (old, successor) pairs they now use
NOW_READ = {
    "pyzdde/Doublet.ZMX": {("BK7", "N-BK7")},
    "pyzdde/Double_Gauss_5_degree field.ZMX": {("LAF2", "N-LAF2"), ("PSK3", "N-PSK3")},
    "pyzdde/Tessar_lens_using_vignetting_factors.ZMX": {
        ("SK4", "N-SK4"),
        ("BAF4", "N-BAF4"),
        ("KF9", "N-KF9"),
    },
    "opticspy/singlet.seq": {("BK7", "N-BK7")},
    "rayoptics/zmax_55278.zmx": {("BK7", "N-BK7")},
    "optiland/complicated_fold_mirrors_setup_v2.zmx": {("BK7", "N-BK7")},
}
#: files whose EFL is compared with optiland (the fold-mirror file is tilted: no paraxial EFL;
#: singlet.seq's EFL is fixed at 100 mm by its ``CUY UMY -0.1`` solve with EPD 20, so there the
#: comparison checks the solve, and the glass shows in the solved radius)
REFEREED = [f for f in NOW_READ if "fold_mirrors" not in f] + ["optiland/telescope_objective.seq"]
#: optiland 0.6.3 ignores the file's ``UNIT IN`` line (Double Gauss: "UNIT IN X W X CM MR CPMM"),
#: so its lengths are in inches where orthoscope's are in mm
OPTILAND_SCALE = {"pyzdde/Double_Gauss_5_degree field.ZMX": 25.4}


def _read(rel: str):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lens = load_lens(CORPUS / rel)
    return lens, [str(w.message) for w in caught]


@pytest.mark.parametrize("rel", list(NOW_READ))
def test_file_reads_and_the_warning_names_the_substitution(rel):
    lens, msgs = _read(rel)
    used = {(s.material.name, s.material.catalog) for s in lens.surfaces}
    text = " ".join(msgs)
    for old, new in NOW_READ[rel]:
        assert (new, "Schott") in used, (rel, used)
        assert f"{old} is not in the shipped Schott catalog" in text
        assert f"successor Schott {new} (nd" in text
        # the successor's catalog nd/vd are stated (taken from the shipped catalog)
        g = find_glass(new, ["Schott"])[0]
        assert f"{new} (nd {g.nd:.6g}, vd {g.vd:.2f}" in text


def test_a_named_data_set_of_a_crystal_reads_with_the_shipped_data():
    # optiland/telescope_objective.seq line 13: "S  15.758 1.6701  CAF2_DAIMON-20"
    lens, msgs = _read("optiland/telescope_objective.seq")
    m = lens.surfaces[3].material
    assert (m.name, m.catalog) == ("CAF2", "Misc")
    text = " ".join(msgs)
    assert "CAF2_DAIMON-20" in text and "main/CaF2/Malitson.yml is used" in text


@pytest.mark.parametrize("rel", REFEREED)
def test_efl_agrees_with_optiland_reading_the_same_file(rel):
    pytest.importorskip("optiland")
    from optiland.fileio import load_codev_file, load_zemax_file
    from optiland.materials import IdealMaterial

    lens, _ = _read(rel)
    path = str(CORPUS / rel)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        op = load_codev_file(path) if rel.endswith(".seq") else load_zemax_file(path)
    scale = OPTILAND_SCALE.get(rel, 1.0)
    w = lens.wavelength
    assert float(op.wavelengths.primary_wavelength.value) * 1000.0 == pytest.approx(w, rel=1e-12)
    surfs = op.surfaces.surfaces
    assert len(surfs) == len(lens.surfaces) + 2
    ours = paraxial(lens).efl
    theirs_n = [float(np.ravel(s.material_post.n(w / 1000.0))[0]) for s in surfs]
    own = float(op.paraxial.f2()) * scale
    # all of the own-glass difference is glass data: our lens with optiland's indices
    mod = dataclasses.replace(
        lens,
        surfaces=tuple(
            dataclasses.replace(s, material=fixed_index(theirs_n[i + 1]))
            for i, s in enumerate(lens.surfaces)
        ),
    )
    assert paraxial(mod).efl == pytest.approx(own, rel=1e-12)
    # same glass data (orthoscope's indices in optiland's optic): same EFL
    n = lens.indices(w)[0]
    for i, s in enumerate(surfs):
        s.material_post = IdealMaterial(float(n[min(i, len(n) - 1)]))
    assert float(op.paraxial.f2()) * scale == pytest.approx(ours, rel=1e-12)
    # and where optiland took the same glass as orthoscope, the index is the same to 1e-9
    for i, s in enumerate(lens.surfaces):
        m = s.material
        their = Path(getattr(surfs[i + 1].material_post, "filename", "") or "").stem
        if m.kind == "catalog" and their == m.name:
            assert theirs_n[i + 1] == pytest.approx(float(n[i + 1]), abs=1e-9)


def test_gcat_prefers_the_named_vendor_and_refuses_an_unnamed_ambiguity():
    # LAF2: Hoya LAF2 and Hikari LAF2 differ in vd in the shipped catalog
    hoya = resolve_glass("LAF2", ["HOYA"])
    assert (hoya.glass.catalog, hoya.glass.name, hoya.warning) == ("Hoya", "LAF2", "")
    hikari = resolve_glass("LAF2", ["HIKARI", "HOYA"])
    assert hikari.glass.catalog == "Hikari" and hikari.warning == ""
    with pytest.raises(PrescriptionError, match="ambiguous glass 'LAF2'.*Hoya.*Hikari"):
        resolve_glass("LAF2")
    schott = resolve_glass("LAF2", ["SCHOTT"])
    assert (schott.glass.catalog, schott.glass.name) == ("Schott", "N-LAF2")
    assert "Hoya LAF2" in schott.warning and "Hikari LAF2" in schott.warning


def test_seq_vendor_suffix_names_the_catalog():
    r = resolve_glass("BK7_SCHOTT")
    assert (r.glass.catalog, r.glass.name) == ("Schott", "N-BK7")
    assert "BK7 is not in the shipped Schott catalog" in r.warning
    # a glass the suffix's catalog has is used silently
    assert resolve_glass("NSK16_SCHOTT").warning == ""


def test_a_glass_outside_the_named_catalogs_is_used_with_a_warning():
    # B270 (ACL3026U-Zemax(ZMX).zmx names GCAT SCHOTT) is only in the Misc catalog
    r = resolve_glass("B270", ["SCHOTT"])
    assert r.glass.catalog == "Misc" and "none of the catalogs the file names (Schott)" in r.warning
    assert resolve_glass("B270").warning == ""


def test_printed_nd_vd_decide_between_successor_and_model_glass():
    g = find_glass("N-BK7", ["Schott"])[0]
    close = resolve_glass("BK7", ["SCHOTT"], printed=(g.nd + 0.5 * ND_TOLERANCE, g.vd))
    assert close.glass is g and "Δnd -2.50e-04" in close.warning
    far = resolve_glass("BK7", ["SCHOTT"], printed=(g.nd, g.vd + 2.0 * VD_TOLERANCE))
    assert far.glass is None and "a model glass with the file's nd and vd" in far.warning
    assert far.material.nd == g.nd and far.material.vd == g.vd + 2.0 * VD_TOLERANCE


def test_printed_nd_vd_are_read_only_where_they_are_the_glasses():
    # GLAS lines of the corpus (field 1 = glass solve: 0 fixed, 3 substitute)
    assert printed_nd_vd("D-ZK3M 0 0 1.601 5.0277746E+1 2.7E-3 0 0 0 0 0".split()) == (
        1.601,
        50.277746,
    )  # rayoptics/354710-C-Zemax(ZMX).zmx
    assert printed_nd_vd("BK7 0 0 1.5 4.0E+1 0 0 0 0 0 0".split()) is None  # placeholder
    assert printed_nd_vd("BK7 0 0 0 0 0 0 0 0 0 0".split()) is None  # placeholder
    assert printed_nd_vd("SK16 3 1 1.717 4.7959999E+1 -2.8E-3 1 1 1 0 0".split()) is None
    assert printed_nd_vd(["SF5"]) is None  # rayoptics/zmax_55278.zmx: name only


@pytest.mark.parametrize(
    "rel, glass",
    [
        # otk: GCAT SCHOTT MISC ANGSTROMLINK HOYA; "GLAS COC 0 0 1.5 4.0E+1" prints placeholders
        ("otk/US08934179-4.zmx", "COC"),
        # OSLO "GLA LAKN6": no numbers at all (the other four files: tests/test_glass_fallback.py)
        ("optiland/test_glass_fallback.len", "LAKN6"),
    ],
)
def test_glasses_without_evidence_stay_refused_with_the_fix(rel, glass):
    with pytest.raises(PrescriptionError) as e:
        _read(rel)
    msg = str(e.value)
    assert "\n" not in msg and glass in msg and "model glass" in msg


def test_refusal_states_the_nd_vd_the_file_prints_and_the_catalog_to_add():
    # an unknown name whose GLAS line prints nd/vd, read strictly: the refusal names the numbers
    # (the non-strict reading makes a model glass of them: tests/test_glass_fallback.py)
    with pytest.raises(PrescriptionError) as e:
        resolve_glass("XYZ-1", ["LIGHTPATH", "SCHOTT"], printed=(1.601, 50.277746), strict=True)
    msg = str(e.value)
    assert "the file prints nd 1.601, vd 50.277746" in msg and "LIGHTPATH" in msg
    assert "strict reading takes no substitute glass" in msg
