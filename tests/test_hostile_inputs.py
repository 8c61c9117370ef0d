"""Hostile inputs, by class (docs/design.md, "Errors and files"): every one gives a result or one
clear line with exit status 2 — never a traceback, never an internal error."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from orthoscope.cli import main

ROOT = Path(__file__).resolve().parents[1]
COOKE = ROOT / "lenses" / "cooke-triplet-f4.toml"
TABLE1 = ROOT / "tests" / "data" / "pestrecov_table1.csv"


def _cli(*argv, env=None, **kw):
    e = dict(os.environ, **(env or {}))
    return subprocess.run(
        [sys.executable, "-m", "orthoscope", *argv], capture_output=True, text=True, env=e, **kw
    )


def _one_error_line(stderr: str) -> bool:
    lines = [ln for ln in stderr.strip().splitlines() if ln]
    return len(lines) == 1 and ": error:" in lines[0] and "Traceback" not in stderr


def test_a_lens_from_a_pipe_is_read(tmp_path):
    fifo = tmp_path / "lens.toml"
    os.mkfifo(fifo)
    text = COOKE.read_bytes()

    def feed():
        with open(fifo, "wb") as fh:
            fh.write(text)

    t = threading.Thread(target=feed, daemon=True)
    t.start()
    r = _cli("paraxial", str(fifo), timeout=60)
    if t.is_alive():  # the command never opened the pipe: unblock the writer, then fail
        with open(fifo, "rb") as fh:
            fh.read()
    t.join(timeout=10)
    assert r.returncode == 0, r.stderr
    assert "50.000" in r.stdout  # the Cooke triplet's EFL (lenses/README.md: 50.000)


def test_utf16_toml_and_bom_csv_are_read(tmp_path):
    lens = tmp_path / "cooke16.toml"
    lens.write_bytes(COOKE.read_text(encoding="utf-8").encode("utf-16"))
    assert _cli("paraxial", str(lens)).returncode == 0
    table = tmp_path / "bom.csv"
    table.write_bytes(b"\xef\xbb\xbf" + TABLE1.read_bytes())
    r = _cli("calibrate", str(table), "--method", "minimax")
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize(
    "text,words",
    [
        ("a = " + "[" * 2000 + "]" * 2000, "nests too deeply"),
        ('name = "x"\nobject = { distance = ' + "9" * 400 + " }\n", "too large"),
        ("\x00\x01binary", "binary data"),
    ],
    ids=["deep-nesting", "400-digit-integer", "binary"],
)
def test_broken_toml_is_one_line(tmp_path, text, words):
    f = tmp_path / "bad.toml"
    f.write_text(text) if "\x00" not in text else f.write_bytes(text.encode())
    r = _cli("paraxial", str(f))
    assert r.returncode == 2 and _one_error_line(r.stderr), r.stderr
    assert words in r.stderr


@pytest.mark.parametrize("value", ["0", "-1", "abc", "2.5"])
def test_bad_numba_threads_is_one_line(value):
    r = _cli("trace", "cooke-triplet-f4", env={"NUMBA_NUM_THREADS": value})
    assert r.returncode == 2 and _one_error_line(r.stderr), r.stderr
    assert "NUMBA_NUM_THREADS" in r.stderr


def test_a_broken_mplbackend_does_not_stop_a_plot(tmp_path):
    out = tmp_path / "fig.png"
    r = _cli("distortion", "cooke-triplet-f4", "--plot", str(out), env={"MPLBACKEND": "nonsense"})
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 1000


def test_a_full_stdout_is_one_line():
    with open("/dev/full", "w") as full:
        r = subprocess.run(
            [sys.executable, "-m", "orthoscope", "distortion", "cooke-triplet-f4"],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
        )
    assert r.returncode == 1
    assert _one_error_line(r.stderr) and "No space left" in r.stderr, r.stderr


def test_debug_zero_means_no_traceback(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text("nonsense = [")
    r = _cli("paraxial", str(f), env={"ORTHOSCOPE_DEBUG": "0"})
    assert r.returncode == 2 and "Traceback" not in r.stderr


@pytest.mark.parametrize(
    "argv,words",
    [
        (["paraxial", "cooke-triplet-f4", "--wavelength", "0"], "positive"),
        (["paraxial", "cooke-triplet-f4", "--wavelength", "nan"], "not a number"),
        (["paraxial", "cooke-triplet-f4", "--wavelength", "-587.6"], "positive"),
        (["paraxial", "cooke-triplet-f4", "--wavelength", "0.5876"], "micrometres"),
        (["distortion", "cooke-triplet-f4", "--object-distance", "1.5parsec"], "unit"),
        (["distortion", "cooke-triplet-f4", "--object-scale", "-12x"], "positive"),
        (["paraxial", "cooke-triplet-f4", "--object-s", "10"], "negative"),
        (["paraxil", "cooke-triplet-f4"], "did you mean 'paraxial'"),
        (["paraxial", "cooke-trplet-f4"], "did you mean"),
        (["distortion", "cooke-triplet-f4", "--plot", "x.bmp"], ".png"),
        (["trace", "cooke-triplet-f4", "--steps", "1000000000"], "--allow-large"),
    ],
)
def test_bad_values_are_one_line_with_the_fix(argv, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2 and _one_error_line(err), err
    assert words in err


def test_an_existing_lens_is_never_overwritten_by_convert(tmp_path):
    src = tmp_path / "cooke.toml"
    shutil.copy(COOKE, src)
    before = src.read_bytes()
    r = _cli("convert", str(src), str(src))
    assert r.returncode == 2 and "input file" in r.stderr
    r = _cli("convert", str(src), str(tmp_path / "." / "cooke.toml"), "--force")
    assert r.returncode == 2 and "input file" in r.stderr
    link = tmp_path / "link.toml"
    link.symlink_to(src)
    r = _cli("convert", str(src), str(link), "--force")
    assert r.returncode == 2 and "input file" in r.stderr
    assert src.read_bytes() == before
