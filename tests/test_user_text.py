"""What a person reads carries no internal tracker references ("as given in orthoscope issue 2",
"issues 4 and 19"): the strings of the bundled files (lens sources and notes, which `orthoscope
lenses` and `orthoscope report` print), the bundled data files, every --help page and the lens
list. Comments of the files and code are not checked (nobody reads them in a command's output).
Also: under an ASCII-only locale the tables keep their columns (docs/design.md, "Errors": the
symbols are written in ASCII, ``α`` as ``alpha``, and the layout is measured on that text)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tomllib

import pytest
from support import ROOT, run_cli

from orthoscope.cli import COMMANDS, build_parser

TRACKER = re.compile(r"\bissues?[ -]#?\d", re.IGNORECASE)


def _strings(value):
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for v in value.values():
            yield from _strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from _strings(v)


@pytest.mark.parametrize(
    "path", sorted((ROOT / "lenses").rglob("*.toml")), ids=lambda p: p.relative_to(ROOT).as_posix()
)
def test_bundled_toml_strings(path):
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    bad = [s[:80] for s in _strings(data) if TRACKER.search(s)]
    assert bad == []


def test_bundled_data_files():
    files = [p for suffix in ("*.csv", "*.yml") for p in (ROOT / "lenses").rglob(suffix)]
    assert files
    for p in files:
        assert not TRACKER.search(p.read_text(encoding="utf-8")), p


def _help_pages():
    from orthoscope.cli.camera import ACTIONS, action_parser

    parser = build_parser()
    yield "orthoscope", parser.format_help()
    sub = parser._subparsers._group_actions[0].choices
    for name in COMMANDS:
        yield name, sub[name].format_help()
    for form in ACTIONS:
        yield f"camera {form}", action_parser(form).format_help()


def test_help_pages():
    pages = dict(_help_pages())
    assert len(pages) >= len(COMMANDS) + 4
    assert [name for name, text in pages.items() if TRACKER.search(text)] == []


def test_lens_list():
    for argv in (["lenses"], ["lenses", "--json"]):
        rc, out, err = run_cli(argv)
        assert rc == 0, err
        assert "cooke-triplet-f4" in out and not TRACKER.search(out)


def _ascii_run(argv: list[str]) -> list[str]:
    """stdout lines of ``orthoscope argv`` in a fresh process under ``LC_ALL=C
    PYTHONIOENCODING=ascii`` (the command line then writes the tables' symbols in ASCII)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("LC_", "LANG", "PYTHONUTF8"))}
    env.update(LC_ALL="C", PYTHONIOENCODING="ascii", PYTHONUTF8="0")
    r = subprocess.run(
        [sys.executable, "-m", "orthoscope", *argv], env=env, cwd=ROOT, capture_output=True
    )
    assert r.returncode == 0, r.stderr.decode("ascii", "replace")
    return r.stdout.decode("ascii").splitlines()  # ASCII only, or this raises


@pytest.mark.parametrize("layout", ["rows", "paper"])
def test_ascii_table_columns_line_up(layout):
    # The header "alpha (deg)" (11 characters; "α (deg)" is 7) was laid out before the ASCII
    # substitution: the rule stayed 7 dashes wide and every column after it moved by 4.
    lines = _ascii_run(["distortion", "topogon-like-pestrecov", "--table-layout", layout])
    i = next(k for k, line in enumerate(lines) if line.startswith("alpha (deg)"))
    header, rule = lines[i], lines[i + 1]
    assert set(rule) <= {"-", " "} and rule.startswith("-")
    table = [header, rule] + lines[i + 2 : i + 6]
    assert [len(line.rstrip()) for line in table] == [len(rule)] * len(table)
    if layout == "rows":
        # each dash run of the rule ends where its column's label and numbers end
        ends = [m.end() for m in re.finditer(r"-+", rule)]
        for line in table:
            assert all(line[e - 1] != " " and line[e : e + 1] in ("", " ") for e in ends), line


def test_ascii_variation_gamma_column_lines_up():
    # "γ" right-aligned in 9 columns became "gamma" with its 8 spaces: 4 past the numbers
    lines = _ascii_run(
        ["variation", "--lens", "cooke-triplet-f4", "--focus", "12x", "--objects", "8x,16x"]
        + ["--n-r", "8"]
    )
    i = next(k for k, line in enumerate(lines) if line.startswith("Brown gamma_ss'"))
    header, rows = lines[i + 1], lines[i + 2 : i + 4]
    assert header.endswith(" gamma")
    assert [len(r) for r in rows] == [len(header)] * 2


@pytest.mark.parametrize(
    "argv",
    [
        ["glass", "N-BK7"],  # λ, Σ, sub- and superscripts of the dispersion formula
        ["variation", "--lens", "cooke-triplet-f4", "--focus", "12x", "--objects", "8x,16x"],
        ["pupils", "cooke-triplet-f4"],
        ["report", "cooke-triplet-f4", "--sensor", "24x16"],
    ],
)
def test_ascii_output_has_no_unmapped_symbol(argv):
    # a symbol missing from the ASCII map printed as "?" (λ and σ did: "? (nm)", "?_g"; the
    # glass formula's "Σ₁³ Kᵢλ²" was "sum?^3 K?lambda^2")
    lines = _ascii_run(argv)
    assert not [line for line in lines if "?" in line]
    if argv[0] == "glass":
        assert "n^2 - 1 = sum_1^3 K_i lambda^2/(lambda^2 - L_i)   [lambda in um]" in "\n".join(
            lines
        )
