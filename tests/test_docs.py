"""Docs that cannot rot: every ``orthoscope ...`` example in the README and in each command's
``--help`` epilog runs (in a scratch folder holding copies of the files the examples name) and
exits with status 0; every Python block of the README runs."""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest
from support import run_cli

from orthoscope.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def _readme_blocks(lang: str) -> list[str]:
    text = README.read_text(encoding="utf-8")
    return re.findall(rf"```{lang}\n(.*?)```", text, flags=re.S)


def _commands(text: str) -> list[str]:
    """``orthoscope ...`` command lines of a shell text (continuation lines joined, comments and
    the install line of the quick start dropped)."""
    joined = re.sub(r"\\\n\s*", " ", text)
    out = []
    for line in re.split(r"\n|;\s+", joined):
        line = line.split(" #")[0].strip()
        m = re.search(r"(?:^|&& |: )(orthoscope (?:[^&]|&(?!&))*)", line)
        if m:
            out.append(m.group(1).strip())
    return out


def readme_examples() -> list[str]:
    return [c for block in _readme_blocks("sh") for c in _commands(block)]


def help_examples() -> list[str]:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.choices and isinstance(a.choices, dict))
    out = []
    for p in sub.choices.values():
        out += _commands(p.epilog or "")
    return out


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    d = tmp_path_factory.mktemp("docs")
    shutil.copytree(ROOT / "tests" / "data", d / "tests" / "data")
    shutil.copytree(ROOT / "lenses", d / "lenses")
    return d


def _run(cmd: str, cwd: Path, monkeypatch) -> tuple[int, str]:
    argv = shlex.split(cmd)[1:]
    monkeypatch.chdir(cwd)
    rc, _, err = run_cli(argv)
    return rc, err


def test_examples_were_found():
    assert len(readme_examples()) >= 10
    assert len(help_examples()) >= len(build_parser()._subparsers._group_actions[0].choices) - 1


@pytest.mark.parametrize("cmd", sorted(set(readme_examples() + help_examples())))
def test_example_runs(cmd, scratch, monkeypatch, tmp_path):
    # each example in its own copy of the scratch folder: outputs never exist beforehand
    work = tmp_path / "w"
    shutil.copytree(scratch, work)
    rc, err = _run(cmd, work, monkeypatch)
    assert rc == 0, f"{cmd}\n{err}"


def test_readme_python_blocks_run(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    import matplotlib

    matplotlib.use("Agg")
    for block in _readme_blocks("python"):
        exec(compile(block, "README.md", "exec"), {})


def _task_table() -> list[tuple[str, list[str]]]:
    """(task, Python snippets) of the README's task table (the column after the command line)."""
    text = README.read_text(encoding="utf-8")
    head = "| task | command line | Python (`import orthoscope as osc`) |"
    rows = text.split(head, 1)[1].split("\n\n", 1)[0].strip().splitlines()[1:]
    out = []
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split(" | ")]
        out.append((cells[0], re.findall(r"`([^`]+)`", cells[-1])))
    return out


def test_readme_task_table_runs(monkeypatch, tmp_path):
    """Every Python cell of the task table runs, in order, in one namespace (each task in at most
    three statements after ``import orthoscope as osc``)."""
    monkeypatch.chdir(tmp_path)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tasks = _task_table()
    assert len(tasks) >= 10
    ns: dict = {}
    exec("import orthoscope as osc\nimport matplotlib.pyplot as plt", ns)
    for task, snippets in tasks:
        statements = [s for snip in snippets for s in snip.split("; ")]
        assert 1 <= len(statements) <= 3, task
        for snip in snippets:
            exec(compile(snip, f"README task {task!r}", "exec"), ns)
    plt.close("all")
