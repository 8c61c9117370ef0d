"""The orthoscope command line, end to end: output content, JSON/CSV, errors with exit status 2."""

import csv
import io
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from orthoscope.cli import main

DATA = Path(__file__).parent / "data"
TABLE1 = DATA / "pestrecov_table1.csv"


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_lenses_lists_every_bundled_lens(capsys):
    rc, out, _ = run(capsys, "lenses")
    assert rc == 0
    for name in (
        "topogon-us2031792-fig1",
        "cooke-triplet-f4",
        "tessar-fr1066698",
        "super-angulon-de975637",
        "wide-field-ektar-us2518719",
    ):
        assert name in out
    rc, out, _ = run(capsys, "lenses", "--json")
    names = {d["name"] for d in json.loads(out)}
    assert "cooke-triplet-f4" in names


def test_paraxial_json_published_values(capsys):
    # Cooke triplet: EFL 50.000, BFL 43.080 (issue 2's reference values for this prescription).
    rc, out, _ = run(capsys, "paraxial", "cooke-triplet-f4", "--json")
    d = json.loads(out)
    assert rc == 0
    assert d["efl"] == pytest.approx(50.000, abs=5e-4)
    assert d["bfl"] == pytest.approx(43.080, abs=5e-4)
    assert d["object_distance"] == "inf"


def test_paraxial_image_scale_object(capsys):
    # '12x' means Gaussian magnification -1/12 (Pestrecov Eq. 5: m0 = f/(f+s)).
    rc, out, _ = run(capsys, "paraxial", "cooke-triplet-f4", "--object-distance", "12x", "--json")
    d = json.loads(out)
    assert d["m0"] == pytest.approx(-1.0 / 12.0, rel=1e-12)
    assert d["m0"] == pytest.approx(d["efl"] / (d["efl"] + d["s"]), rel=1e-12)


def test_trace_topogon_published_heights(capsys):
    # US 2,031,792 Fig. 1, public lens-test fixture: real chief-ray heights on the paraxial image
    # plane at 7, 14, 21, 28, 35 degrees.
    rc, out, _ = run(
        capsys, "trace", "topogon-us2031792-fig1", "--fields", "7,14,21,28,35", "--json"
    )
    d = json.loads(out)
    got = [r["y_image_mm"] for r in d["rays"]]
    assert got == pytest.approx([8.112, 16.495, 25.457, 35.382, 46.805], abs=1e-3)
    assert all(r["status"] == "ok" for r in d["rays"])
    assert d["image_plane"]["defocus_mm"] == pytest.approx(0.0, abs=1e-12)


def test_trace_csv_and_text(capsys):
    rc, out, _ = run(
        capsys, "trace", "cooke-triplet-f4", "--max-field", "20", "--steps", "4", "--csv"
    )
    rows = list(csv.DictReader(io.StringIO(out)))
    assert [float(r["angle_deg"]) for r in rows] == [0, 5, 10, 15, 20]
    rc, out, _ = run(capsys, "trace", "cooke-triplet-f4", "--defocus", "0.5")
    assert rc == 0 and "defocus +0.500000 mm" in out


def test_trace_field_beyond_lens_gets_a_status(capsys):
    rc, out, _ = run(capsys, "trace", "topogon-us2031792-fig1", "--fields", "30,70", "--json")
    d = json.loads(out)
    assert rc == 0
    assert d["rays"][0]["status"] == "ok"
    assert d["rays"][1]["status"] != "ok" and d["rays"][1]["y_image_mm"] is None


def test_calibrate_prints_table_II(capsys):
    # Acceptance (issue 3): Table I with two-point calibration at 37.5 and 45 deg prints Table II
    # (Pestrecov 1958): Fc = 154.059, Yc' and Dc per field.
    rc, out, _ = run(capsys, "calibrate", str(TABLE1), "--method", "two-point", "--at", "37.5,45")
    assert rc == 0
    assert "F_c = 154.059 mm" in out
    assert "27.165" in out and "154.059" in out  # Yc' at 10 and 45 deg
    assert "-0.045" in out and "+0.081" in out and "-0.081" in out  # Dc at 10, 37.5, 45 deg
    rc, out, _ = run(
        capsys, "calibrate", str(TABLE1), "--method", "two-point", "--at", "37.5,45", "--json"
    )
    d = json.loads(out)
    assert d["Fc"] == pytest.approx(154.059, abs=5e-4)
    assert d["rho_k_deg"] == pytest.approx(24.67, abs=0.015)


