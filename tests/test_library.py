"""The bundled lens library: every lens loads, reproduces its source's published paraxial data,
and is found by name from any working directory."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orthoscope.report.lenses import format_lens_table, lens_infos_to_dict
from raytrace.errors import PrescriptionError
from raytrace.files.library import (
    bundled_names,
    library_dir,
    list_lenses,
    load_lens,
    resolve_lens_path,
)
from raytrace.files.native import PROVENANCES, provenance
from raytrace.paraxial import paraxial

REPO_LENSES = Path(__file__).resolve().parent.parent / "lenses"

# Published paraxial data, tolerance = half a unit of the last published digit.
#   name: (EFL, EFL tolerance, BFL, BFL tolerance, source)
PUBLISHED = {
    # US 2,031,792 Fig. 1 (public lens-test fixture of this patent): EFL 66.04, BFL 51.94.
    "topogon-us2031792-fig1": (66.04, 0.005, 51.94, 0.005),
    # Cooke triplet 50 mm f/4 reference values (issue 2): EFL 50.000, BFL 43.080.
    "cooke-triplet-f4": (50.000, 0.0005, 43.080, 0.0005),
    # FR 1.066.698 Example 1: f = 99.89, back focal distance 80.55.
    "tessar-fr1066698": (99.89, 0.005, 80.55, 0.005),
    # the same patent lens; its infinity configuration (the base lens) is Example 1 unchanged
    "tessar-fr1066698-inner-focus": (99.89, 0.005, 80.55, 0.005),
    # US 2,518,719 Example 2: EF = 100 (stated as a round figure), BFD = 89.01.
    "wide-field-ektar-us2518719": (100.0, 0.5, 89.01, 0.005),
    # DE 975 637: f' = 100 (round figure), s' = 73.4.
    "super-angulon-de975637": (100.0, 0.5, 73.4, 0.05),
}


def test_library_holds_the_bundled_files() -> None:
    assert library_dir().resolve() == REPO_LENSES.resolve()
    assert bundled_names() == sorted(p.stem for p in REPO_LENSES.glob("*.toml"))
    # every bundled lens is either checked against published data here, or is one of our derived
    # designs, checked against its design targets in tests/test_design_*.py
    assert set(PUBLISHED) <= set(bundled_names())
    assert set(bundled_names()) - set(PUBLISHED) <= DESIGNED


DESIGNED = {
    "topogon-like-pestrecov",
    "topogon-like-spherical",
    "topogon-like-spherical-heights",
    "twinplex-like-55-525",
}


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_bundled_lens_matches_published_paraxial_data(name: str) -> None:
    efl, efl_tol, bfl, bfl_tol = PUBLISHED[name]
    lens = load_lens(name)
    par = paraxial(lens)
    assert abs(par.efl - efl) <= efl_tol, (name, par.efl)
    assert abs(par.bfl - bfl) <= bfl_tol, (name, par.bfl)
    # the file's image plane is the solved paraxial focus
    assert lens.image_solve == "gaussian"
    assert lens.surfaces[-1].thickness == pytest.approx(par.bfl, abs=1e-9)


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_bundled_lens_is_documented(name: str) -> None:
    lens = load_lens(name)
    assert lens.source, name
    assert provenance(lens) in PROVENANCES
    assert lens.n_surfaces >= 4
    text = resolve_lens_path(name).read_text()
    assert "mm from the object plane to the first vertex" in text


def test_list_lenses() -> None:
    infos = list_lenses()
    assert [i.name for i in infos] == bundled_names()
    for i in infos:
        assert i.path.is_file()
        assert i.efl == pytest.approx(paraxial(load_lens(i.name)).efl, rel=1e-12)
        assert i.kind in PROVENANCES
        assert i.fnumber is not None and i.fnumber > 0
    table = format_lens_table(infos)
    for i in infos:
        assert i.name in table
    data = json.loads(json.dumps(lens_infos_to_dict(infos)))
    assert data[0]["name"] == infos[0].name


def test_load_by_name_from_another_directory(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    a = load_lens("topogon-us2031792-fig1")
    b = load_lens("topogon-us2031792-fig1.toml")
    assert a == b
    assert Path(a.path).resolve() == (REPO_LENSES / "topogon-us2031792-fig1.toml").resolve()


def test_existing_path_wins_over_bundled_name(tmp_path: Path, monkeypatch) -> None:
    text = (REPO_LENSES / "cooke-triplet-f4.toml").read_text()
    local = text.replace('name       = "Cooke triplet 50 mm f/4"', 'name       = "my copy"')
    (tmp_path / "cooke-triplet-f4.toml").write_text(local)
    monkeypatch.chdir(tmp_path)
    assert load_lens("cooke-triplet-f4.toml").name == "my copy"
    assert load_lens("cooke-triplet-f4").name == "Cooke triplet 50 mm f/4"  # no such file
    assert load_lens(tmp_path / "cooke-triplet-f4.toml").name == "my copy"


@pytest.mark.parametrize(
    ("query", "suggestion"),
    [
        ("topogon-us2031792", "topogon-us2031792-fig1"),
        ("tesar", "tessar-fr1066698"),
        ("cooke-triplet-f5.toml", "cooke-triplet-f4"),
    ],
)
def test_unknown_name_lists_the_library(query: str, suggestion: str) -> None:
    with pytest.raises(PrescriptionError) as e:
        resolve_lens_path(query)
    msg = str(e.value)
    assert msg.startswith(f"{query}: no such file or bundled lens")
    assert "did you mean" in msg and f"'{suggestion}'" in msg.split("did you mean")[1].split("?")[0]
    for name in bundled_names():
        assert name in msg


def test_directory_is_not_a_lens(tmp_path: Path) -> None:
    with pytest.raises(PrescriptionError, match="is a directory"):
        load_lens(tmp_path)
