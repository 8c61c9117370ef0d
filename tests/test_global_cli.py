"""``orthoscope optimize SPEC --global``: the written lens and its provenance, JSON, progress
(plain lines off a terminal, a tqdm bar on one), the glass map, and the usage errors — all
checked before any long work."""

from __future__ import annotations

import io
import json
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from orthoscope.cli import main
from orthoscope.cli.optimize import GlobalProgress
from orthoscope.plots.glassmap import plot_glass_map
from raytrace.files.native import read_lens, write_lens
from raytrace.optimize import GlassChoice, GlassSettings, SearchProgress, glass_pool
from raytrace.paraxial import paraxial

REFOCUS = """
name = "cooke-refocus"
start = "cooke-triplet-f4"
max_evaluations = 60
variables = [ { kind = "thickness", surface = 6, min = 30, max = 60 } ]
operands = [ { type = "rms_spot", field = 0, plane = "file", weight = 1000 } ]
[global]
starts = 2
hops = 1
perturbation = 0.2
"""


@pytest.fixture
def refocus(tmp_path: Path) -> Path:
    p = tmp_path / "refocus.toml"
    p.write_text(REFOCUS)
    return p


def test_global_writes_the_lens_with_seed_and_merit(refocus: Path, tmp_path: Path, capsys):
    out = tmp_path / "out.toml"
    argv = ["optimize", str(refocus), "-o", str(out), "--global", "--seed", "9", "--hops", "0"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    assert "wrote" in cap.out and "merit per start" in cap.out
    # off a terminal: plain progress lines, one per finished start
    assert "start 0 done (1/2)" in cap.err and "start 1 done (2/2)" in cap.err
    # two starts: the median is their mean (it once printed the larger one)
    done = [
        float(x.split("merit ")[1].split(",")[0]) for x in cap.err.splitlines() if " done " in x
    ]
    line = next(x for x in cap.out.splitlines() if x.startswith("merit per start"))
    median = float(line.split("median ")[1].split(",")[0])
    assert len(done) == 2 and median == pytest.approx(sum(done) / 2, rel=1e-5)
    lens = read_lens(out)
    assert lens.notes.startswith("provenance: derived")
    assert (
        "--global --seed 9 --starts 2' (0 hops per start, local method least_squares)" in lens.notes
    )
    assert lens.surfaces[-1].thickness < paraxial(lens).bfl  # refocused inside the Gaussian


def test_global_json(refocus: Path, tmp_path: Path, capsys):
    out = tmp_path / "out.toml"
    argv = ["optimize", str(refocus), "-o", str(out), "--global", "--json", "--starts", "3"]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["global"] is True and d["seed"] == 0 and d["starts"] == 3
    assert len(d["start_merits"]) == 3 and d["starts_done"] == 3
    assert d["merit"] <= min(d["start_merits"]) * (1 + 1e-9)
    assert d["stopped"] is None and d["written"] == str(out)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--seed", "3"], "add --global"),
        (["--global", "--time", "10 minutes"], "--time: bad duration '10 minutes'"),
        (["--global", "--starts", "0"], "--starts must be at least 1"),
        (["--global", "--glass-map", "m.png"], "has no glass variables"),
    ],
)
def test_global_usage_errors(refocus: Path, tmp_path: Path, capsys, extra, message):
    out = tmp_path / "out.toml"
    assert main(["optimize", str(refocus), "-o", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not out.exists()


def test_existing_output_refused_before_the_run(refocus: Path, tmp_path: Path, capsys):
    out = tmp_path / "out.toml"
    out.write_text("keep me")
    assert main(["optimize", str(refocus), "-o", str(out), "--global"]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == "keep me"


def test_glass_run_and_glass_map(tmp_path: Path, capsys):
    # a singlet whose glass is chosen among three Schott crowns for the least axial spot at f/4
    from raytrace import AIR, Aperture, Field, Lens, Surface
    from raytrace.glass import lookup_glass

    start = tmp_path / "singlet.toml"
    bk7 = lookup_glass("N-BK7", ["Schott"]).material
    write_lens(
        Lens(
            "singlet",
            (Surface(0.0155, 3.0, bk7, stop=True), Surface(-0.0045, 90.0, AIR)),
            Aperture("fnumber", 4.0),
            Field("angle", 1.0),
            image_solve="gaussian",
        ),
        start,
    )
    spec = tmp_path / "glass.toml"
    spec.write_text(
        'start = "singlet.toml"\nmax_evaluations = 40\n'
        'variables = [ { kind = "curvature", surface = 1 }, { kind = "curvature", surface = 2 },\n'
        '  { kind = "glass", surface = 1, glasses = ["N-BK7", "N-LASF9", "N-K5"] } ]\n'
        'operands = [ { type = "efl", target = 50, weight = 100 },\n'
        '  { type = "rms_spot", field = 0, plane = "best", weight = 1000 } ]\n'
        '[glass]\ncatalogs = ["Schott"]\nneighbours = 2\n[global]\nstarts = 2\nhops = 1\n'
    )
    out, gm = tmp_path / "out.toml", tmp_path / "map.png"
    argv = ["optimize", str(spec), "-o", str(out), "--global", "--glass-map", str(gm), "--quiet"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    # a high index bends the rays less: spherical aberration favours N-LASF9 (nd 1.85)
    assert "glass after surface 1: N-LASF9 (Schott" in cap.out
    # the vendor's relative price beside it (Schott's "rel. Price" column of the shipped catalog)
    price = lookup_glass("N-LASF9", ("Schott",)).price
    assert f"relative price {price:g})" in cap.out
    assert cap.err == ""  # --quiet
    lens = read_lens(out)
    assert lens.surfaces[0].material.name == "N-LASF9"
    assert "Glasses: S1 N-LASF9 (Schott)" in lens.notes
    assert gm.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    argv = ["optimize", str(spec), "-o", str(tmp_path / "j.toml"), "--global", "--json"]
    assert main(argv) == 0
    (g,) = json.loads(capsys.readouterr().out)["glasses"]
    assert (g["name"], g["relative_price"]) == ("N-LASF9", price)  # as orthoscope glass --json


def test_glass_map_figure():
    pool = glass_pool(GlassSettings(catalogs=("Schott",)))
    chosen = [GlassChoice(1, "N-BK7", "Schott", 1.5168, 64.17, "current")]
    fig = plot_glass_map(pool.glasses, chosen, title="t")
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert ax.xaxis_inverted()  # Abbe diagram: vd decreasing to the right
    offsets = np.concatenate([c.get_offsets() for c in ax.collections if len(c.get_offsets())])
    assert len(offsets) == len(pool) + 1  # every glass, and the chosen one's marker
    assert any("S1: N-BK7 (Schott)" in t.get_text() for t in ax.texts)
    # a priced choice carries its price in the label (the unpriced one above: none)
    priced = [GlassChoice(1, "N-BK7", "Schott", 1.5168, 64.17, "current", 1.0)]
    ax = plot_glass_map(pool.glasses, priced).axes[0]
    assert any("S1: N-BK7 (Schott, price 1)" in t.get_text() for t in ax.texts)


class _TTY(io.StringIO):
    def isatty(self) -> bool:
        return True


def _event(kind, k, best):
    return SearchProgress(kind, k, -1, best, best, 0, 2, 1.0)


def test_progress_uses_tqdm_on_a_terminal(monkeypatch):
    made = []

    class FakeBar:
        def __init__(self, **kw):
            self.kw, self.n, self.post = kw, 0, ""
            made.append(self)

        def update(self, n):
            self.n += n

        def set_postfix_str(self, s, refresh=True):
            self.post = s

        def close(self):
            self.closed = True

    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    stream = _TTY()
    p = GlobalProgress(2, False, stream=stream)
    p(_event("local", 0, 5.0))
    p(_event("start", 0, 4.0))
    p.close()
    (bar,) = made
    assert bar.kw["total"] == 2 and bar.n == 1 and "4" in bar.post and bar.closed


def test_progress_plain_lines_without_tqdm(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm raises ImportError
    stream = _TTY()
    p = GlobalProgress(2, False, stream=stream)
    p(_event("start", 1, 3.5))
    assert "start 1 done" in stream.getvalue() and "best 3.5" in stream.getvalue()


def test_progress_says_a_start_cut_short_is_not_done(monkeypatch):
    # a start that Ctrl-C or the time budget ended: its best merit by then, not "done"
    monkeypatch.setitem(sys.modules, "tqdm", None)
    stream = io.StringIO()
    p = GlobalProgress(8, False, stream=stream)
    p(SearchProgress("start", 2, 0, 6.59, 6.2, 3, 8, 4.0, "interrupted"))
    p(SearchProgress("start", 5, 0, 7.1, 6.2, 4, 8, 5.0, "time"))
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("start 2 cut short (interrupted; 3/8 ended): merit 6.59, best 6.2")
    assert lines[1].startswith("start 5 cut short (time budget spent; 4/8 ended): merit 7.1")
    assert not any("done" in x for x in lines)


def _interrupt_in_start(monkeypatch, start: int) -> list:
    """Ctrl-C (a KeyboardInterrupt from the progress callback) in the first local run of
    ``start``, once: the list that holds the event it was raised at (clear it to re-arm)."""
    real, hit = GlobalProgress.__call__, []

    def call(self, ev):
        real(self, ev)
        if ev.event == "local" and ev.start == start and not hit:
            hit.append(ev)
            raise KeyboardInterrupt

    monkeypatch.setattr(GlobalProgress, "__call__", call)
    return hit


def test_interrupted_global_counts_the_starts_cut_short(
    refocus: Path, tmp_path: Path, monkeypatch, capsys
):
    # Ctrl-C (in this process: one worker) during start 1's first local run: start 0 finished,
    # start 1 is cut short with its best so far; the log and the notes tell them apart
    out = tmp_path / "out.toml"
    hit = _interrupt_in_start(monkeypatch, 1)
    argv = ["optimize", str(refocus), "-o", str(out), "--global", "--seed", "9", "--starts", "3"]
    assert main([*argv, "--json"]) == 130  # --json: no progress lines (the text run below)
    cap = capsys.readouterr()
    d = json.loads(cap.out)
    assert d["stopped"] == "interrupted" and d["starts_done"] == 2 and d["starts_stopped"] == 1
    assert d["message"].startswith("stopped (interrupted) with 1 of 3 starts finished, 1 cut short")
    notes = read_lens(out).notes
    assert "; 1 of 3 starts finished, 1 cut short), " in notes
    assert "Search stopped early (interrupted)" in notes
    hit.clear()
    out.unlink()
    assert main(argv) == 130
    err = capsys.readouterr().err.splitlines()
    assert "start 0 done (1/3)" in err[0]
    assert err[1].startswith("start 1 cut short (interrupted; 2/3 ended): merit ")
    assert err[-1] == (
        "orthoscope optimize: interrupted with 1 of 3 starts finished, 1 cut short; the best "
        "design found was kept"
    )


def test_interrupted_global_says_how_far_it_got_not_not_converged(
    refocus: Path, tmp_path: Path, monkeypatch, capsys
):
    # Ctrl-C in start 0's first local run, the spec's merit goal out of reach: the run said
    # "best merit ... from start 0 of 0/2 starts finished and 1 cut short" and its notes "NOT
    # CONVERGED" beside "stopped early". It was stopped, not failed: it says how many starts
    # finished of how many, that it was stopped, and keeps the best design found.
    spec = tmp_path / "goal.toml"
    spec.write_text(
        REFOCUS.replace("max_evaluations = 60", "max_evaluations = 60\nmerit_goal = 1e-12")
    )
    out = tmp_path / "out.toml"
    _interrupt_in_start(monkeypatch, 0)
    argv = ["optimize", str(spec), "-o", str(out), "--global", "--seed", "9"]
    assert main(argv) == 130
    cap = capsys.readouterr()
    first = cap.out.splitlines()[0]
    assert first.startswith(
        "cooke-refocus: stopped (interrupted) with 0 of 2 starts finished, 1 cut short; best merit "
    ), first
    assert "from start 0, cut short (seed 9); above the merit goal 1e-12" in first, first
    assert "0/2" not in cap.out + cap.err and "of 0 of" not in cap.out
    assert cap.err.splitlines()[-1] == (
        "orthoscope optimize: interrupted with 0 of 2 starts finished, 1 cut short; the best "
        "design found was kept"
    )
    assert f"wrote {out}" in cap.out
    notes = read_lens(out).notes
    assert "NOT CONVERGED" not in notes
    assert (
        "the best design found (start 0, cut short; 0 of 2 starts finished, 1 cut short)" in notes
    )
    assert "Search stopped early (interrupted): the best design found by then." in notes
    assert "It does not meet the spec's goal: merit " in notes and "merit goal 1e-12." in notes
    # the design kept is the one the run reports
    merit = float(first.split("best merit ")[1].split()[0])
    assert f"merit {merit:.6g} is above" in notes


def test_help_says_method_works_with_global(capsys):
    assert main(["optimize", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    method = text.split("--method {least_squares,minimax} ")[1].split("--max-evaluations N")[0]
    assert "not with --global" not in method  # --global --method minimax runs minimax locally
    assert "with --global, the method of every local run" in method