def test_distortion_several_planes_and_fig6_plot(capsys, tmp_path):
    png = tmp_path / "fig6.png"
    rc, out, _ = run(
        capsys,
        "distortion",
        "topogon-us2031792-fig1",
        "--s-prime",
        "65.5",
        "--s-prime",
        "66.5",
        "--plot",
        str(png),
        "--json",
    )
    d = json.loads(out)["distortion"]
    assert rc == 0 and png.stat().st_size > 10_000
    assert [p["s_prime_mm"] for p in d["planes"]] == pytest.approx([65.5, 66.5])
    # Pestrecov Eq. (8): F0 = p0'/m_e in each plane; the Topogon is symmetric so m_e = 1, HE0 = 0
    assert [p["F0_mm"] for p in d["planes"]] == pytest.approx([65.5, 66.5], abs=1e-9)


def test_distortion_calibrate_and_layout(capsys, tmp_path):
    rc, out, _ = run(
        capsys,
        "distortion",
        "topogon-us2031792-fig1",
        "--fields",
        "0,20,40,45",
        "--calibrate",
        "two-point",
        "--at",
        "40,45",
        "--layout",
        str(tmp_path / "l.svg"),
        "--plot-rotation",
        str(tmp_path / "f4.pdf"),
    )
    assert rc == 0
    assert "calibrated distortion" in out and "F_c =" in out
    assert (tmp_path / "l.svg").stat().st_size > 1000
    assert (tmp_path / "f4.pdf").stat().st_size > 1000


def test_distortion_csv_rows(capsys):
    rc, out, _ = run(
        capsys,
        "distortion",
        "cooke-triplet-f4",
        "--defocus",
        "-1",
        "--defocus",
        "1",
        "--steps",
        "2",
        "--csv",
    )
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 6
    assert {round(float(r["defocus_mm"]), 9) for r in rows} == {-1.0, 1.0}


def test_compensate_identical_curves_leave_no_residual(capsys, tmp_path):
    # Pestrecov Section VI: characteristic curves compensate when they are identical (D1 = D2)
    # and M = M2. A printer whose negative-plane distortion equals the camera's, built from
    # Table I itself, leaves zero residual.
    printer = tmp_path / "printer.csv"
    rows = [ln for ln in TABLE1.read_text().splitlines() if ln and not ln.startswith("#")][1:]
    m2 = -2.0
    out_rows = ["y_mm, y0p_mm, D0_mm"]
    yneg = d0 = 0.0
    for r in rows:
        yneg_prev, d_prev = yneg, d0
        a, y0p, d0, _ = (float(v) for v in r.split(","))
        yneg = y0p + d0  # the point of the negative, imaged by the printer
        # printer: D2 (negative plane) = D1 at that point  ->  print distortion Dp = -M2 * D2
        out_rows.append(f"{yneg!r}, {m2 * yneg!r}, {-m2 * d0!r}")
    # one more row 0.1 % beyond the field (linear extrapolation of D): the reader recomputes y0'
    # from the fitted F0, so the camera's last negative point can exceed the printed one by the
    # rounding of Table I.
    yneg_end = 1.001 * yneg
    d_end = d0 + (yneg_end - yneg) * (d0 - d_prev) / (yneg - yneg_prev)
    out_rows.append(f"{yneg_end!r}, {m2 * yneg_end!r}, {-m2 * d_end!r}")
    printer.write_text("\n".join(out_rows) + "\n")
    rc, out, err = run(capsys, "compensate", str(TABLE1), str(printer), "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert max(abs(v) for v in d["residual_mm"]) < 2e-3
    # the bundled copy of Table I by its name, as calibrate takes it (it was read as a lens name)
    rc, out2, err = run(
        capsys, "compensate", "pestrecov-1958-table1-topogon", str(printer), "--json"
    )
    assert rc == 0, err
    assert json.loads(out2) == d


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["trace", "no-such-lens"], "no-such-lens"),
        (["trace", "cooke-triplet-f4", "--fields", "0,abc"], "expected a number"),
        (["trace", "cooke-triplet-f4", "--object-distance", "-5"], "positive magnitude"),
        (["trace", "cooke-triplet-f4", "--from-last-vertex", "-3"], "before the last surface"),
        (["trace", "cooke-triplet-f4", "--field-kind", "height", "--fields", "1"], "finite object"),
        (["distortion", "cooke-triplet-f4", "--at", "5"], "--calibrate"),
        (
            ["distortion", "cooke-triplet-f4", "--calibrate", "two-point", "--at", "5,99"],
            "90 degrees",
        ),
        (["distortion", "cooke-triplet-f4", "--plot", "x.gif"], ".png"),
        (["distortion", "cooke-triplet-f4", "--s-prime", "50,50"], "50 is listed twice"),
        (["calibrate", str(TABLE1), "--method", "two-point", "--at", "37.5,50"], "50"),
        (["calibrate", "/nonexistent.csv", "--method", "minimax"], "nonexistent"),
        (["convert", "cooke-triplet-f4", "out.seq"], ".seq"),
        (["paraxial", "cooke-triplet-f4", "--object-s", "10"], "negative"),
    ],
)
def test_bad_input_exit_2_one_line(capsys, argv, needle):
    rc, out, err = run(capsys, *argv)
    assert rc == 2
    assert needle in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


