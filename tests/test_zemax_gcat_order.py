"""The GCAT line the .zmx writer chooses (review: `convert` refused to write back a .zmx it read).

OpticStudio, and the reader here (:func:`raytrace.glass.resolve_glass`), resolve a catalog
glass name to the first catalog on the GCAT line that has it. The writer used to list the
catalogs in order of first use and refuse when that order resolved a name to another catalog,
although another order worked: US08427765-1.ZMX (rayoptics corpus, ``GCAT SCHOTT HIKARI RPO
HOYA``) uses Hikari's J-LAK14 before Schott's SF11, and Hikari also has an SF11, so first-use
order (Hikari, Ohara, Schott, Hoya) read SF11 as Hikari's. The writer now picks an order in
which every glass resolves to its own catalog and refuses only when none exists.

The reference for every comparison is the lens as read from the file (its own glasses, EFL and
chief rays): the round trip must reproduce it exactly.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from raytrace.errors import PrescriptionError
from raytrace.files import convert
from raytrace.files.library import load_lens
from raytrace.files.zemax import dumps_zmx, loads_zmx, read_zmx
from raytrace.glass import catalog_available, find_glass, lookup_glass
from raytrace.paraxial import paraxial
from raytrace.trace import chief_rays

pytestmark = pytest.mark.skipif(not catalog_available(), reason="glass catalogs not installed")

CORPUS = Path(__file__).parent / "data" / "corpus"
US08427765 = CORPUS / "rayoptics" / "US08427765-1.ZMX"
CORPUS_ZMX = sorted(p for p in CORPUS.rglob("*") if p.suffix.lower() == ".zmx")


def quiet(f, *a):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*a)


def materials(lens):
    return [lens.object_material, *(s.material for s in lens.surfaces)]


def gcat_line(text: str) -> list[str]:
    (line,) = [x for x in text.splitlines() if x.startswith("GCAT ")]
    return line.split()[1:]


def resolves_as_opticstudio(text: str, lens) -> None:
    """Every catalog glass of ``lens``, by the name the text writes, is found first in its own
    catalog on the text's GCAT line (OpticStudio's rule, checked here without the reader)."""
    gcat = gcat_line(text)
    for m in materials(lens):
        if m.kind != "catalog":
            continue
        first = next(c for c in gcat if find_glass(m.name.replace(" ", ""), [c]))
        assert find_glass(m.name.replace(" ", ""), [first])[0].catalog == m.catalog, m.name


def chief_heights(lens) -> np.ndarray:
    cr = quiet(lambda: chief_rays(lens, [0.0, 10.0, 17.0, 24.0]))
    assert np.all(cr.status == 0)
    return cr.heights_at(lens.image_z)


def assert_same_optics(back, lens) -> None:
    assert materials(back) == materials(lens)
    assert back == lens  # every field the Lens compares
    assert quiet(paraxial, back).efl == quiet(paraxial, lens).efl
    np.testing.assert_array_equal(chief_heights(back), chief_heights(lens))


def test_us08427765_zmx_to_zmx_writes_and_reads_back_the_same_glasses(tmp_path):
    lens = quiet(read_zmx, US08427765)
    assert {(m.name, m.catalog) for m in materials(lens) if m.kind == "catalog"} >= {
        ("SF11", "Schott"),
        ("J-LAK14", "Hikari"),
    }
    text = dumps_zmx(lens)  # was refused: "glass SF11 of the Schott catalog cannot be written"
    gcat = gcat_line(text)
    assert gcat.index("SCHOTT") < gcat.index("HIKARI")
    resolves_as_opticstudio(text, lens)
    assert_same_optics(quiet(loads_zmx, text), lens)
    out = tmp_path / "x.zmx"
    quiet(convert, US08427765, out)  # the CLI's `convert` path (UTF-16 file)
    assert_same_optics(quiet(read_zmx, out), lens)


def test_us08427765_zmx_to_toml_to_zmx(tmp_path):
    lens = quiet(read_zmx, US08427765)
    toml, zmx = tmp_path / "x.toml", tmp_path / "x.zmx"
    quiet(convert, US08427765, toml)
    quiet(convert, toml, zmx)
    back = quiet(read_zmx, zmx)
    assert materials(back) == materials(lens)
    assert back.surfaces == lens.surfaces
    assert quiet(paraxial, back).efl == quiet(paraxial, lens).efl
    np.testing.assert_array_equal(chief_heights(back), chief_heights(lens))
    assert back == quiet(load_lens, toml)


def with_glasses(*names_catalogs):
    """The Cooke triplet with its three glasses replaced by catalog glasses."""
    lens = load_lens("cooke-triplet-f4")
    ss = list(lens.surfaces)
    glassy = [i for i, s in enumerate(ss) if not s.material.is_air]
    for i, (name, cat) in zip(glassy, names_catalogs, strict=True):
        ss[i] = replace(ss[i], material=lookup_glass(name, [cat], first_catalog_wins=True).material)
    return replace(lens, surfaces=tuple(ss))


def test_first_use_order_is_kept_when_it_works():
    # Schott's SF11 first: the order of first use (Schott, Hikari) already resolves every name
    lens = with_glasses(("SF11", "Schott"), ("J-LAK14", "Hikari"), ("N-BK7", "Schott"))
    text = dumps_zmx(lens)
    assert gcat_line(text) == ["SCHOTT", "HIKARI"]
    assert loads_zmx(text) == lens


def test_an_order_other_than_first_use_is_found():
    # Hikari's J-LAK14 first, then Schott's SF11 (also in Hikari): Schott must come first
    lens = with_glasses(("J-LAK14", "Hikari"), ("SF11", "Schott"), ("N-BK7", "Schott"))
    text = dumps_zmx(lens)
    assert gcat_line(text) == ["SCHOTT", "HIKARI"]
    resolves_as_opticstudio(text, lens)
    assert loads_zmx(text) == lens


def test_no_order_exists_is_refused():
    # Schott's SF11 needs SCHOTT before HIKARI, Hikari's SF11 the opposite
    lens = with_glasses(("SF11", "Schott"), ("SF11", "Hikari"), ("N-BK7", "Schott"))
    assert lens.surfaces[0].material != lens.surfaces[2].material
    with pytest.raises(PrescriptionError) as e:
        dumps_zmx(lens)
    msg = e.value.reason
    assert "cannot all be written to .zmx" in msg
    assert "glass SF11 of the Schott catalog needs SCHOTT before HIKARI" in msg
    assert "glass SF11 of the Hikari catalog needs HIKARI before SCHOTT" in msg
    assert "write the lens as .toml instead" in msg


@pytest.mark.parametrize("path", CORPUS_ZMX, ids=lambda p: str(p.relative_to(CORPUS)))
def test_every_corpus_zmx_that_loads_round_trips_through_the_writer(path):
    try:
        lens = quiet(read_zmx, path)
    except PrescriptionError as e:
        # a file the reader refuses (gratings, toroids, unknown glasses, NSC) says why in one
        # line; nothing to write back
        assert e.reason and "\n" not in e.reason
        return
    text = dumps_zmx(lens)
    if "GCAT " in text:
        resolves_as_opticstudio(text, lens)
    back = quiet(loads_zmx, text)
    assert materials(back) == materials(lens)
    assert back == lens
