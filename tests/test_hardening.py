"""Nothing lost, nothing silently wrong (docs/design.md, "Errors and files"), checked by class and
for every command of the registry (orthoscope.cli.COMMANDS): each command module declares quick
SAMPLES and its OUTPUTS, so a command added later is covered without anyone remembering to.

Classes: an output that is an input is refused and the input survives; an existing output is
replaced only with --force; a failing disk leaves the old file intact and no fragment; a
non-UTF-8 locale prints; a value in the wrong unit is one clear line; Ctrl-C stops with 130 and
one line, within a second, also inside a long kernel run; two threads trace at once."""

from __future__ import annotations

import errno
import importlib
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from support import ctrl_c_child, run_cli

from orthoscope.cli import COMMANDS, COMPILE_NOTICE, build_parser

ROOT = Path(__file__).resolve().parents[1]
LENS_NAMES = ("cooke-triplet-f4", "topogon-us2031792-fig1", "twinplex-like-55-525")


def _modules():
    return [importlib.import_module(f"orthoscope.cli.{m}") for m in COMMANDS]


def _samples():
    out = []
    for mod in _modules():
        for i, argv in enumerate(getattr(mod, "SAMPLES", [])):
            out.append(pytest.param(mod, argv, id=f"{argv[0]}-{i}"))
    return out


def _outputs():
    out = []
    for mod in _modules():
        for argv in getattr(mod, "SAMPLES", [])[:1]:
            for flag, suffix in getattr(mod, "OUTPUTS", []):
                out.append(pytest.param(argv, flag, suffix, id=f"{argv[0]}{flag}"))
    return out


@pytest.fixture
def work(tmp_path):
    shutil.copytree(
        ROOT / "tests" / "data", tmp_path / "data", ignore=shutil.ignore_patterns("corpus")
    )
    shutil.copytree(ROOT / "lenses" / "specs", tmp_path / "specs")
    for name in LENS_NAMES:
        shutil.copy(ROOT / "lenses" / f"{name}.toml", tmp_path / f"{name}.toml")
    return tmp_path


def _materialize(argv: list[str], work: Path) -> list[str]:
    """Placeholders filled, bundled lens names replaced by copies in ``work`` (so that no test
    can ever write onto the repository's files)."""
    out = []
    for a in argv:
        a = a.format(data=work / "data", specs=work / "specs", tmp=work)
        if a in LENS_NAMES:
            a = str(work / f"{a}.toml")
        out.append(a)
    return out


def _with_output(argv: list[str], flag: str, path: Path) -> list[str]:
    argv = list(argv)
    if flag == "OUT":  # a positional output: the last argument of the sample
        argv[-1] = str(path)
    elif flag in argv:
        argv[argv.index(flag) + 1] = str(path)
    else:
        argv += [flag, str(path)]
    return argv


def _error_lines(err: str) -> list[str]:
    """The error lines of stderr (progress lines of long commands go there too)."""
    return [ln for ln in err.splitlines() if ": error:" in ln or "Traceback" in ln]


def _first_input(argv: list[str]) -> Path:
    return next(Path(a) for a in argv[1:] if Path(a).is_file())


def test_every_command_has_samples():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a.choices, dict))
    covered = {argv[0] for mod in _modules() for argv in getattr(mod, "SAMPLES", [])}
    assert set(sub.choices) <= covered, f"commands without SAMPLES: {set(sub.choices) - covered}"


@pytest.mark.parametrize("mod,argv", _samples())
def test_sample_runs(mod, argv, work, monkeypatch):
    monkeypatch.chdir(work)
    rc, _, err = run_cli(_materialize(argv, work))
    assert rc == 0, err


@pytest.mark.parametrize("argv,flag,suffix", _outputs())
def test_output_onto_an_input_is_refused_and_the_input_survives(
    argv, flag, suffix, work, monkeypatch
):
    monkeypatch.chdir(work)
    full = _materialize(argv, work)
    target = _first_input(full)
    before = target.read_bytes()
    for force in ([], ["--force"]):
        rc, _, err = run_cli(_with_output(full, flag, target) + force)
        assert rc == 2, err
        assert "input file" in err and len(_error_lines(err)) == 1, err
        assert target.read_bytes() == before