BROKEN = {
    "two_stops.toml": "aperture = { fnumber = 4 }\nfield = { angle = 10 }\nsurfaces = [\n"
    '  { r = 20, t = 2, glass = "1.5/60", stop = true },\n  { r = -20, t = 40, stop = true },\n]\n',
    "unknown_material.toml": "aperture = { fnumber = 4 }\nfield = { angle = 10 }\nsurfaces = [\n"
    '  { r = 20, t = 2, glass = "unobtainium", stop = true },\n  { r = -20, t = 40 },\n]\n',
    "empty.toml": "",
}


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_lens_file_via_console_script(tmp_path, name):
    # End to end through the installed console script: exit status 2, the file named, no traceback.
    exe = shutil.which("orthoscope")
    f = tmp_path / name
    f.write_text(BROKEN[name])
    cmd = [exe] if exe else [sys.executable, "-m", "orthoscope"]
    p = subprocess.run([*cmd, "trace", str(f)], capture_output=True, text=True, cwd=tmp_path)
    assert p.returncode == 2
    assert name in p.stderr and "Traceback" not in p.stderr
    assert p.stdout == ""


def test_binary_garbage_lens_file(tmp_path, capsys):
    f = tmp_path / "garbage.toml"
    f.write_bytes(bytes(range(256)) * 4)
    rc, out, err = run(capsys, "paraxial", str(f))
    assert rc == 2 and "garbage.toml" in err and "Traceback" not in err


def test_cli_choices_equal_the_science_constants():
    from distortion.calibration import METHODS
    from distortion.characteristic import REFERENCES
    from orthoscope.cli import common

    assert common.METHODS == METHODS and common.REFERENCES == REFERENCES


def test_strict_turns_a_failed_field_into_exit_2(capsys):
    # 85 deg is beyond what the Cooke triplet (20 deg half-field) can trace: by default the table
    # shows the field's status and the run succeeds; --strict makes it an error (README, "--strict")
    rc, out, err = run(capsys, "distortion", "cooke-triplet-f4", "--fields", "0,10,85")
    assert rc == 0 and "85" in out
    rc, out, err = run(capsys, "distortion", "cooke-triplet-f4", "--fields", "0,10,85", "--strict")
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert rc == 2 and len(lines) == 1 and "--strict" in lines[0]
    rc, out, err = run(capsys, "distortion", "cooke-triplet-f4", "--fields", "0,10,20", "--strict")
    assert rc == 0
    # trace too (the README's example): the table first, then the one error line
    rc, out, err = run(capsys, "trace", "cooke-triplet-f4", "--fields", "0,10,30,60", "--strict")
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert rc == 2 and "aim_failed" in out
    assert lines == ["orthoscope trace: error: 2 field(s) could not be traced (see the table); "
                     "--strict fails"]  # fmt: skip
    rc, out, err = run(capsys, "trace", "cooke-triplet-f4", "--fields", "0,10,20", "--strict")
    assert rc == 0


def test_two_outputs_naming_one_file_are_refused_before_any_work(capsys, tmp_path):
    # the second plot silently replaced the first (with --force), or the run failed half-way
    # after writing the first (without it)
    same = tmp_path / "same.png"
    for argv in (
        ["distortion", "cooke-triplet-f4", "--plot", str(same), "--layout", str(same)],
        ["distortion", "cooke-triplet-f4", "--plot", str(same), "--layout",
         str(tmp_path / "." / "same.png"), "--force"],
    ):  # fmt: skip
        rc, _, err = run(capsys, *argv)
        assert rc == 2 and "two outputs of this command name the same file" in err
        assert not same.exists()


def test_api_keywords_in_errors_are_said_as_flags(capsys):
    # one vocabulary (docs/design.md): the science packages name API keywords, the command
    # line names the same things with dashes
    from orthoscope.cli import cli_words

    assert cli_words("needs exactly 2 field(s) in at=, got 1") == (
        "needs exactly 2 field(s) in --at, got 1"
    )
    assert cli_words("give format= one of x") == "give --format one of x"
    assert cli_words("n_coefficients=6 does not apply") == "--coefficients 6 does not apply"
    assert cli_words("e.g. at=(37.5, 45)") == "e.g. at=(37.5, 45)"  # an API example stays
    assert cli_words("thickness=0.5") == "thickness=0.5"  # not a flag
    rc, _, err = run(capsys, "calibrate", str(TABLE1), "--method", "given")
    assert rc == 2 and "needs the calibrated constant F_c (--value)" in err


