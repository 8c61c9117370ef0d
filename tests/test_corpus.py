"""The real-file corpus: every published lens file in tests/data/corpus either reads or is refused
with a PrescriptionError — never another exception, never a hang.

The files come from lens vendors and open projects as shipped in PyPI distributions; each one's
package, version, path inside the distribution and licence are in tests/data/corpus/SOURCES.md.
How many of them read (the baseline fraction and the refusal groups) is measured by
``python benchmarks/corpus.py``; this test only guards against reader crashes.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest
from support import Hang, time_limit

import orthoscope as osc
from raytrace.errors import PrescriptionError

CORPUS = Path(__file__).resolve().parent / "data" / "corpus"
SOURCES = CORPUS / "SOURCES.md"
LENS_SUFFIXES = (".zmx", ".seq", ".len", ".zar")  # same list as benchmarks/corpus.py
TIME_LIMIT_S = 30.0  # per file; every file reads in well under a second today
SIZE_BUDGET = 5 * 1024 * 1024  # bytes, the whole corpus

FILES = sorted(p for p in CORPUS.rglob("*") if p.is_file() and p.suffix.lower() in LENS_SUFFIXES)

#: files that crash the reader with something other than PrescriptionError: path relative to the
#: corpus -> the bug. Each is an xfail(strict=True), so a fix makes the test fail until it is
#: removed from here. Empty: no file crashes the reader today.
KNOWN_CRASHES: dict[str, str] = {}


def _rel(p: Path) -> str:
    return p.relative_to(CORPUS).as_posix()


def _params():
    for p in FILES:
        marks = []
        if _rel(p) in KNOWN_CRASHES:
            marks.append(pytest.mark.xfail(strict=True, reason=KNOWN_CRASHES[_rel(p)]))
        yield pytest.param(p, id=_rel(p), marks=marks)


def test_corpus_present():
    # the corpus holds both main formats and stays within its size budget
    suffixes = {p.suffix.lower() for p in FILES}
    assert {".zmx", ".seq"} <= suffixes
    assert len(FILES) >= 50
    size = sum(p.stat().st_size for p in CORPUS.rglob("*") if p.is_file())
    assert size < SIZE_BUDGET


@pytest.mark.parametrize("path", list(_params()))
def test_reads_or_refuses_cleanly(path):
    try:
        with warnings.catch_warnings(), time_limit(TIME_LIMIT_S):
            warnings.simplefilter("ignore")  # skipped-command warnings are not the subject here
            lens = osc.load_lens(path)
    except PrescriptionError as e:
        assert str(e).strip(), "a refusal must say why"
        return
    except Hang:
        pytest.fail(f"reading {_rel(path)} took more than {TIME_LIMIT_S:g} s")
    assert isinstance(lens, osc.Lens)
    assert len(lens.surfaces) >= 1


def test_every_file_has_a_source_row():
    # SOURCES.md names every corpus file (first column, as `path`), and names no missing file
    text = SOURCES.read_text(encoding="utf-8")
    listed = set(re.findall(r"^\|\s*`([^`]+)`\s*\|", text, flags=re.MULTILINE))
    on_disk = {_rel(p) for p in FILES}
    assert on_disk - listed == set(), "corpus files without a SOURCES.md row"
    assert listed - on_disk == set(), "SOURCES.md rows without a corpus file"