@pytest.mark.parametrize("argv,flag,suffix", _outputs())
def test_existing_output_needs_force(argv, flag, suffix, work, monkeypatch):
    monkeypatch.chdir(work)
    out = work / f"existing{suffix}"
    out.write_bytes(b"precious")
    full = _with_output(_materialize(argv, work), flag, out)
    rc, _, err = run_cli(full)
    assert rc == 2 and "--force" in err, err
    assert out.read_bytes() == b"precious"
    rc, _, err = run_cli(full + ["--force"])
    assert rc == 0, err
    assert out.read_bytes() != b"precious"


@pytest.mark.parametrize("argv,flag,suffix", _outputs())
def test_failing_disk_leaves_the_old_file_and_no_fragment(argv, flag, suffix, work, monkeypatch):
    monkeypatch.chdir(work)
    out = work / "out" / f"existing{suffix}"
    out.parent.mkdir()
    out.write_bytes(b"precious")

    def full_disk(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full_disk)
    rc, _, err = run_cli(_with_output(_materialize(argv, work), flag, out) + ["--force"])
    assert rc == 2, err
    assert "No space left" in err and len(_error_lines(err)) == 1, err
    assert out.read_bytes() == b"precious"
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name]


def _wavelength_samples():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a.choices, dict))
    return [
        p
        for p in _samples()
        if "--wavelength" in sub.choices[p.values[1][0]]._option_string_actions
    ]


@pytest.mark.parametrize("mod,argv", _wavelength_samples())
def test_wavelength_in_the_wrong_unit_is_one_clear_line(mod, argv, work, monkeypatch):
    monkeypatch.chdir(work)
    rc, _, err = run_cli(_materialize(argv, work) + ["--wavelength", "0.5876"])
    assert rc == 2
    assert "micrometres" in err and "0.5876um" in err and len(err.strip().splitlines()) == 1


def _env_c_locale() -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("LC_", "LANG", "PYTHONUTF8"))}
    env.update(LANG="C", LC_ALL="C", PYTHONCOERCECLOCALE="0", PYTHONUTF8="0")
    return env


@pytest.mark.parametrize("mod,argv", _samples())
def test_runs_under_a_non_utf8_locale(mod, argv, work):
    r = subprocess.run(
        [sys.executable, "-m", "orthoscope", *_materialize(argv, work)],
        env=_env_c_locale(),
        cwd=work,
        capture_output=True,
    )
    assert r.returncode == 0, r.stderr.decode("ascii", "replace")
    assert b"internal error" not in r.stderr


@pytest.mark.parametrize(
    "argv,wait",
    [
        (
            [
                "--allow-large",
                "trace",
                "cooke-triplet-f4",
                "--max-field",
                "20",
                "--steps",
                "3000000",
            ],
            4.0,
        ),
        # about 5 s in all on an idle 2-core machine (0.6 s of it start-up): interrupt at 2 s
        (
            [
                "--allow-large",
                "spot",
                "cooke-triplet-f4",
                "--fields",
                "0,5,10,15,20",
                "--rings",
                "900",
            ],
            2.0,
        ),
    ],
    ids=["chief-rays", "bulk-trace"],
)
def test_ctrl_c_exits_130_with_one_line_within_a_second(argv, wait, work):
    with ctrl_c_child(argv, cwd=work, stdout=subprocess.DEVNULL) as p:
        time.sleep(wait)  # inside the kernel run
        assert p.poll() is None, "the command finished before it could be interrupted"
        t0 = time.monotonic()
        p.send_signal(signal.SIGINT)
        rc = p.wait(timeout=30)
        dt = time.monotonic() - t0
        err = p.stderr.read().decode()
    assert rc == 130, err
    lines = [ln for ln in err.strip().splitlines() if COMPILE_NOTICE not in ln]
    assert lines == [f"orthoscope {argv[1]}: interrupted"]
    assert dt < 1.5, f"took {dt:.2f} s to stop"