def test_an_unknown_flag_is_said_by_its_subcommand(capsys):
    # "orthoscope: error: unrecognized arguments" did not say which command's --help to read
    rc, _, err = run(capsys, "distortion", "cooke-triplet-f4", "--bogus")
    assert rc == 2 and err.strip().splitlines()[-1] == (
        "orthoscope distortion: error: unrecognized arguments: --bogus "
        "(see orthoscope distortion --help)"
    )


def test_a_height_field_table_has_one_y_column(capsys):
    # the field column of a height table is the object height; it was printed twice
    rc, out, _ = run(capsys, "distortion", "twinplex-like-55-525", "--object-s", "-55.0009",
                     "--fields", "-1,-2", "--field-kind", "height")  # fmt: skip
    header = next(x for x in out.splitlines() if "y0' (mm)" in x)
    assert rc == 0 and header.split().count("y") == 1, header


def test_ctrl_c_while_the_engine_is_imported_is_one_line(capsys, monkeypatch):
    # main() imported raytrace before its try: a Ctrl-C in the first ~0.4 s was a traceback
    import orthoscope.cli as cli

    def interrupted(argv):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "_run", interrupted)
    assert cli.main(["paraxial", "cooke-triplet-f4"]) == 130
    assert capsys.readouterr().err == "orthoscope: interrupted\n"


def test_strict_refuses_a_glass_outside_its_data_range(capsys):
    # topogon-like-spherical is in Schott glasses whose data start at 312.566 nm (N-SK11): at
    # 250 nm the index is an extrapolation (a warning); --strict fails (review 2026-11-27: it
    # printed four warnings and exit 0), and the filter does not outlive the call
    argv = ["trace", "topogon-like-spherical", "--fields", "0,10", "--wavelength", "250"]
    rc, out, err = run(capsys, *argv)
    assert rc == 0 and "outside its data range" in err
    from raytrace.lens import _indices

    _indices.cache_clear()  # the indices of a lens are cached per process (a CLI run is fresh)
    rc, out, err = run(capsys, *argv, "--strict")
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert rc == 2 and out == "" and len(lines) == 1
    assert "surface 1: glass N-SK11 (Schott) evaluated at 250 nm" in lines[0]
    assert lines[0].endswith(
        "--strict fails: use wavelengths inside the data range (or leave out --strict)"
    )
    assert run(capsys, *argv)[0] == 0


def test_review_of_the_analysis_commands(capsys):
    # review 2026-11-27: each of these was silently ignored, misleading or refused
    rc, out, err = run(capsys, "distortion", "cooke-triplet-f4", "--sensor-metrics")
    assert (rc, out) == (2, "") and "--sensor-metrics needs --sensor WxH" in err
    # a headline over the traced fields only (80 deg does not trace in the Cooke triplet)
    rc, out, _ = run(capsys, "pupils", "cooke-triplet-f4", "--fields", "0,80")
    assert rc == 0 and "(0 = telecentric in image space); over the traced fields only" in out
    # a line letter where one wavelength is asked, as where several are
    rc, out, _ = run(capsys, "pupils", "cooke-triplet-f4", "--wavelength", "d", "--json")
    assert rc == 0 and json.loads(out)["pupils"]["wavelength_nm"] == 587.5618
    # fan status words, as trace's (20 deg: the Cooke triplet's rim rays run backward)
    rc, out, _ = run(capsys, "fan", "cooke-triplet-f4", "--field", "20", "--n", "5", "--json")
    assert json.loads(out)["fans"][0]["status"] == ["backward", "ok", "ok", "ok", "backward"]
    # a finite object's nominal angles are named so in the CSV (as distortion --csv does)
    rc, out, _ = run(capsys, "pupils", "twinplex-like-55-525", "--csv")
    assert rc == 0 and out.startswith("nominal_angle_deg,cra_deg,")


