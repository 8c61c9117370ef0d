"""What a person reads carries no internal tracker references ("as given in orthoscope issue 2",
"issues 4 and 19"): the strings of the bundled files (lens sources and notes, which `orthoscope
lenses` and `orthoscope report` print), the bundled data files, every --help page and the lens
list. Comments of the files and code are not checked (nobody reads them in a command's output)."""

from __future__ import annotations

import re
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
