"""Ctrl-C during a local run of ``orthoscope optimize`` (damped least squares, minimax,
``--split auto``): the best design evaluated so far is kept — returned by the API with
``stopped == "interrupted"``, written by the CLI with its notes marked, one line on stderr and
exit status 130, as ``--global`` does. A Ctrl-C before the start lens is evaluated keeps nothing.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from support import (
    cooke_multimodal_spec_text,
    cooke_split_spec,
    interrupt_group,
    singlet,
    singlet_spec,
)

import raytrace.optimize.solver as solver
from orthoscope.cli import main
from orthoscope.cli.optimize import _Progress
from raytrace.files import save_lens
from raytrace.files.library import load_lens
from raytrace.files.native import read_lens
from raytrace.optimize import evaluate, merit, optimize, read_spec, scan_splits

ROOT = Path(__file__).resolve().parents[1]

METHODS = ["least_squares", "minimax"]


def _spec_file(tmp_path: Path) -> Path:
    """The singlet-bending problem (tests/support.py) as a spec file with its start lens."""
    save_lens(singlet(), tmp_path / "start.toml")
    p = tmp_path / "bend.toml"
    p.write_text(
        'name = "bend"\nstart = "start.toml"\nmax_evaluations = 400\n'
        'variables = [ { kind = "curvature", surface = 1 }, { kind = "curvature", surface = 2 } ]\n'
        'operands = [ { type = "efl", target = 100, weight = 100 },\n'
        '  { type = "rms_spot", field = 0, plane = "best", target = 0, weight = 1000 } ]\n',
        encoding="utf-8",
    )
    return p


def _interrupt_after(n_eval: int):
    """A progress callback that records the merits and raises KeyboardInterrupt (what Ctrl-C
    raises in the main thread) at evaluation ``n_eval``."""
    seen: list[float] = []

    def progress(n, m, worst) -> None:
        seen.append(m)
        if n >= n_eval:
            raise KeyboardInterrupt

    return progress, seen


def _kept(fn, *args, **kw):
    """``fn(*args, **kw)``, a KeyboardInterrupt escaping it a test failure (not pytest's stop)."""
    try:
        return fn(*args, **kw)
    except KeyboardInterrupt:
        pytest.fail("the KeyboardInterrupt escaped: what was evaluated is lost")


# ----------------------------------------------------------------------------- the API
@pytest.mark.parametrize("method", METHODS)
def test_keyboard_interrupt_returns_the_best_design_so_far(method):
    lens, spec = singlet(), singlet_spec()
    progress, seen = _interrupt_after(25)
    res = _kept(optimize, lens, spec, progress, method=method)
    assert res.stopped == "interrupted" and not res.converged
    assert "interrupted" in res.message
    assert res.evaluations == 25
    # the design returned is the best one evaluated (minimax: by its merit φ, which is the max
    # weighted residual without bound operands)
    assert res.merit <= min(seen) * (1 + 1e-12) and res.merit < res.merit_start
    vals = evaluate(res.lens, spec.operands)
    got = merit(vals) if method == "least_squares" else max(abs(v.residual) for v in vals)
    assert got == pytest.approx(res.merit, rel=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_keyboard_interrupt_in_the_start_evaluation_propagates(method, monkeypatch):
    # no design evaluated yet: nothing to return
    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(solver, "evaluate", interrupted)
    with pytest.raises(KeyboardInterrupt):
        optimize(singlet(), singlet_spec(), method=method)


def _ctrl_c_in_the_second_run(monkeypatch) -> None:
    """Ctrl-C at the 10th evaluation of the second local run of --split auto / scan_splits."""
    import raytrace.optimize.elements as elements

    real, runs = elements.optimize, []

    def run(lens, spec, progress=None, **kw):
        runs.append(1)
        if len(runs) == 2:
            progress = _interrupt_after(10)[0]
        return real(lens, spec, progress, **kw)

    monkeypatch.setattr(elements, "optimize", run)


def test_scan_splits_ends_with_the_interrupted_trial(monkeypatch):
    lens = load_lens("cooke-triplet-f4")
    spec = cooke_split_spec(20)
    _ctrl_c_in_the_second_run(monkeypatch)
    trials = _kept(scan_splits, lens, spec)
    # the first element's run finished, the second was interrupted, the third never ran
    assert [t.surface for t in trials] == [1, 3]
    assert trials[0].result.stopped == ""
    assert trials[1].result.stopped == "interrupted" and math.isfinite(trials[1].merit)


def test_scan_splits_keeps_finished_trials_when_ctrl_c_comes_between_runs(monkeypatch):
    # a Ctrl-C outside a run's own loop (here: the second run's start evaluation, which
    # propagates from optimize() by design) threw away the finished first trial
    import raytrace.optimize.elements as elements

    lens = load_lens("cooke-triplet-f4")
    spec = cooke_split_spec(20)
    real, runs = elements.optimize, []

    def run(lens, spec, progress=None, **kw):
        runs.append(1)
        if len(runs) == 2:
            raise KeyboardInterrupt
        return real(lens, spec, progress, **kw)

    monkeypatch.setattr(elements, "optimize", run)
    trials = _kept(scan_splits, lens, spec)
    assert [t.surface for t in trials] == [1, 3]
    assert trials[0].result is not None and trials[0].stopped == ""
    assert trials[1].result is None and trials[1].stopped == "interrupted"
    # before any run finished there is nothing to keep: the Ctrl-C propagates
    runs.clear()
    runs.append(1)  # the next call is the "second"
    with pytest.raises(KeyboardInterrupt):
        scan_splits(lens, spec)


# ----------------------------------------------------------------------------- the CLI
@pytest.mark.parametrize("method", METHODS)
def test_cli_interrupted_writes_the_best_design_marked(method, tmp_path, monkeypatch, capsys):
    spec = _spec_file(tmp_path)
    out = tmp_path / "out.toml"
    real, seen = _Progress.__call__, []

    def call(self, n, m, worst):
        seen.append(m)
        real(self, n, m, worst)
        if n == 30:
            raise KeyboardInterrupt  # Ctrl-C, as the CLI's SIGINT handler raises it

    monkeypatch.setattr(_Progress, "__call__", call)
    rc = main(["optimize", str(spec), "-o", str(out), "--method", method, "--json"])
    cap = capsys.readouterr()
    assert rc == 130, cap.err  # as --global after Ctrl-C
    assert cap.err.strip().splitlines()[-1] == (
        "orthoscope optimize: interrupted; the best design found was kept"
    )
    d = json.loads(cap.out)
    assert d["stopped"] == "interrupted" and d["converged"] is False
    assert d["written"] == str(out) and d["evaluations"] == 30
    lens = read_lens(out)
    assert "Run stopped early (interrupted) before converging" in lens.notes
    assert "NOT CONVERGED" not in lens.notes  # said once, in the provenance
    # the written design is the best evaluated, with the merit the notes give
    assert d["merit"] <= min(seen) * (1 + 1e-12) and d["merit"] < d["merit_start"]
    ops = read_spec(spec).operands
    vals = evaluate(lens, ops)
    got = merit(vals) if method == "least_squares" else max(abs(v.residual) for v in vals)
    assert got == pytest.approx(d["merit"], rel=1e-9)
    assert f"{d['merit']:.9g}" in lens.notes


def test_cli_interrupted_before_any_evaluation_writes_nothing(tmp_path, monkeypatch, capsys):
    spec = _spec_file(tmp_path)
    out = tmp_path / "out.toml"

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(solver, "evaluate", interrupted)
    rc = main(["optimize", str(spec), "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 130 and err.strip() == "orthoscope optimize: interrupted"
    assert not out.exists()


def test_cli_split_auto_interrupted_keeps_the_best_trial(tmp_path, monkeypatch, capsys):
    save_lens(load_lens("cooke-triplet-f4"), tmp_path / "start.toml")
    spec = tmp_path / "s.toml"
    text = 'start = "start.toml"\nmax_evaluations = 20\nvariables = ['
    text += ", ".join(f'{{ kind = "curvature", surface = {k} }}' for k in range(1, 7)) + " ]\n"
    text += 'operands = [ { type = "efl", target = 50, weight = 100 },\n'
    text += '  { type = "rms_spot", field = 0, plane = "best", target = 0, weight = 1000 } ]\n'
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "best.toml"
    _ctrl_c_in_the_second_run(monkeypatch)
    rc = main(["optimize", str(spec), "-o", str(out), "--split", "auto"])
    err = capsys.readouterr().err
    assert rc == 130, err
    assert "--split 1: merit" in err and "--split 3: merit" in err and "--split 5" not in err
    assert err.strip().splitlines()[-1].endswith("interrupted; the best design found was kept")
    notes = read_lens(out).notes
    assert "(best of --split auto" in notes and "interrupted at element 3" in notes


@pytest.mark.parametrize("method", METHODS)
def test_cli_sigint_during_a_local_run_writes_the_best_design(tmp_path: Path, method):
    # A real Ctrl-C: SIGINT to the command's process group (tests/support.py), a second and a
    # half into a run that takes half a minute (the Cooke triplet's six curvatures against the
    # EFL and three RMS spots; its progress line comes at the first evaluation).
    import time

    spec = tmp_path / "cooke.toml"
    spec.write_text(cooke_multimodal_spec_text(100000))
    out = tmp_path / "best.toml"
    argv = ["optimize", str(spec), "-o", str(out), "--method", method]

    def ready(line: str) -> bool:
        if line.startswith("eval"):
            time.sleep(1.5)
            return True
        return False

    before, rc, stdout, stderr = interrupt_group(argv, cwd=ROOT, ready=ready)
    assert rc == 130, stderr
    assert "Traceback" not in stderr
    assert stderr.strip() == "orthoscope optimize: interrupted; the best design found was kept"
    assert out.is_file() and f"wrote {out}" in stdout
    notes = read_lens(out).notes
    assert "Run stopped early (interrupted) before converging" in notes
    # the design improved on the start, and the lens written has the merit the notes give
    merit_of = float(
        notes.split("; merit " if method == "least_squares" else "residual ")[1].split()[0]
    )
    start = float(notes.split("(start ")[1].split(")")[0])
    assert merit_of < start
    vals = evaluate(read_lens(out), read_spec(spec).operands)
    got = merit(vals) if method == "least_squares" else max(abs(v.residual) for v in vals)
    assert got == pytest.approx(merit_of, rel=1e-8)