def test_ctrl_c_inside_llvm_is_delivered_again_later(monkeypatch):
    # 1 in 40 runs of `spot --rings 900` interrupted in the first 2 s lost the Ctrl-C ("Exception
    # ignored on calling ctypes callback ... _raw_object_cache_notify", exit 0) and one full
    # test run saw exit -11: a KeyboardInterrupt raised inside llvmlite's callbacks. The handler
    # asks again 50 ms later when the main thread is in llvmlite / numba's compiler
    import os
    import signal
    import sys
    import time

    from orthoscope.cli import _sigint_handler

    sent = []
    monkeypatch.setattr(os, "kill", lambda pid, sig: sent.append((pid, sig)))
    inside = {"__name__": "llvmlite.binding.executionengine"}
    exec("def callback(h):\n    import sys\n    h(2, sys._getframe())", inside)
    inside["callback"](_sigint_handler)  # no KeyboardInterrupt here
    time.sleep(0.3)
    assert sent == [(os.getpid(), signal.SIGINT)]
    with pytest.raises(KeyboardInterrupt):
        _sigint_handler(signal.SIGINT, sys._getframe())


#: a child's 20 s in a function of a module named like numba's compiler, SIGINT handled as the
#: CLI handles it (the child has imported sys and time, and _sigint_outside_llvm)
_LONG_COMPILE = (
    "_sigint_outside_llvm()\n"
    "ns = {'__name__': 'numba.core.compiler'}\n"
    "exec('def compile_for_a_while():\\n    import time\\n    t = time.monotonic()\\n'\n"
    "     '    while time.monotonic() - t < 20:\\n        sum(range(1000))', ns)\n"
    "print('compiling', file=sys.stderr, flush=True)\n"
    "ns['compile_for_a_while']()\n"
)


def test_ctrl_c_held_by_a_long_compile_ends_the_run_within_the_hold(tmp_path):
    # The first run on a new machine compiles kernels for about a minute with numba's compiler
    # on the stack all along: the Ctrl-C was held back over and over and the command then ran
    # to its end with status 0. Here a child spends 20 s in a function of a module named like
    # numba's compiler; a Ctrl-C must end it within about SIGINT_HOLD_S, one line, status 130.
    import signal
    import subprocess
    import sys
    import time

    from support import default_sigint

    from orthoscope.cli import SIGINT_HOLD_S

    code = (
        "import sys, time\n"
        "from orthoscope.cli import _sigint_outside_llvm\n"
        + _LONG_COMPILE
        + "print('finished', flush=True)\n"
    )
    p = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=default_sigint,
    )
    assert p.stderr.readline().strip() == "compiling"
    time.sleep(0.3)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=15)
    took = time.monotonic() - t0
    assert p.returncode == 130 and out == ""
    assert err.strip() == "orthoscope: interrupted"
    assert took < SIGINT_HOLD_S + 3.0  # the 20 s "compile" did not run to its end


def _read_only_home(tmp_path) -> dict:
    """This environment with a home that cannot be written (no config or cache folders) and
    ``tmp_path`` as TMPDIR."""
    import os

    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("HOME", "XDG_CONFIG_HOME", "XDG_CACHE_HOME", "MPLCONFIGDIR")
    }
    env.update(HOME="/proc/no-home", TMPDIR=str(tmp_path))
    return env


def test_ctrl_c_held_by_a_long_compile_removes_the_temporary_matplotlib_folder(tmp_path):
    # The Ctrl-C held back past SIGINT_HOLD_S ends the run through os._exit, which runs no
    # atexit handler: the temporary MPLCONFIGDIR folder of a read-only home
    # (_matplotlib_folder) stayed behind in TMPDIR. It is removed before that exit.
    import signal
    import subprocess
    import sys
    import time

    from support import default_sigint

    env = _read_only_home(tmp_path)
    code = (
        "import os, sys, time\n"
        "from orthoscope.cli import _matplotlib_folder, _sigint_outside_llvm\n"
        "_matplotlib_folder()\n"
        "print(os.environ['MPLCONFIGDIR'], flush=True)\n" + _LONG_COMPILE
    )
    p = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        preexec_fn=default_sigint,
    )
    folder = Path(p.stdout.readline().strip())
    assert p.stderr.readline().strip() == "compiling"
    assert folder.parent == tmp_path and folder.is_dir()  # made, and used by matplotlib
    time.sleep(0.3)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=15)
    assert p.returncode == 130 and err.strip() == "orthoscope: interrupted"
    assert not folder.exists()
    assert not list(tmp_path.glob("*matplotlib*"))


