"""``orthoscope tolerance`` end to end: text, --json, the plot, resume after an interruption,
one-line errors (docs/tolerance.md; the science is tested in tests/test_tolerance_*.py).

The numbers checked here are computed independently of the command's formatting: the yield is
recounted from the per-lens curves of the API run with the same seed, the JSON summary is
compared with the API's own summary of the same run, and a resumed run must give the summary of
an uninterrupted one bit for bit (issue 15: "the same seed gives a bit-identical summary ...
after a resumed interruption").
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support import run_cli

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "lenses" / "tolerances" / "cooke-triplet-f4.toml"
LENS = "cooke-triplet-f4"
FIELDS = "0,10,20"
BASE = ["tolerance", LENS, str(SPEC), "--fields", FIELDS, "--quiet"]


@pytest.fixture(scope="module")
def api_run():
    """The same run through the API (seed 3, 48 instances, chunks of 16)."""
    from distortion.tolerance import monte_carlo
    from raytrace.files.library import load_lens
    from raytrace.tolerance import read_tolerance_spec

    lens = load_lens(LENS)
    spec = read_tolerance_spec(SPEC)
    return monte_carlo(lens, spec, 48, seed=3, fields_deg=np.array([0.0, 10.0, 20.0]),
                       chunk_size=16)  # fmt: skip


def test_text_run_reports_envelope_spreads_and_yield(api_run):
    rc, out, err = run_cli(BASE + ["--samples", "48", "--seed", "3", "--chunk", "16",
                                   "--limit", "20@20"])  # fmt: skip
    assert rc == 0, err
    assert "48 lenses" in out and "seed 3" in out
    assert api_run.generator in out
    assert "Fc (calibrated)" in out and "P1 raw" in out
    # the yield sentence, recounted from the API run's curves at the traced field 20 deg
    o = api_run.outputs
    ok = np.asarray(o.ok)
    raw = np.mean(np.abs(o.D_um[ok, 2]) < 20.0)
    cal = np.mean(np.abs(o.D_cal_um[ok, 2]) < 20.0)
    assert f"{100 * raw:.1f} % of lenses have |D| < 20 µm at 20°" in out
    assert f"({100 * cal:.1f} % after calibration)" in out


def test_json_is_the_api_summary_plus_yield(api_run):
    rc, out, err = run_cli(BASE + ["--samples", "48", "--seed", "3", "--chunk", "16",
                                   "--limit", "15@10", "--json"])  # fmt: skip
    assert rc == 0, err
    d = json.loads(out)
    mc = d["monte_carlo"]
    y = mc.pop("yield")
    from orthoscope.report.jsonout import jsonable

    assert mc == jsonable(api_run.summary())
    o = api_run.outputs
    ok = np.asarray(o.ok)
    assert y[0]["limit_um"] == 15.0 and y[0]["field_deg"] == 10.0
    assert y[0]["fraction"] == pytest.approx(np.mean(np.abs(o.D_um[ok, 1]) < 15.0), abs=1e-12)


def test_sensitivity_table_lists_every_item_and_the_rss():
    from raytrace.tolerance import read_tolerance_spec

    rc, out, err = run_cli(BASE + ["--sensitivity"])
    assert rc == 0, err
    assert "Sensitivity of" in out and "RSS" in out
    for name in read_tolerance_spec(SPEC).names():
        assert name in out
    rc, out, err = run_cli(BASE + ["--sensitivity", "--json"])
    assert rc == 0, err
    s = json.loads(out)["sensitivity"]
    ranked = s["outputs"][s["ranked_by"]]["items"]
    worst = [max(abs(r["delta_at_min"] or 0.0), abs(r["delta_at_max"] or 0.0)) for r in ranked]
    assert worst == sorted(worst, reverse=True)  # ranked by the largest change


def test_plot_is_written_and_never_overwritten_without_force(tmp_path):
    png = tmp_path / "tol.png"
    rc, out, err = run_cli(BASE + ["--samples", "16", "--plot", str(png)])
    assert rc == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    before = png.read_bytes()
    rc, out, err = run_cli(BASE + ["--samples", "16", "--plot", str(png)])
    assert rc == 2 and "--force" in err and len(err.strip().splitlines()) == 1
    assert png.read_bytes() == before


def test_interrupted_run_keeps_chunks_and_resumes_bit_identical(tmp_path, monkeypatch):
    import orthoscope.cli.tolerance as cli

    run_dir = tmp_path / "run"
    argv = BASE + ["--samples", "64", "--seed", "5", "--chunk", "16", "-o", str(run_dir),
                   "--json"]  # fmt: skip
    real_call = cli.Progress.__call__

    def interrupt_after_two_chunks(self, done, total):
        real_call(self, done, total)
        if done >= 32:
            raise KeyboardInterrupt

    monkeypatch.setattr(cli.Progress, "__call__", interrupt_after_two_chunks)
    rc, out, err = run_cli(argv)
    assert rc == 130, err
    assert "resume" in err and len(err.strip().splitlines()) == 1
    manifest = json.loads((run_dir / "manifest.json").read_text())
    assert 2 <= len(manifest["done"]) < 4
    monkeypatch.setattr(cli.Progress, "__call__", real_call)
    rc, out, err = run_cli(argv)
    assert rc == 0, err
    resumed = json.loads(out)["monte_carlo"]
    rc, out, err = run_cli(BASE + ["--samples", "64", "--seed", "5", "--chunk", "32", "--json"])
    assert rc == 0, err
    fresh = json.loads(out)["monte_carlo"]
    assert resumed == fresh  # bit-identical after resumption and with another chunk size


@pytest.mark.parametrize(
    "text,words",
    [
        ('tolerances = [ { type = "TWOBBLE", surface = 1, limit = 0.1 } ]', "TWOBBLE"),
        ('tolerances = [ { type = "TRAD", surface = 40, limit = 0.1 } ]', "surface 40"),
        ("tolerances = [ { type = ", "TOML"),
    ],
    ids=["unknown-type", "no-such-surface", "broken-toml"],
)
def test_bad_spec_is_one_line_exit_2(tmp_path, text, words):
    bad = tmp_path / "bad.toml"
    bad.write_text(text + "\n")
    rc, out, err = run_cli(["tolerance", LENS, str(bad), "--sensitivity"])
    assert rc == 2
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert words in err and "bad.toml" in err


@pytest.mark.parametrize(
    "extra,words",
    [
        (["--dask", "localhost"], "tcp://HOST:PORT"),
        (["--limit", "20"], "UM@DEG"),
        (["--limit", "20@80"], "beyond"),
        (["--samples", "0"], "at least 1"),
        (["--sensitivity", "-o", "x"], "Monte Carlo"),
    ],
)
def test_bad_flags_are_one_line_exit_2(extra, words):
    rc, out, err = run_cli(BASE + extra)
    assert rc == 2, err
    assert words in err and len(err.strip().splitlines()) == 1


def test_compensator_choices_are_the_science_packages():
    import orthoscope.cli.tolerance as cli
    from raytrace.tolerance import COMPENSATORS

    assert cli.COMPENSATORS == COMPENSATORS


def test_ctrl_c_on_a_dask_run_stops_once_and_keeps_the_chunks(tmp_path):
    # A real Ctrl-C in a terminal: SIGINT to the whole process group, the LocalCluster's worker
    # processes included. They leave it to the command (raytrace.executors.dask_setup): one
    # line, exit 130, no Dask traceback or log line, the finished chunks on disk.
    pytest.importorskip("distributed")
    from support import interrupt_group

    out = tmp_path / "run"
    progress = []

    def ready(line: str) -> bool:  # two progress lines: chunks have come back
        progress.append(line.startswith("tolerance: ") and "instances" in line)
        return sum(progress) >= 2

    argv = ["tolerance", "cooke-triplet-f4", str(SPEC), "--samples", "200000", "--dask",
            "local:2", "-o", str(out)]  # fmt: skip
    _, rc, _, err = interrupt_group(argv, cwd=ROOT, ready=ready)
    assert rc == 130, err
    rest = [
        x for x in err.splitlines() if not x.startswith(("tolerance: ", "orthoscope: compiling"))
    ]
    assert len(rest) == 1 and "interrupted; the finished chunks are kept" in rest[0], err
    assert sorted(out.glob("chunk-*.npz")), "no finished chunk kept"


@pytest.mark.parametrize("run", [["--sensitivity"], ["--samples", "4", "--quiet"]])
def test_a_lens_file_object_inside_the_front_focal_length_is_exit_2(tmp_path, run):
    # the lens file's object 2 mm from the first vertex (inside the front focal length: a
    # virtual image) ran to exit 0 with numbers measured on no real image
    src = (ROOT / "lenses" / "cooke-triplet-f4.toml").read_text()
    near = src.replace('distance = "inf"', "distance = 2").replace('t = "gaussian"', "t = 43.08")
    assert near != src
    lens = tmp_path / "near.toml"
    lens.write_text(near)
    rc, out, err = run_cli(["tolerance", str(lens), str(SPEC), "--fields", FIELDS, *run])
    assert rc == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "internal error" not in err
    assert "inside the front focal length" in err and "before the last surface" in err


def _entries(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` and its bytes (what a refused run must leave as it was)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_a_run_refused_for_missing_dask_writes_nothing(tmp_path, monkeypatch):
    # `--dask local:2 -o run2` without Dask was refused ("Dask is not installed") after
    # run2/manifest.json was written; the next run there with another --samples was then
    # refused as "holds another run" (docs/tolerance.md: the checks run before any long work)
    import sys

    from distortion.tolerance import monte_carlo
    from raytrace.errors import OrthoscopeError
    from raytrace.files.library import load_lens
    from raytrace.tolerance import read_tolerance_spec

    monkeypatch.setitem(sys.modules, "distributed", None)  # `import distributed` fails
    run = tmp_path / "run2"
    rc, out, err = run_cli(BASE + ["--samples", "32", "--dask", "local:2", "-o", str(run)])
    assert rc == 2 and "Dask is not installed" in err, err
    assert not run.exists()
    # the API (the command checks Dask before its run; the run itself writes nothing either)
    lens, spec = load_lens(LENS), read_tolerance_spec(SPEC)
    empty = tmp_path / "empty"
    empty.mkdir()
    for folder in (run, empty):
        with pytest.raises(OrthoscopeError, match="Dask is not installed"):
            monte_carlo(lens, spec, 32, fields_deg=[0.0, 10.0, 20.0], chunk_size=16,
                        executor="local:2", out_dir=folder)  # fmt: skip
    assert not run.exists() and list(empty.iterdir()) == []
    # so the next run there is not refused as "another run"
    rc, out, err = run_cli(BASE + ["--samples", "16", "--chunk", "16", "-o", str(run)])
    assert rc == 0, err
    assert json.loads((run / "manifest.json").read_text())["n"] == 16


def test_a_run_refused_for_an_unreachable_scheduler_leaves_the_folder_as_it_was(
    tmp_path, monkeypatch
):
    # `--dask tcp://127.0.0.1:1 -o run3` (nothing listens) was refused after the 20 s connect
    # timeout, with run3/manifest.json written (and, with --force, the chunks of the run that
    # was there removed). The scheduler's connect error is made at once here: a Client that
    # raises what distributed.Client raises after its timeout (OSError)
    distributed = pytest.importorskip("distributed")

    class Unreachable:
        def __init__(self, address, *args, **kwargs):
            raise OSError(f"Timed out trying to connect to {address} after 20 s")

    monkeypatch.setattr(distributed, "Client", Unreachable)
    dask = ["--dask", "tcp://127.0.0.1:1"]
    run = tmp_path / "run3"
    rc, out, err = run_cli(BASE + ["--samples", "32", *dask, "-o", str(run)])
    assert rc == 2 and "cannot reach the Dask scheduler tcp://127.0.0.1:1" in err, err
    assert len(err.strip().splitlines()) == 1
    assert not run.exists()
    # a folder that holds a finished run keeps it, with or without --force
    rc, out, err = run_cli(BASE + ["--samples", "16", "--chunk", "8", "-o", str(run)])
    assert rc == 0, err
    before = _entries(run)
    assert "chunk-00001.npz" in before
    for extra, words in (([], "holds another run"), (["--force"], "cannot reach the Dask")):
        rc, out, err = run_cli(BASE + ["--samples", "32", "--chunk", "8", *dask, "-o", str(run),
                                       *extra])  # fmt: skip
        assert rc == 2 and words in err, err
        assert _entries(run) == before


def test_a_run_that_fails_before_any_chunk_leaves_no_manifest(tmp_path, monkeypatch):
    # a run that fails before its first chunk is on disk (here: the chunk's own error) leaves
    # neither the folder it made nor a manifest that would refuse the next run with other
    # settings; an interrupted run keeps its chunks (test above)
    import distortion.tolerance.montecarlo as mc
    from raytrace.files.library import load_lens
    from raytrace.tolerance import read_tolerance_spec

    def broken(*args, **kwargs):
        raise RuntimeError("worker lost")

    monkeypatch.setattr(mc, "run_chunk", broken)
    lens, spec = load_lens(LENS), read_tolerance_spec(SPEC)
    run = tmp_path / "run"
    with pytest.raises(RuntimeError, match="worker lost"):
        mc.monte_carlo(lens, spec, 32, fields_deg=[0.0, 10.0, 20.0], chunk_size=16, out_dir=run)
    assert not run.exists()