def test_two_threads_trace_at_once():
    import orthoscope as osc
    from raytrace.trace import PARALLEL_THRESHOLD

    lens = osc.load_lens("cooke-triplet-f4")
    rng = np.random.default_rng(1)
    n = PARALLEL_THRESHOLD + 5000  # the parallel (prange) kernel
    x, y = rng.uniform(-5, 5, (2, n))
    d = (np.zeros(n), rng.uniform(-0.2, 0.2, n), np.ones(n))
    ref = osc.trace_rays(lens, (x, y, -1.0), d, threads=1)
    results, errors = [], []

    def work():
        try:
            for _ in range(5):
                results.append(osc.trace_rays(lens, (x, y, -1.0), d))
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    ts = [threading.Thread(target=work) for _ in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not errors and len(results) == 10
    for r in results:
        np.testing.assert_array_equal(r.y, ref.y)


# ------------------------------------------------------------ files too large or nested too deeply
def _readers():
    """(reader, suffix, project error) for every user file the API reads as text."""
    import orthoscope as osc
    from distortion.camera import read_calibration, read_camera_setup
    from distortion.errors import DataError
    from raytrace.errors import PrescriptionError
    from raytrace.optimize import SpecError
    from raytrace.tolerance import ToleranceSpecError

    return [
        (osc.load_lens, ".toml", PrescriptionError),
        (osc.read_configurations, ".toml", PrescriptionError),
        (osc.read_spec, ".toml", SpecError),
        (osc.read_tolerance_spec, ".toml", ToleranceSpecError),
        (osc.read_tolerance_spec, ".zmx", ToleranceSpecError),
        (osc.read_distortion_table, ".csv", DataError),
        (osc.read_profiles_csv, ".csv", DataError),
        (read_camera_setup, ".toml", DataError),
        (read_calibration, ".yml", DataError),
    ]


def test_a_file_too_large_to_read_is_refused_by_every_reader(tmp_path):
    # /dev/zero, or a video given by mistake, filled the memory: killed, or "internal error:
    # MemoryError"; only the lens reader had a cap. A sparse file over the cap costs no disk.
    from raytrace.files.text import MAX_FILE_BYTES

    for read, suffix, error in _readers():
        big = tmp_path / f"big{suffix}"
        with open(big, "wb") as fh:
            fh.truncate(MAX_FILE_BYTES + 1)
        with pytest.raises(error, match=r"big\.\w+.*larger than 64 MB"):
            read(big)
    rc, _, err = run_cli(["camera", "cooke-triplet-f4", "--camera", str(big.with_suffix(".toml"))])
    assert rc == 2 and err.count("\n") == 1 and "larger than 64 MB" in err, err


def test_toml_nested_too_deeply_is_one_error_not_a_recursion_error(tmp_path):
    # tomllib recurses per nesting level: 5,000 brackets raised RecursionError from read_spec,
    # read_camera_setup and read_configurations ("internal error" in the CLI)
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n", encoding="utf-8")
    for read, suffix, error in _readers():
        if suffix == ".toml":
            with pytest.raises(error, match="deep.toml"):
                read(deep)
    rc, _, err = run_cli(["optimize", str(deep), "-o", str(tmp_path / "o.toml")])
    assert rc == 2 and err.count("\n") == 1 and "nested too deeply" in err, err


def test_configurations_of_an_oslo_file_say_where_configurations_come_from():
    # an OSLO .len was parsed as TOML: "TOML syntax error: Invalid statement"
    import orthoscope as osc
    from raytrace.errors import PrescriptionError

    path = Path(__file__).parent / "data" / "corpus" / "optiland" / "test_cooke_triplet.len"
    with pytest.raises(PrescriptionError, match=r"OSLO \.len file holds no configurations"):
        osc.read_configurations(path)