def test_a_plot_with_a_read_only_home_prints_no_matplotlib_lines(tmp_path):
    # matplotlib printed "mkdir -p failed for path ..." and "Matplotlib created a temporary cache
    # directory ..." on every plot when HOME cannot be written; the command gives it a
    # temporary folder first and removes it at exit
    import subprocess
    import sys

    env = _read_only_home(tmp_path)
    png = tmp_path / "d.png"
    r = subprocess.run(
        [sys.executable, "-m", "orthoscope", "distortion", "cooke-triplet-f4", "--fields",
         "0,10,20", "--plot", str(png)],
        env=env, capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert png.stat().st_size > 0
    assert "matplotlib" not in r.stderr.lower() and "mkdir" not in r.stderr, r.stderr
    assert not list(tmp_path.glob("*matplotlib*"))  # the temporary folder is gone


def test_a_warning_raised_again_is_printed_once(capsys):
    # N-SK16 at 2600 nm (its data end at 2325.42 nm): the extrapolation warning came once per
    # evaluation of the lens, three times for one trace; and again in the next run
    zmx = str(Path(__file__).parent / "data" / "cooke-triplet-f4.zmx")
    argv = ["trace", zmx, "--wavelength", "2600", "--fields", "0,10"]
    from raytrace.lens import _indices

    for _ in range(2):  # each run says it (the cache of a lens's indices is per process)
        _indices.cache_clear()
        rc, _, err = run(capsys, *argv)
        # N-SK16 (surfaces 1 and 5, one material) and the model glass of surface 3
        lines = [ln for ln in err.splitlines() if "evaluated at 2600 nm, outside" in ln]
        assert rc == 0 and len(lines) == 2 and len(set(lines)) == 2, err


def test_a_flood_of_distinct_warnings_is_cut_short(capsys):
    # an optimization fitting model glasses outside their range warns with a new nd/vd (a new
    # text) at every evaluation: the command line shows ten of a kind, then says it stops
    import orthoscope.cli as cli
    from raytrace.materials import OutOfRangeWarning

    cli._PRINTED.clear()
    cli._PER_CATEGORY.clear()
    for k in range(15):
        cli._one_line_warning(f"model glass 1.5/{50 + k} ...", OutOfRangeWarning, "f.py", 1)
        cli._one_line_warning(f"model glass 1.5/{50 + k} ...", OutOfRangeWarning, "f.py", 1)
    cli._one_line_warning("another kind", UserWarning, "f.py", 1)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 12
    assert lines[9] == "orthoscope: warning: model glass 1.5/59 ..."
    assert lines[10] == (
        "orthoscope: warning: more warnings like these (OutOfRangeWarning) are not shown"
    )
    assert lines[11] == "orthoscope: warning: another kind"


# ------------------------------------------------------------------ deprecated spellings
S_DEPRECATED = "orthoscope: warning: --s is deprecated and will be removed; use --object-s"


def _err_lines(err: str) -> list[str]:
    return [ln for ln in err.strip().splitlines() if "compiling" not in ln]


def _refused(capsys, *argv) -> tuple[list[str], str]:
    """``orthoscope ARGV``, which must be refused: exit status 2, nothing on stdout. Returns the
    lines of its stderr (compile notices left out) and the stderr itself."""
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and out == "", err
    return _err_lines(err), err


@pytest.mark.parametrize(
    "argv",
    [
        ["distortion", "cooke-triplet-f4", "--s", "-1000", "--object-s", "-900"],
        ["distortion", "cooke-triplet-f4", "--object-s", "-900", "--s", "-1000"],
        ["distortion", "cooke-triplet-f4", "--s", "-900", "--object-s", "-900", "--json"],
        ["paraxial", "cooke-triplet-f4", "--object-s", "-900", "--s", "-1000"],
        ["trace", "cooke-triplet-f4", "--s", "-1000", "--object-s=-1m"],
    ],
)
def test_s_with_object_s_is_refused(argv, capsys):
    # --s is the deprecated spelling of --object-s: both given, the last one won, with the
    # deprecation line said at parse time (now refused before any work, as every deprecated
    # spelling with its flag: test_a_deprecated_spelling_with_its_flag_is_refused)
    lines, _ = _refused(capsys, *argv)
    assert lines == [
        f"orthoscope {argv[0]}: error: --s and --object-s both give the object's s (--s is the "
        "deprecated spelling of --object-s): give --object-s alone"
    ]


@pytest.mark.parametrize(
    "argv,said",
    [
        # a deprecated spelling in a refused run
        (["distortion", "cooke-triplet-f4", "--s", "-1000", "--fields", "abc"],
         "--fields: expected a number"),
        (["distortion", "cooke-triplet-f4", "--s", "abc"], "--s: 'abc' is not a number"),
        (["distortion", "cooke-triplet-f4", "--s", "-1000", "--image-distance", "50",
          "--defocus", "1"], "give the image planes one way"),
        (["distortion", "cooke-triplet-f4", "--k", "100", "--at", "5"],
         "--at and --value need --calibrate"),
        (["trace", "cooke-triplet-f4", "--s", "-1000", "--object-distance", "1m"],
         "give the object one way"),
        # an old spelling of a plane flag, named as typed
        (["distortion", "cooke-triplet-f4", "--image-distance", "50", "--defocus", "1"],
         "give the image planes one way, not --image-distance, --defocus"),
        (["distortion", "cooke-triplet-f4", "--image-distance", "abc"], "--image-distance: "),
        (["distortion", "cooke-triplet-f4", "--image-distance", "50,50"],
         "--image-distance: the plane 50 is listed twice"),
        (["trace", "cooke-triplet-f4", "--image-from-vertex", "50", "--defocus", "1"],
         "give the image planes one way, not --image-from-vertex, --defocus"),
    ],
)  # fmt: skip
def test_a_refusal_is_one_line_naming_the_flags_as_typed(argv, said, capsys):
    # the deprecation line was said at parse time, before the refusal; and an old spelling was
    # named by its new one in these refusals ("not --s-prime, --defocus" for --image-distance 50
    # --defocus 1): the user is told what they wrote, in one line
    lines, err = _refused(capsys, *argv)
    assert len(lines) == 1, err
    assert lines[0].startswith(f"orthoscope {argv[0]}: error: {said}"), lines[0]
    assert "deprecated" not in err


def test_an_accepted_deprecated_spelling_is_said_once(capsys):
    new = run(capsys, "distortion", "cooke-triplet-f4", "--object-s", "-1000", "--json")
    assert new[0] == 0 and _err_lines(new[2]) == []
    for argv in (["--s", "-1000"], ["--s", "-1000", "--s", "-1000"]):  # twice: said once
        rc, out, err = run(capsys, "distortion", "cooke-triplet-f4", *argv, "--json")
        assert rc == 0 and out == new[1]
        assert _err_lines(err) == [S_DEPRECATED]
    rc, out, err = run(capsys, "distortion", "cooke-triplet-f4", "--s", "-1000", "--k", "100")
    assert rc == 0 and _err_lines(err) == [
        S_DEPRECATED,
        "orthoscope: warning: --k is deprecated and will be removed; use --exaggeration",
    ]


def _deprecated_pairs():
    """(command, deprecated action) for every deprecated spelling of every command (the
    registry: a spelling added later is covered without anyone remembering to)."""
    import importlib

    from orthoscope.cli import COMMANDS, _subparser, build_parser
    from orthoscope.cli.common import DeprecatedAlias

    parser = build_parser()
    samples = {}
    for name in COMMANDS:
        for argv in getattr(importlib.import_module(f"orthoscope.cli.{name}"), "SAMPLES", []):
            samples.setdefault(argv[0], argv)
    out = []
    for command, argv in samples.items():
        for a in _subparser(parser, command)._actions:
            if isinstance(a, DeprecatedAlias):
                value = a.choices[0] if a.choices else "1"
                out.append((argv, a.option_strings[0], a.new, a.what, value))
    return out


DEPRECATED_PAIRS = _deprecated_pairs()


def test_every_deprecated_spelling_of_the_brief_is_covered():
    # the pairs that let the last one win silently (issue: --s/--object-s alone was refused)
    found = {(argv[0], old, new) for argv, old, new, _, _ in DEPRECATED_PAIRS}
    assert {
        ("distortion", "--s", "--object-s"),
        ("distortion", "--k", "--exaggeration"),
        ("distortion", "--image-distance", "--s-prime"),
        ("distortion", "--image-from-vertex", "--from-last-vertex"),
        ("calibrate", "--criterion", "--method"),
        ("compensate", "--criterion", "--method"),
        ("compensate", "--M", "--magnification"),
        ("trace", "--image-distance", "--s-prime"),
        ("colour", "--image-from-vertex", "--from-last-vertex"),
        ("camera", "--s", "--object-s"),
    } <= found


@pytest.mark.parametrize("old_first", [True, False], ids=["old-first", "new-first"])
@pytest.mark.parametrize(
    "argv,old,new,what,value",
    DEPRECATED_PAIRS,
    ids=[f"{p[0][0]}{p[1]}" for p in DEPRECATED_PAIRS],
)
def test_a_deprecated_spelling_with_its_flag_is_refused(
    argv, old, new, what, value, old_first, capsys, tmp_path
):
    # before: both stored to one place and the last one given won silently (--k 100
    # --exaggeration 50 plotted with 50; a repeatable --s-prime took both as two planes), with
    # a deprecation line; now one line, exit 2, before any work, in every command
    argv = [a.format(data=DATA, specs=DATA.parent.parent / "lenses" / "specs", tmp=tmp_path)
            for a in argv]  # fmt: skip
    both = [old, value, new, value] if old_first else [new, value, old, value]
    lines, _ = _refused(capsys, *argv, *both)
    assert lines == [
        f"orthoscope {argv[0]}: error: {old} and {new} both give {what} ({old} is the "
        f"deprecated spelling of {new}): give {new} alone"
    ]
    assert not list(tmp_path.iterdir())  # nothing written


def test_repeated_planes_of_both_spellings_are_refused(capsys):
    # distortion's --s-prime is repeatable (more planes from one trace), but the README and the
    # design doc call --image-distance an old spelling, not a second list: mixing them is
    # refused like any pair (before: two planes, s' = 50 and 51, and a deprecation line)
    lines, _ = _refused(
        capsys, "distortion", "cooke-triplet-f4", "--s-prime", "50", "--image-distance", "51"
    )
    assert lines == [
        "orthoscope distortion: error: --image-distance and --s-prime both give the image "
        "plane's s' (--image-distance is the deprecated spelling of --s-prime): give --s-prime "
        "alone"
    ]
    # each spelling alone, repeated, still gives its planes
    rc, new, _ = run(capsys, "distortion", "cooke-triplet-f4", "--s-prime", "50", "--s-prime",
                     "51", "--json")  # fmt: skip
    assert rc == 0 and len(json.loads(new)["distortion"]["planes"]) == 2
    rc, old, err = run(capsys, "distortion", "cooke-triplet-f4", "--image-distance", "50",
                       "--image-distance", "51", "--json")  # fmt: skip
    assert rc == 0 and old == new
    assert _err_lines(err) == [
        "orthoscope: warning: --image-distance is deprecated and will be removed; use --s-prime"
    ]


@pytest.mark.parametrize(
    "old,new,value",
    [("--M", "--magnification", "-9"), ("--criterion", "--method", "minimax")],
)
def test_compensate_old_spellings_alone_still_run(old, new, value, capsys):
    base = ["compensate", "topogon-us2031792-fig1", "twinplex-like-55-525", "--fields",
            "0,10,20,30", "--json"]  # fmt: skip
    rc, want, err = run(capsys, *base, new, value)
    assert rc == 0 and _err_lines(err) == [], err
    rc, got, err = run(capsys, *base, old, value)
    assert rc == 0 and got == want
    assert _err_lines(err) == [
        f"orthoscope: warning: {old} is deprecated and will be removed; use {new}"
    ]


def test_an_alias_of_a_flag_that_does_not_note_it_is_refused():
    # the refusal of both spellings needs the new flag noted as given (NotedStore,
    # NotedAppend): a deprecated spelling of a plain flag is a mistake of the code
    import argparse

    from orthoscope.cli.common import NotedStore, add_alias

    p = argparse.ArgumentParser()
    p.add_argument("--plain")
    with pytest.raises(ValueError, match="noting action"):
        add_alias(p, "--old-plain", "--plain", "plain", what="a value")
    with pytest.raises(ValueError, match="add '--missing' first"):
        add_alias(p, "--old-missing", "--missing", "missing", what="a value")
    p.add_argument("--noted", action=NotedStore)
    add_alias(p, "--old-noted", "--noted", "noted", what="a value")
    assert p.parse_args(["--old-noted", "x"]).noted == "x"


@pytest.mark.parametrize(
    "argv,flags",
    [
        (["trace", "cooke-triplet-f4", "--s", "-1000", "--object-distance", "1m"],
         "--s and --object-distance"),
        (["trace", "cooke-triplet-f4", "--object-distance", "1m", "--s", "-1000"],
         "--object-distance and --s"),
        (["paraxial", "cooke-triplet-f4", "--object-scale", "12", "--object-s=-1m"],
         "--object-scale and --object-s"),
        (["distortion", "cooke-triplet-f4", "--object-distance", "1m", "--object-scale", "12"],
         "--object-distance and --object-scale"),
        (["pupils", "cooke-triplet-f4", "--object-s", "-1000", "--object-scale", "12",
          "--object-distance", "1m"], "--object-s and --object-scale and --object-distance"),
        (["colour", "cooke-triplet-f4", "--object-d", "1m", "--object-sc", "12"],
         "--object-distance and --object-scale"),  # abbreviations: the flags they stand for
        (["fan", "cooke-triplet-f4", "--s", "-1000", "--object-scale", "12"],
         "--s and --object-scale"),
        (["report", "cooke-triplet-f4", "--object-scale", "12", "--object-distance", "1m"],
         "--object-scale and --object-distance"),
    ],
)  # fmt: skip
def test_two_object_flags_are_named_as_flags(argv, flags, capsys):
    # before: the API's keywords, "give the object one way, not object_distance and object_s"
    lines, _ = _refused(capsys, *argv)
    assert lines == [f"orthoscope {argv[0]}: error: give the object one way, not {flags}"]
