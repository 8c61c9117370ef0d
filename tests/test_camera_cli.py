"""``orthoscope camera``: the command line gives what the API gives (same words, same numbers),
writes the files the real libraries read, states the projection centre in every output, and
refuses what a person can get wrong in one line (exit 2).

Referees: the API (distortion.camera) for the numbers, cv2.FileStorage / cv2.imread and numpy
for the files written; the synthetic calibrations of tests/data/camera (make_measured.py).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from support import TEST_DATA, run_cli

import orthoscope as osc
from distortion.camera import (
    CameraSetup,
    Sensor,
    calibrated_models_by_distance,
    camera_model,
    compare_calibration,
    project,
    read_calibration,
    traced_models_by_distance,
)

DATA = TEST_DATA / "camera"
BASE = ["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "1200x800", "--grid", "9x7"]


def run(argv, cwd=None, monkeypatch=None):
    if cwd is not None:
        monkeypatch.chdir(cwd)
    return run_cli(argv)


def _camera_spec(directory, text: str):
    """``directory / "cam.toml"`` holding ``text``: a ``--camera`` spec."""
    spec = directory / "cam.toml"
    spec.write_text(text, encoding="utf-8")
    return spec


@pytest.fixture(scope="module")
def sensor():
    return Sensor.from_spec(size="24x16", pixels="1200x800")


def test_cli_equals_api_and_states_the_projection_centre(cooke, sensor):
    rc, out, err = run([*BASE, "--focus", "2m", "--object-distance", "5m", "--json"])
    assert rc == 0, err
    d = json.loads(out)
    api = camera_model(cooke, sensor, "opencv", focus="2m", object_distance="5m", grid=(9, 7))
    assert d["camera"]["model"] == api.camera.model
    for k, v in api.camera.as_dict().items():
        assert d["camera"]["parameters"][k] == pytest.approx(v, rel=1e-12, abs=1e-15)
    assert d["camera"]["rms_px"] == pytest.approx(api.rms_px, rel=1e-9)
    g = d["geometry"]
    assert g["object_distance_mm"] == 5000.0
    assert g["focus_object_distance_mm"] == 2000.0
    assert "paraxial entrance pupil" in g["projection_centre"]
    assert g["projection_centre_z_mm"] == pytest.approx(osc.paraxial(cooke).z_E0, abs=1e-12)
    assert d["pupils"]["max_entrance_pupil_shift_mm"] > 0
    rc, text, err = run([*BASE, "--focus", "2m", "--object-distance", "5m"])
    assert rc == 0 and "projection centre: paraxial entrance pupil E0" in text
    assert "model chosen by" in text and "COLMAP cameras.txt: 1 " in text


def test_calibration_file_written_is_what_cv2_reads(tmp_path, monkeypatch, cooke, sensor):
    cv2 = pytest.importorskip("cv2")
    rc, _, err = run([*BASE, "-o", "cam.yml"], tmp_path, monkeypatch)
    assert rc == 0, err
    api = camera_model(cooke, sensor, "opencv", grid=(9, 7))
    ours = read_calibration(tmp_path / "cam.yml")
    np.testing.assert_allclose(ours.params, api.camera.params, rtol=1e-15, atol=1e-300)
    fs = cv2.FileStorage(str(tmp_path / "cam.yml"), cv2.FILE_STORAGE_READ)
    k = fs.getNode("camera_matrix").mat()
    fs.release()
    np.testing.assert_allclose(k, api.camera_matrix, rtol=1e-15)
    # COLMAP from the name, the smallest COLMAP model that holds the camera
    rc, _, err = run([*BASE, "--model", "colmap", "-o", "cameras.txt"], tmp_path, monkeypatch)
    assert rc == 0, err
    written = read_calibration(tmp_path / "cameras.txt")
    api = camera_model(cooke, sensor, "colmap", grid=(9, 7))
    assert written.model == api.camera.model
    # FULL_OPENCV's rational terms are nearly degenerate here (parameters move with round-off):
    # the projections must agree, not the digits
    ideal, _ = api.points.valid()
    a = project(written, ideal, pixels="opencv").points
    b = project(api.camera, ideal, pixels="opencv").points
    assert np.abs(a - b).max() < 1e-6
    # an existing file needs --force; a file of another model family than --model's is refused
    # with the fix (test_the_output_file_is_of_the_model_family_asked_for)
    rc, _, err = run([*BASE, "-o", "cam.yml"], tmp_path, monkeypatch)
    assert rc == 2 and "--force" in err and len(err.strip().splitlines()) == 1
    rc, _, err = run([*BASE, "--model", "fisheye", "-o", "m.xml"], tmp_path, monkeypatch)
    assert rc == 2 and "give --model metashape" in err and not (tmp_path / "m.xml").exists()


def test_camera_spec_toml_and_flags(tmp_path, monkeypatch, cooke):
    spec = _camera_spec(
        tmp_path,
        '[sensor]\nsize = "24x16"\npixels = "1200x800"\n[focus]\ndistance = "2m"\n'
        "[trace]\ngrid = [9, 7]\n",
    )
    rc, out, err = run(["camera", "cooke-triplet-f4", "--camera", str(spec), "--json",
                        "--object-distance", "1m"], tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    d = json.loads(out)
    api = camera_model(cooke, spec, "opencv", object_distance="1m")
    assert d["camera"]["parameters"]["k1"] == pytest.approx(api.camera["k1"], rel=1e-12)
    assert d["geometry"]["focus_object_distance_mm"] == 2000.0
    assert d["sensor"]["width_px"] == 1200 and d["trace"]["grid"] == [9, 7]


def test_table_per_object_distance(tmp_path, monkeypatch, cooke, sensor):
    argv = [*BASE, "--focus", "2m", "--object-distances", "1m,2m,inf"]
    rc, out, err = run([*argv, "--csv"])
    assert rc == 0, err
    assert "projection centre: paraxial entrance pupil" in err  # CSV has no room: stderr
    rows = [ln.split(",") for ln in out.strip().splitlines()]
    t = traced_models_by_distance(cooke, sensor, ["1m", "2m", "inf"], focus="2m", grid=(9, 7))
    head, ref = t.rows()
    assert rows[0] == head
    for got, want in zip(rows[1:], ref, strict=True):
        np.testing.assert_allclose([float(v) for v in got], want, rtol=1e-12, atol=1e-15)
    rc, _, err = run([*argv, "-o", "table.json"], tmp_path, monkeypatch)
    assert rc == 0, err
    d = json.loads((tmp_path / "table.json").read_text())["models_by_distance"]
    assert d["columns"] == head and len(d["rows"]) == 3 and d["method"] == "traced"
    rc, _, err = run([*argv, "-o", "table.yml"], tmp_path, monkeypatch)
    assert rc == 2 and ".csv or .json" in err


def test_compare_convert_and_variation(tmp_path, monkeypatch, cooke):
    cal = str(DATA / "cooke-measured-2m.yml")
    argv = ["camera", "compare", "cooke-triplet-f4", cal, "--sensor", "24x16", "--focus", "2m",
            "--object-distance", "2m", "--grid", "9x7"]  # fmt: skip
    rc, out, err = run([*argv, "--json"])
    assert rc == 0, err
    d = json.loads(out)["comparison"]
    api = compare_calibration(cooke, read_calibration(cal),
                              Sensor.from_spec(size="24x16", pixels="3000x2000"),
                              focus="2m", object_distance="2m", grid=(9, 7))  # fmt: skip
    assert d["distortion_difference_rms_px"] == pytest.approx(api.rms_px, rel=1e-9)
    assert any("paraxial entrance pupil" in n for n in d["notes"])
    rc, _, err = run([*argv, "--plot", "cmp.png"], tmp_path, monkeypatch)
    assert rc == 0 and (tmp_path / "cmp.png").read_bytes()[:4] == b"\x89PNG"
    rc, _, err = run([*argv, "--pixels", "1000x1000"])
    assert rc == 2 and "3000x2000" in err
    # convert: exact into Metashape, a refit into Australis with its residual
    rc, out, err = run(["camera", "convert", cal, "--model", "metashape", "--json"])
    assert rc == 0, err
    conv = json.loads(out)["conversion"]
    assert conv["method"] == "exact" and conv["rms_px"] < 1e-9
    rc, out, err = run(["camera", "convert", cal, "--model", "australis", "--sensor", "24x16"])
    assert rc == 0 and "refit" in out and "RMS" in out
    rc, _, err = run(["camera", "convert", cal, "--model", "australis"])
    assert rc == 2 and "give --pitch (or --sensor)" in err  # the API says pixel_size_mm=
    # variation: the table equals the API's
    c1, c5 = DATA / "cooke-measured-1m.yml", DATA / "cooke-measured-5m.yml"
    rc, out, err = run(["camera", "variation", str(c1), str(c5), "--calibrated-at", "1m,5m",
                        "--focal-length", "50", "--focus", "2m", "--object-distances",
                        "1m,2m,5m", "--sensor", "24x16", "--method", "fraser-shortis",
                        "--g", "0.45", "--json"])  # fmt: skip
    assert rc == 0, err
    d = json.loads(out)["models_by_distance"]
    api = calibrated_models_by_distance(
        read_calibration(c1), "1m", read_calibration(c5), "5m", focal_length_mm=50,
        focus="2m", object_distances=["1m", "2m", "5m"], method="fraser-shortis", g=0.45,
        pixel_size_mm=(0.008, 0.008),
    )  # fmt: skip
    head, rows = api.rows()
    for got, want in zip(d["rows"], rows, strict=True):
        np.testing.assert_allclose([got[h] for h in head], want, rtol=1e-12)


def test_picture_and_maps(tmp_path, monkeypatch):
    cv2 = pytest.importorskip("cv2")
    rc, _, err = run([*BASE, "--picture", "pic.png", "--maps", "maps.npz", "--pattern",
                      "checkerboard"], tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    img = cv2.imread(str(tmp_path / "pic.png"), cv2.IMREAD_GRAYSCALE)
    assert img.shape == (800, 1200)
    with np.load(tmp_path / "maps.npz") as z:
        assert z["map1"].shape == (800, 1200) and z["map1"].dtype == np.float32
        assert str(z["direction"]) == "undistort" and z["camera_matrix"].shape == (3, 3)
    rc, _, err = run([*BASE, "--picture", "pic.jpg"], tmp_path, monkeypatch)
    assert rc == 2 and ".png" in err


def test_a_principal_point_off_the_sensor_is_taken_with_a_warning():
    # a shift or rise puts the axis off the sensor (refused for a few hours: 2026-11-28)
    rc, out, err = run([*BASE, "--principal-point", "13,0"])
    assert rc == 0, err
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert len(lines) == 1 and "lies off the 24x16 mm sensor" in lines[0], err


@pytest.mark.parametrize(
    "argv,words",
    [
        (["camera", "cooke-triplet-f4"], "give the sensor"),
        (["camera", "cooke-triplet-f4", "--sensor", "24x16"], "two of"),
        ([*BASE, "--model", "opencvv"], "did you mean"),
        ([*BASE, "--focus", "2m", "--defocus", "0.1"], "focus one way"),
        ([*BASE, "--grid", "9"], "--grid"),
        (["camera", "compare", "cooke-triplet-f4"], "usage"),
        (["camera", "cooke-triplet-f4", "extra"], "one LENS"),
        ([*BASE, "--coefficients", "6"], "--coefficients 6 does not apply"),
        (["camera", "variation", "a.yml", "b.yml"], "--calibrated-at"),
        # too few points: the grid's fault, or rays that miss the sensor (said apart)
        ([*BASE[:-1], "2x2"], "the grid gives 4 points (a larger grid)"),
        ([*BASE, "--object-distances", "10m,1m,,1m"], "an empty entry"),
        ([*BASE, "--object-distances", "10m,1m,1m"], "1m is listed twice"),
        # a 1 m sensor: its corners lie far beyond the field the lens images
        (
            ["camera", "cooke-triplet-f4", "--sensor", "1000x800", "--pixels", "10000x8000"]
            + ["--grid", "8x6", "--no-clip"],
            "only 0 of 48 chief rays reached",
        ),
        (
            ["camera", "cooke-triplet-f4", "--sensor", "80x60", "--pixels", "32x24"],
            "makes pixels of 2500 x 2500 µm",
        ),
    ],
)
def test_errors_are_one_line(argv, words):
    rc, _, err = run(argv)
    assert rc == 2, err
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert len(lines) == 1 and words in lines[0], err


def test_setup_flags_reach_the_setup(cooke, sensor):
    """The same plane through the CLI words and the API keywords gives the same camera."""
    g = CameraSetup(sensor, from_last_vertex=43.5).resolve(cooke)
    rc, out, err = run([*BASE, "--from-last-vertex", "43.5", "--json"])
    assert rc == 0, err
    got = json.loads(out)["geometry"]["from_last_vertex_mm"]
    assert got == pytest.approx(g.from_last_vertex, abs=1e-12)


def test_plots_keep_the_ax_convention(cooke, sensor):
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    from orthoscope.plots.camera import (
        plot_calibration_comparison,
        plot_camera_residuals,
        plot_difference_map,
        plot_distortion_picture,
        plot_radial_comparison,
    )

    tc = camera_model(cooke, sensor, "opencv", grid=(9, 7))
    measured = tc.camera.replace(k1=1.1 * tc.camera["k1"], cx=tc.camera["cx"] + 2.0)
    cmp = compare_calibration(cooke, measured, sensor, grid=(9, 7))
    makers = [
        lambda ax: plot_camera_residuals(tc, ax=ax),
        lambda ax: plot_radial_comparison(cmp, ax=ax),
        lambda ax: plot_difference_map(cmp, ax=ax),
    ]
    try:
        import cv2  # noqa: F401

        makers.append(lambda ax: plot_distortion_picture(tc.camera, reference=True, ax=ax))
    except ImportError:
        pass
    for make in makers:
        fig = Figure()
        ax = fig.subplots()
        assert make(ax) is fig
        new = make(None)
        assert new in [plt.figure(n) for n in plt.get_fignums()]
        plt.close("all")
    two = plot_calibration_comparison(cmp)
    assert len([a for a in two.axes if a.get_label() != "<colorbar>"]) == 2
    plt.close("all")


def test_convert_keeps_to_the_model_and_coefficient_count_asked_for(tmp_path, monkeypatch, cooke):
    # --model opencv on a fisheye calibration is the perspective model (a refit), not the
    # fisheye again; --coefficients N refits to N coefficients (the exact path ignored N)
    cv2 = pytest.importorskip("cv2")  # the referee (extra "camera")
    from distortion.camera import format_calibration

    setup = CameraSetup(sensor=Sensor.from_spec(size="24x16", pixels="1200x800"), grid=(9, 7))
    fe = camera_model(cooke, setup, "fisheye")
    (tmp_path / "fe.yml").write_text(format_calibration(fe.camera, "opencv-yaml"))
    rc, out, err = run(["camera", "convert", "fe.yml", "--model", "opencv", "--json"],
                       tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    conv = json.loads(out)["conversion"]
    assert conv["method"] == "refit" and conv["target"]["model"] == "opencv", conv
    cal = str(DATA / "cooke-measured-2m.yml")
    rc, _, err = run(["camera", "convert", cal, "--model", "opencv", "--coefficients", "4",
                      "-o", "c4.yml"], tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    fs = cv2.FileStorage(str(tmp_path / "c4.yml"), cv2.FILE_STORAGE_READ)
    assert fs.getNode("distortion_coefficients").mat().size == 4  # what cv2 reads
    fs.release()


def test_the_table_of_models_refuses_the_one_distance_outputs(tmp_path, monkeypatch):
    # with --object-distances, --plot / --picture / --maps / --format / --strict were accepted and
    # ignored (exit 0, only the table written); -o of a comparison took any suffix and wrote JSON
    # into a .png
    monkeypatch.chdir(tmp_path)
    base = ["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "1200x800",
            "--grid", "9x7", "--object-distances", "1m,2m"]  # fmt: skip
    for extra in (["--plot", "p.png"], ["--strict"], ["--maps", "m.npz", "--format", "colmap"]):
        rc, out, err = run_cli([*base, *extra])
        (line,) = err.strip().splitlines()
        assert rc == 2 and "--object-distances" in line and extra[0] in line, err
    assert not list(tmp_path.iterdir())
    rc, out, err = run_cli([*base, "-o", "t.json"])
    assert rc == 0 and (tmp_path / "t.json").is_file(), err
    rc, out, err = run_cli(["camera", "compare", "cooke-triplet-f4",
                            "cooke-triplet-f4-synthetic-2m", "--sensor", "24x16", "--grid", "9x7",
                            "-o", "cmp.png"])  # fmt: skip
    (line,) = err.strip().splitlines()
    assert rc == 2 and "-o cmp.png: a comparison is written as .csv or .json" in line
    assert not (tmp_path / "cmp.png").exists()


def test_a_sensor_beyond_the_image_circle_is_said(tmp_path, monkeypatch):
    # the Cooke triplet images to r = 28 mm; a 60 x 40 sensor's corners are at 36 mm: the model
    # is extrapolated there (a warning), and --strict refuses before writing anything
    argv = ["camera", "cooke-triplet-f4", "--sensor", "60x40", "--pixels", "1500x1000"]
    rc, _, err = run([*argv, "-o", "big.yml"], tmp_path, monkeypatch)
    assert rc == 0 and "chief rays do not reach the sensor" in err and "--strict" in err
    rc, _, err = run([*argv, "-o", "strict.yml", "--strict"], tmp_path, monkeypatch)
    assert rc == 2 and "--strict fails" in err and not (tmp_path / "strict.yml").exists()


def test_a_measured_affinity_is_fitted_in_the_prediction(cooke):
    # design.md: the prediction frees "every coefficient it holds away from identity"; Metashape's
    # b1 (affinity) is not among its fits' defaults and was held at 0 although the file had it
    from distortion.camera import convert_camera_model
    from distortion.camera.models import CameraModel
    from distortion.camera.traced import prediction_like, trace_camera_points

    cal = read_calibration(str(DATA / "cooke-measured-2m.yml"))
    ms = convert_camera_model(cal, "metashape").camera
    params = ms.as_dict() | {"b1": 8.8e-5}
    measured = CameraModel.create(ms.model, ms.width, ms.height,
                                  pixel_size_mm=ms.pixel_size_mm, **params)  # fmt: skip
    setup = CameraSetup(
        sensor=Sensor.from_spec(size="24x16", pixels=f"{ms.width}x{ms.height}"), grid=(9, 7),
        focus="2m", object_distance="2m",
    )  # fmt: skip
    pred = prediction_like(measured, trace_camera_points(cooke, setup))
    assert "b1" in pred.fit.free


def test_camera_id_chooses_a_camera_of_a_colmap_file(tmp_path, monkeypatch):
    # COLMAP's cameras.txt format (CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]), two cameras
    (tmp_path / "cameras.txt").write_text(
        "# Camera list\n1 PINHOLE 3000 2000 6000 6000 1500 1000\n"
        "2 SIMPLE_RADIAL 4000 3000 3000 2000 1500 0.01\n"
    )
    rc, _, err = run(["camera", "convert", "cameras.txt", "--model", "opencv"],
                     tmp_path, monkeypatch)  # fmt: skip
    assert rc == 2 and "choose one with --camera-id" in err
    rc, out, err = run(["camera", "convert", "cameras.txt", "--model", "opencv", "--camera-id",
                        "2", "--json"], tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    src = json.loads(out)["conversion"]["source"]
    assert src["model"] == "colmap:SIMPLE_RADIAL" and src["image_width_px"] == 4000


# ------------------------------------------------------------- each form's help, bundled examples
def _examples(page: str) -> list[str]:
    lines = page.split("Examples:", 1)[1].splitlines()
    return [ln.strip() for ln in lines if ln.strip().startswith("orthoscope ")]


@pytest.mark.parametrize(
    "form,has,lacks",
    [
        ("compare", ["--plot", "--object-distance", "--focus-s", "--grid", "--strict"],
         ["--picture", "--maps", "--model", "--calibrated-at", "--format"]),
        ("convert", ["--model", "--coefficients", "--format", "--camera-id"],
         ["--grid", "--focus", "--plot", "--picture", "--calibrated-at", "--csv"]),
        ("variation", ["--calibrated-at", "--focal-length", "--method", "--g", "--focus",
                       "--object-distances"],
         ["--model", "--grid", "--wavelength", "--plot", "--picture", "--strict"]),
    ],
)  # fmt: skip
def test_each_form_prints_its_own_help(form, has, lacks):
    """`orthoscope camera compare --help` (convert, variation) is that form's page, not the
    command's general page (a review found all three printing the general one)."""
    rc, general, _ = run(["camera", "--help"])
    assert rc == 0 and "--picture" in general and general.count("orthoscope camera") >= 4
    for argv in (["camera", form, "--help"], ["camera", form, "x", "-h"]):
        rc, page, err = run(argv)
        assert rc == 0, err
        assert page.startswith(f"usage: orthoscope camera {form} ") and page != general
        flags = set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", page.split("Examples:")[0]))
        assert set(has) <= flags, set(has) - flags
        assert not set(lacks) & flags, set(lacks) & flags
    # its examples are the general page's (tests/test_docs.py runs those) and use this form
    examples = _examples(page)
    assert examples and all(e.startswith(f"orthoscope camera {form} ") for e in examples)
    assert set(examples) <= set(_examples(general))


def test_every_flag_a_form_page_shows_is_parsed():
    """A form's page is for the help only; the command's one parser must accept what it shows,
    with the same choices, default, type and count of values (the metavar may differ)."""
    from orthoscope.cli import build_parser
    from orthoscope.cli.camera import ACTIONS, action_parser

    sub = build_parser("camera")._subparsers._group_actions[0].choices["camera"]
    real = {o: a for a in sub._actions for o in a.option_strings}
    for form in ACTIONS:
        for a in action_parser(form)._actions:
            for o in a.option_strings:
                if o in ("-h", "--help"):
                    continue
                assert o in real, (form, o)
                keys = ("choices", "default", "type", "nargs", "const")
                assert [getattr(real[o], k) for k in keys] == [getattr(a, k) for k in keys], o


def test_bundled_calibrations_are_the_test_data(tmp_path, monkeypatch):
    """lenses/calibrations/ ships the synthetic calibrations of tests/data/camera under names
    that work from any folder (the help's examples use them): the same numbers, and the same
    command result by name as by path; an existing file wins over a name."""
    from orthoscope.cli.camera import BUNDLED_CALIBRATIONS
    from raytrace.files.library import library_dir

    folder = library_dir() / "calibrations"
    assert sorted(p.stem for p in folder.glob("*.yml")) == sorted(BUNDLED_CALIBRATIONS)
    for name in BUNDLED_CALIBRATIONS:
        d = name.rsplit("-", 1)[1]
        shipped, test = folder / f"{name}.yml", DATA / f"cooke-measured-{d}.yml"
        assert read_calibration(shipped) == read_calibration(test)
        body = [ln for ln in shipped.read_text().splitlines() if not ln.startswith("#")]
        assert body == test.read_text().splitlines()
        assert "Synthetic, not a measurement" in shipped.read_text()

    def convert(word):
        return ["camera", "convert", word, "--model", "australis", "--sensor", "24x16", "--json"]

    rc, by_path, err = run(convert(str(DATA / "cooke-measured-2m.yml")))
    assert rc == 0, err
    for word in ("cooke-triplet-f4-synthetic-2m", "cooke-triplet-f4-synthetic-2m.yml"):
        rc, by_name, err = run(convert(word), tmp_path, monkeypatch)
        assert rc == 0, err
        assert by_name == by_path
    (tmp_path / "cooke-triplet-f4-synthetic-2m.yml").write_bytes(
        (DATA / "cooke-measured-5m.yml").read_bytes()
    )
    rc, local, err = run(convert("cooke-triplet-f4-synthetic-2m.yml"), tmp_path, monkeypatch)
    assert rc == 0 and local != by_path
    rc, _, err = run(["camera", "convert", "no-such-calibration", "--model", "opencv"])
    assert rc == 2 and "no-such-calibration" in err


# ------------------------------------------------------------- a flag of another form is refused
_CAL = str(DATA / "cooke-measured-2m.yml")
_FORM_ARGV = {
    "lens": BASE,
    "compare": ["camera", "compare", "cooke-triplet-f4", _CAL, "--sensor", "24x16",
                "--grid", "9x7"],
    "convert": ["camera", "convert", _CAL, "--model", "metashape", "-o", "{tmp}/out.xml"],
    "variation": ["camera", "variation", str(DATA / "cooke-measured-1m.yml"),
                  str(DATA / "cooke-measured-5m.yml"), "--calibrated-at", "1m,5m",
                  "--focal-length", "50", "--focus", "2m", "--object-distances", "1m,2m,5m",
                  "--sensor", "24x16", "-o", "{tmp}/table.csv"],
}  # fmt: skip


@pytest.mark.parametrize(
    "form,extra,words",
    [
        ("lens", ["--calibrated-at", "1m,5m"],
         "--calibrated-at is not read by `camera LENS` (it is a flag of `camera variation`); "
         "drop it"),
        # given with its default value: still given
        ("compare", ["--model", "opencv"],
         "--model is not read by `camera compare` (it is a flag of `camera LENS` and `camera "
         "convert`); drop it"),
        ("convert", ["--grid", "9x7"],
         "--grid is not read by `camera convert` (it is a flag of `camera LENS` and `camera "
         "compare`); drop it"),
        # an abbreviation (with '=') of another form's flag: named as typed, and what it would be
        ("convert", ["--gri=9x7"],
         "--gri is not a flag of `camera convert` (it would be --grid, a flag of `camera LENS` "
         "and `camera compare`); drop it"),
        ("convert", ["--csv"], "--csv is not read by `camera convert`"),
        ("variation", ["--pattern", "grid"],
         "--pattern is not read by `camera variation` (it is a flag of `camera LENS`); drop it"),
        ("variation", ["--no-clip", "--camera-id", "1", "--strict"],
         "`camera variation` does not read --no-clip (a flag of `camera LENS` and `camera "
         "compare`), --strict (a flag of `camera LENS` and `camera compare`); drop them"),
    ],
)  # fmt: skip
def test_a_form_refuses_a_flag_it_does_not_read(form, extra, words, tmp_path):
    """The command's one parser accepts every form's flags; a form refuses, before any work, a
    flag it does not read (it was silently ignored: a review found `camera convert ... --grid`
    running), naming the flag, the form and where the flag belongs."""
    argv = [a.format(tmp=tmp_path) for a in _FORM_ARGV[form]]
    rc, _, err = run([*argv, *extra])
    assert rc == 2, err
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert len(lines) == 1 and words in lines[0], err
    assert not list(tmp_path.iterdir())  # nothing written


def test_each_form_runs_with_its_own_flags(tmp_path):
    """The refusal's baseline: each form's argv of the test above runs as it is (the foreign
    flag is what fails it), also with a flag given at its default value (--method brown)."""
    for form, argv in _FORM_ARGV.items():
        argv = [a.format(tmp=tmp_path) for a in argv]
        if form == "variation":
            argv += ["--method", "brown"]
        rc, _, err = run(argv)
        assert rc == 0, (form, err)


def test_form_flags_are_the_help_pages_and_cover_the_parser():
    """One list: the flags a form accepts are those its help page shows (compare, convert,
    variation), every flag of the command's parser is some form's, and every flag notes that
    it was given (so none escapes the check)."""
    from orthoscope.cli import build_parser
    from orthoscope.cli.camera import ACTIONS, FORMS, action_parser, form_flags
    from orthoscope.cli.common import Noted

    sub = build_parser("camera")._subparsers._group_actions[0].choices["camera"]
    options = [a for a in sub._actions if a.option_strings and "--help" not in a.option_strings]
    assert all(isinstance(a, Noted) for a in options)
    every = {o for a in options for o in a.option_strings}
    assert set().union(*(form_flags(f) for f in FORMS)) == every
    for form in ACTIONS:
        page = {o for a in action_parser(form)._actions for o in a.option_strings}
        assert page - {"-h", "--help"} == form_flags(form), form
    assert {"--picture", "--grid", "--model", "--format"} <= form_flags("lens")
    assert not {"--calibrated-at", "--camera-id", "--method"} & form_flags("lens")


# ------------------------------------------------- flags that were accepted and silently ignored
def test_principal_point_replaces_the_specs_offset_in_compare(tmp_path):
    # with --camera and no --sensor / --pitch, compare took the spec's sensor whole and dropped
    # --principal-point (camera LENS --camera ... --principal-point replaced the offset)
    spec = _camera_spec(
        tmp_path,
        '[sensor]\nsize = "24x16"\npixels = "3000x2000"\nprincipal_point_offset_mm = [1.0, 1.0]\n',
    )
    argv = ["camera", "compare", "cooke-triplet-f4", _CAL, "--camera", str(spec), "--grid",
            "9x7", "--json"]  # fmt: skip
    outs = {}
    for pp in (None, "1,1", "0,0"):
        rc, out, err = run([*argv, *(["--principal-point", pp] if pp else [])])
        assert rc == 0, err
        outs[pp] = json.loads(out)["comparison"]
    assert outs[None] == outs["1,1"]  # the spec's offset, given again: the same
    assert outs["0,0"] != outs[None]
    # the offset 0,0 is the one of the same sensor without the spec
    rc, out, err = run(["camera", "compare", "cooke-triplet-f4", _CAL, "--sensor", "24x16",
                        "--grid", "9x7", "--json"])  # fmt: skip
    assert rc == 0, err
    assert json.loads(out)["comparison"] == outs["0,0"]


def test_gaussian_replaces_the_specs_focus(tmp_path):
    # --gaussian was ignored with a spec that sets [focus] (focused at 2m), while --defocus
    # replaced it
    spec = _camera_spec(
        tmp_path,
        '[sensor]\nsize = "24x16"\npixels = "1200x800"\n[focus]\ndistance = "2m"\n'
        '[object]\ndistance = "5m"\n[trace]\ngrid = [9, 7]\n',
    )
    rc, out, err = run(["camera", "cooke-triplet-f4", "--camera", str(spec), "--gaussian",
                        "--json"])  # fmt: skip
    assert rc == 0, err
    g = json.loads(out)["geometry"]
    assert g["focus_object_distance_mm"] == 5000.0 and g["object_distance_mm"] == 5000.0
    rc, out, err = run(["camera", "cooke-triplet-f4", "--camera", str(spec), "--json"])
    assert rc == 0 and json.loads(out)["geometry"]["focus_object_distance_mm"] == 2000.0


@pytest.mark.parametrize(
    "argv,words",
    [
        ([*BASE, "--pattern", "grid"],
         "--pattern sets the pattern of --picture: give --picture, or drop --pattern"),
        ([*BASE, "--maps-direction", "undistort"],
         "--maps-direction sets the direction of --maps: give --maps, or drop --maps-direction"),
        ([*BASE, "--format", "colmap"],
         "--format sets the file format of -o: give -o, or drop --format"),
        (["camera", "convert", _CAL, "--model", "metashape", "--format", "metashape"],
         "--format sets the file format of -o: give -o, or drop --format"),
        (["camera", "convert", _CAL, "--model", "metashape", "--camera-id", "1"],
         "--camera-id chooses a camera of a COLMAP cameras.txt, and "),
        (["camera", "compare", "cooke-triplet-f4", _CAL, "--sensor", "24x16", "--grid", "9x7",
          "--camera-id", "1"], "drop --camera-id"),
        (["camera", "variation", str(DATA / "cooke-measured-1m.yml"),
          str(DATA / "cooke-measured-5m.yml"), "--calibrated-at", "1m,5m", "--focal-length", "50",
          "--focus", "2m", "--object-distances", "1m,2m", "--sensor", "24x16", "--camera-id",
          "1"], "drop --camera-id"),
    ],
)  # fmt: skip
def test_a_flag_that_would_do_nothing_is_refused(argv, words, tmp_path, monkeypatch):
    # each was accepted and did nothing (exit 0); given at its default value it is given too
    rc, _, err = run(argv, tmp_path, monkeypatch)
    assert rc == 2, err
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert len(lines) == 1 and words in lines[0], err
    assert not list(tmp_path.iterdir())


def test_the_output_file_is_of_the_model_family_asked_for(tmp_path, monkeypatch):
    # convert --model metashape -o cameras.txt said "opencv -> metashape: exact" and wrote a
    # COLMAP FULL_OPENCV camera; the file's format and --model must name one family
    rc, _, err = run(["camera", "convert", _CAL, "--model", "metashape", "-o", "cameras.txt"],
                     tmp_path, monkeypatch)  # fmt: skip
    (line,) = err.strip().splitlines()
    assert rc == 2 and line.endswith(
        "-o cameras.txt writes the colmap family but --model metashape converts to metashape: "
        "give --model colmap, or -o a file of the metashape family (.xml)"
    ), err
    rc, _, err = run(["camera", "convert", _CAL, "--model", "colmap", "-o", "m.txt", "--format",
                      "australis"], tmp_path, monkeypatch)  # fmt: skip
    assert rc == 2 and "-o m.txt --format australis writes the australis family" in err, err
    rc, _, err = run([*BASE, "--model", "metashape", "-o", "cameras.txt"], tmp_path, monkeypatch)
    assert rc == 2 and "--model metashape fits metashape: give --model colmap" in err, err
    assert not list(tmp_path.iterdir())
    rc, _, err = run(["camera", "convert", _CAL, "--model", "colmap", "-o", "cameras.txt"],
                     tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    assert read_calibration(tmp_path / "cameras.txt").model.startswith("colmap:")


# ------------------------------------------- abbreviations, help, --s, the words of the refusals
def _one_line(err: str) -> str:
    lines = [ln for ln in err.strip().splitlines() if "compiling" not in ln]
    assert len(lines) == 1, err
    return lines[0]


def test_an_abbreviation_resolves_among_the_flags_of_the_form(tmp_path):
    """Abbreviated long flags stay allowed, as in every orthoscope command (`orthoscope
    distortion --obj` is argparse's), but only the form's own flags count: `variation
    --object-d` was ambiguous with `camera LENS`'s --object-distance, `compare --pi` listed
    --picture, and an abbreviation of another form's flag was named by that flag only."""
    argv = [a.format(tmp=tmp_path) for a in _FORM_ARGV["variation"][:-2]]
    rc, full, err = run(argv)
    assert rc == 0, err
    short = ["--object-d" if a == "--object-distances" else a for a in argv]
    short = ["--calib" if a == "--calibrated-at" else a for a in short]
    rc, out, err = run(short)
    assert rc == 0 and out == full, err
    rc, _, err = run(["camera", "compare", "cooke-triplet-f4", _CAL, "--pi", "24x16"])
    line = _one_line(err)
    assert rc == 2 and "--pi could match --pixels, --pitch" in line and "--picture" not in line
    rc, _, err = run([*BASE, "--calib", "1m,5m"])
    assert rc == 2 and _one_line(err).endswith(
        "error: --calib is not a flag of `camera LENS` (it would be --calibrated-at, a flag of "
        "`camera variation`); drop it"
    )
    rc, _, err = run(["camera", "convert", _CAL, "--mo", "metashape", "--ma", "x.npz"])
    assert rc == 2 and "--ma is not a flag of `camera convert` (it would be --maps, a flag of " in (
        _one_line(err)
    )
    assert not list(tmp_path.iterdir())
    rc, page, _ = run(["camera", "convert", _CAL, "--he"])  # the help, abbreviated
    assert rc == 0 and page.startswith("usage: orthoscope camera convert ")


@pytest.mark.parametrize("form", ["compare", "convert", "variation"])
def test_help_before_the_form_prints_the_form_page(form):
    # `orthoscope camera --help compare` printed the general page
    rc, page, err = run(["camera", form, "--help"])
    assert rc == 0 and page.startswith(f"usage: orthoscope camera {form} "), err
    for argv in (["camera", "--help", form], ["camera", "-h", form, "x"],
                 ["camera", "--sensor", "24x16", "--help", form]):  # fmt: skip
        rc, out, err = run(argv)
        assert rc == 0 and out == page, (argv, err)
    rc, general, _ = run(["camera", "--help", "cooke-triplet-f4"])
    assert rc == 0 and general.count("orthoscope camera") >= 4 and general != page


@pytest.mark.parametrize(
    "argv",
    [
        [*BASE, "--s", "-1000", "--object-s", "-2000"],
        [*BASE, "--object-s", "-2000", "--s", "-1000"],
        ["camera", "compare", "cooke-triplet-f4", _CAL, "--sensor", "24x16", "--s", "-2m",
         "--object-s", "-2m"],
    ],
)  # fmt: skip
def test_s_with_object_s_is_a_conflict(argv, tmp_path):
    # --s is the deprecated --object-s: both were taken, the last one winning, with a
    # deprecation line (now refused for every command when the arguments are parsed)
    rc, _, err = run([*argv, "-o", str(tmp_path / "out.json")])
    assert rc == 2, err
    assert _one_line(err).endswith(
        "error: --s and --object-s both give the object's s (--s is the deprecated spelling of "
        "--object-s): give --object-s alone"
    )
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "argv,words",
    [
        (["camera", "convert", _CAL, "--model", "metashape", "--s", "-1000"],
         "--s is not read by `camera convert`"),
        ([*_FORM_ARGV["variation"][:-2], "--s", "-1000"], "--s is not read by `camera variation`"),
        ([*BASE, "--s", "-1000", "--object-distance", "1m"],
         "give the object one way, not --s and --object-distance"),
        ([*BASE, "--object-distances", "1m,2m", "--s", "-1000"],
         "--object-distances are the table's rows: leave out --s"),
        ([*BASE, "--s", "abc"], "--s: 'abc' is not a number"),
    ],
)  # fmt: skip
def test_a_refused_s_gets_no_deprecation_line(argv, words):
    # the deprecation line came first, then the refusal
    rc, _, err = run(argv)
    assert rc == 2 and words in _one_line(err), err
    assert "deprecated" not in err


def test_an_accepted_s_still_says_it_is_deprecated():
    rc, out, err = run([*BASE, "--s", "-1000", "--json"])
    assert rc == 0, err
    assert err.count("--s is deprecated and will be removed; use --object-s") == 1
    rc, same, _ = run([*BASE, "--object-s", "-1000", "--json"])
    assert rc == 0
    a, b = json.loads(out), json.loads(same)
    assert a["geometry"] == b["geometry"] and a["geometry"]["s_mm"] == -1000.0
    for k, v in b["camera"]["parameters"].items():
        assert a["camera"]["parameters"][k] == pytest.approx(v, rel=1e-9, abs=1e-12)


_VAR = _FORM_ARGV["variation"][:-2]  # without -o


@pytest.mark.parametrize(
    "argv,words",
    [
        # the object and focus flags, named as given (API keywords before: object_distance_s,
        # object_s, "focus" for --object-distances, CameraSetup's keywords)
        ([*BASE, "--object-s", "abc"], "--object-s: 'abc' is not a number"),
        ([*BASE, "--object-s", "100"], "--object-s 100: Pestrecov's s is negative for a real"),
        ([*BASE, "--object-distance", "-5"],
         "--object-distance -5: a positive distance in mm from the object plane to the first "
         "vertex (or 2m, inf, 12x); for Pestrecov's signed s use --object-s"),
        ([*BASE, "--object-scale", "abc"], "--object-scale: 'abc' is not a number"),
        ([*BASE, "--object-distance", "1m", "--object-s", "-1000"],
         "give the object one way, not --object-distance and --object-s"),
        ([*BASE, "--object-distances", "1m,abc"], "--object-distances: 'abc' is not a number"),
        ([*BASE, "--object-distances", "abc"], "--object-distances: 'abc' is not a number"),
        ([*BASE, "--object-distances", "1m,2m", "--object-s", "-1000"],
         "--object-distances are the table's rows: leave out --object-s"),
        ([*BASE, "--object-distances", "10,2m"],
         "focused at 10 (the first of --object-distances, as no focus is given): the "
         "sensor plane would lie"),
        ([*BASE, "--focus-s", "100"], "--focus-s 100: Pestrecov's s is negative"),
        ([*BASE, "--s-prime", "-5"], "sensor at --s-prime -5 mm: the sensor plane would lie"),
        ([*BASE, "--grid", "0x0"], "--grid 0x0: write it as columns x rows, each 2..401, e.g."),
        ([*BASE, "--grid", "abc"], "--grid abc: write it as columns x rows, each 2..401, e.g."),
        # the sensor flags
        (["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "0x800"],
         "--pixels 0x800: columns and rows are whole numbers of pixels, 1..1000000"),
        (["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pitch", "abc"],
         "--pitch abc: not a number; give the pixel pitch in µm, e.g. 4.35"),
        (["camera", "cooke-triplet-f4", "--sensor", "5000x16", "--pixels", "1200x800"],
         "--sensor 5000x16: the width 5000 mm is outside"),
        (["camera", "compare", "cooke-triplet-f4", _CAL],
         "holds pixels only: give --sensor WxH (mm) or --pitch UM (or --camera SPEC.toml)"),
        (["camera", "compare", "cooke-triplet-f4", _CAL, "--sensor", "24x16", "--pitch", "20"],
         "give --sensor or --pitch (the pixel count is the calibration's 3000x2000 px)"),
        # the model, before the trace
        ([*BASE, "--model", "foo"], "--model foo: not a camera model (a family: opencv, fisheye"),
        ([*BASE, "--model", "fisheye", "--coefficients", "7"],
         "--coefficients 7 does not apply to --model fisheye: give 4, 5, 8, 12 or 14 with "
         "--model opencv, or 1 to 4 with --model fisheye"),
        ([*BASE, "--coefficients", "x"], "'x' is not a whole number; give 4, 5, 8, 12 or 14"),
        (["camera", "convert", _CAL, "--model", "opencv", "--coefficients", "6"],
         "--coefficients 6 does not apply to --model opencv: it fixes the number of "
         "coefficients of --model opencv, 4, 5, 8, 12 or 14"),
        (["camera", "convert", _CAL, "--model", "foo"], "--model foo: not a camera model"),
        # file names: no --format for an input; -o named
        (["camera", "convert", _CAL, "--model", "metashape", "-o", "x.foo"],
         "-o x.foo: the name does not tell the calibration format; end it in .yml"),
        ([*BASE, "-o", "x.foo"], "-o x.foo: the name does not tell the calibration format"),
        # variation (API keywords before: s1, focal_length_mm, method=, g)
        ([*_VAR[:4], "--calibrated-at", "abc,5m", *_VAR[6:]],
         "--calibrated-at: 'abc' is not a number"),
        ([*_VAR[:4], "--calibrated-at", "2m,2m", *_VAR[6:]],
         "--calibrated-at 2m,2m: the two calibrations are focused at the same distance"),
        ([*_VAR[:6], "--focal-length", "-50", *_VAR[8:]],
         "--focal-length: expected a positive length, got '-50'"),
        ([*_VAR, "--method", "fraser-shortis"],
         "--method fraser-shortis needs --g G (g_ss' of Fraser & Shortis' Eq. 6, e.g. 0.45)"),
        ([*_VAR, "--g", "0.5"],
         "--g is g_ss' of --method fraser-shortis (Eq. 6); Brown's Eq. 1 has none: give "
         "--method fraser-shortis, or drop --g"),
        ([*_VAR, "--g", "abc"], "'abc' is not a number; give g_ss' of Fraser & Shortis' Eq. 6"),
        # the words of a form
        (["camera", "convert"], "`camera convert` takes CALIBRATION; got none (usage: "),
        (["camera", "variation", _CAL],
         f"`camera variation` takes CAL1 CAL2; got 1: {_CAL} (usage: "),
    ],
)  # fmt: skip
def test_each_refusal_names_the_flag_in_the_command_line_words(argv, words, tmp_path, monkeypatch):
    """One line naming the flag and the fix, exit 2, no API keyword (a review found messages
    such as 'object_distance_s: ...', 'free=6: ...', 's1: ...', 'CameraSetup: grid=(0, 0)')."""
    rc, _, err = run(argv, tmp_path, monkeypatch)
    line = _one_line(err)
    assert rc == 2 and words in line, err
    keys = "object_distance|object_s|focus_s|s_prime|focal_length_mm|width_px|s1|free|g"
    assert (
        not re.search(rf"(?<![\w-])({keys})(=|:| =)", line)
        and "CameraSetup" not in line
        and "Traceback" not in err
    )
    assert not list(tmp_path.iterdir())


def test_a_setup_the_lens_cannot_image_is_named_where_it_was_given(tmp_path, monkeypatch):
    # the lens decides these (after the flags' own checks): the API said "sensor at s_prime =
    # -5 mm"; a value of the --camera spec is named by its key there, not by a flag not given
    _camera_spec(
        tmp_path,
        '[sensor]\nsize = "24x16"\npixels = "1200x800"\n[focus]\ns_prime = "-5"\n'
        "[trace]\ngrid = [9, 7]\n",
    )
    spec = ["camera", "cooke-triplet-f4", "--camera", "cam.toml"]
    for argv, said in (
        (spec, "sensor at cam.toml [focus] s_prime = -5 mm: the sensor plane would lie"),
        ([*spec, "--s-prime", "-6"], "sensor at --s-prime -6 mm: the sensor plane would lie"),
    ):
        rc, _, err = run(argv, tmp_path, monkeypatch)
        assert rc == 2 and said in _one_line(err), err


def test_an_object_value_of_the_spec_is_named_by_its_key(tmp_path, monkeypatch):
    # the API named [object] s and scale object_distance_s, object_distance_scale (no such
    # keyword): the line kept them, as no flag or key is spelt so
    head = '[sensor]\nsize = "24x16"\npixels = "1200x800"\n[trace]\ngrid = [5, 5]\n'
    for table, said in (
        ('[object]\nscale = "abc"\n', "cam.toml [object] scale: 'abc' is not a number"),
        ('[object]\ns = "abc"\n', "cam.toml [object] s: 'abc' is not a number"),
        ("[object]\ns = 100\n", "cam.toml [object] s must be negative"),
    ):
        _camera_spec(tmp_path, head + table)
        rc, _, err = run(["camera", "cooke-triplet-f4", "--camera", "cam.toml"], tmp_path,
                         monkeypatch)  # fmt: skip
        assert rc == 2 and said in _one_line(err) and "object_" not in err, err


def test_a_calibration_named_without_a_format_is_refused_with_the_names(tmp_path, monkeypatch):
    # the fix said "give --format", a flag compare does not read (and convert's --format is
    # the format of -o)
    (tmp_path / "cal.dat").write_bytes((DATA / "cooke-measured-2m.yml").read_bytes())
    for argv in (["camera", "compare", "cooke-triplet-f4", "cal.dat", "--sensor", "24x16"],
                 ["camera", "convert", "cal.dat", "--model", "metashape"]):  # fmt: skip
        rc, _, err = run(argv, tmp_path, monkeypatch)
        assert rc == 2 and _one_line(err).endswith(
            "error: cal.dat: the name does not tell the calibration format; a calibration file "
            "ends in .yml, .yaml or .json (OpenCV), .txt (COLMAP cameras.txt), .xml (Metashape) "
            "or .aus (Australis)"
        ), err


def test_camera_id_reaches_the_colmap_file_of_two(tmp_path, monkeypatch):
    """read_calibration refuses camera_id for a file that is not COLMAP: the command gives it
    to the COLMAP file only (variation of a cameras.txt and a .yml)."""
    rc, _, err = run(["camera", "convert", str(DATA / "cooke-measured-5m.yml"), "--model",
                      "colmap", "-o", "cameras.txt"], tmp_path, monkeypatch)  # fmt: skip
    assert rc == 0, err
    argv = ["camera", "variation", str(DATA / "cooke-measured-1m.yml"), "cameras.txt",
            *_VAR[4:]]  # fmt: skip
    rc, out, err = run([*argv, "--camera-id", "1"], tmp_path, monkeypatch)
    assert rc == 0, err
    rc, same, err = run(argv, tmp_path, monkeypatch)
    assert rc == 0 and same == out, err


def _count_reads(monkeypatch) -> list[str]:
    """The names of the files ``raytrace.files.text.read_capped`` (the one reader of every file a
    person names) reads from now on (in order, appended)."""
    from pathlib import Path

    import raytrace.files.text

    reads = []
    read_capped = raytrace.files.text.read_capped

    def counted(path, *args, **kw):
        reads.append(Path(path).name)
        return read_capped(path, *args, **kw)

    monkeypatch.setattr(raytrace.files.text, "read_capped", counted)
    return reads


def test_each_calibration_file_is_read_once(tmp_path, monkeypatch):
    """compare, convert and variation read each calibration file once: the text read to tell its
    format (a .txt or .xml by its content) is the text parsed (it was read a second time)."""
    (tmp_path / "cameras.txt").write_text("1 PINHOLE 3000 2000 6000 6000 1500 1000\n")
    reads = _count_reads(monkeypatch)
    for argv, names in (
        (_FORM_ARGV["compare"], ["cooke-measured-2m.yml"]),
        (["camera", "convert", _CAL, "--model", "metashape"], ["cooke-measured-2m.yml"]),
        (["camera", "convert", str(tmp_path / "cameras.txt"), "--model", "opencv"],
         ["cameras.txt"]),
        (_VAR, ["cooke-measured-1m.yml", "cooke-measured-5m.yml"]),
    ):  # fmt: skip
        reads.clear()
        rc, _, err = run(argv)
        assert rc == 0, err
        assert sorted(n for n in reads if n in names) == names, (argv, reads)


def test_each_camera_spec_is_read_once(tmp_path, monkeypatch):
    """camera LENS and compare read and parse the --camera SPEC.toml once: the spec the sensor
    is built from is the spec the camera setup is built from (it was read a second time);
    convert and variation, which read only its sensor, once too. The spec's pixels are the
    calibration's (3000x2000)."""
    _camera_spec(
        tmp_path,
        '[sensor]\nsize = "24x16"\npixels = "3000x2000"\n[focus]\ndistance = "2m"\n'
        "[trace]\ngrid = [9, 7]\n",
    )
    reads = _count_reads(monkeypatch)
    spec = ["--camera", "cam.toml"]
    for argv in (
        ["camera", "cooke-triplet-f4", *spec],
        ["camera", "cooke-triplet-f4", *spec, "--object-distances", "1m,2m"],
        ["camera", "compare", "cooke-triplet-f4", _CAL, *spec, "--object-distance", "2m"],
        ["camera", "convert", _CAL, "--model", "metashape", *spec],
        [*_VAR[:-2], *spec],  # variation: --camera in place of --sensor
    ):
        reads.clear()
        rc, _, err = run(argv, tmp_path, monkeypatch)
        assert rc == 0, (argv, err)
        assert reads.count("cam.toml") == 1, (argv, reads)


def test_the_table_kind_is_found_once_and_before_the_work(tmp_path, monkeypatch):
    """The suffix of -o of a table (lens --object-distances, compare, variation) is read once
    per run, before any work (variation read it after the calibrations)."""
    import orthoscope.cli.camera.actions as actions  # where the actions look table_kind up

    calls = []

    def counted(path, what):
        calls.append(path)
        return kind(path, what)

    kind = actions.table_kind
    monkeypatch.setattr(actions, "table_kind", counted)
    for argv in (
        [*BASE, "--object-distances", "1m,inf", "-o", str(tmp_path / "t.csv")],
        [*_FORM_ARGV["compare"], "-o", str(tmp_path / "c.json")],
        [*_VAR, "-o", str(tmp_path / "v.csv")],
    ):
        calls.clear()
        rc, _, err = run(argv)
        assert rc == 0 and len(calls) == 1, (argv, err, calls)
    rc, _, err = run(["camera", "variation", "no-such-1.yml", "no-such-2.yml", *_VAR[4:], "-o",
                      str(tmp_path / "v.txt")])  # fmt: skip
    assert rc == 2 and "-o " in _one_line(err) and "written as .csv or .json" in err, err


def test_a_binary_file_is_refused_in_one_line_by_every_text_reader(tmp_path, monkeypatch):
    # a --camera spec that is not UTF-8 text was "internal error: UnicodeDecodeError", exit 1;
    # the API's readers raised the UnicodeDecodeError itself
    from distortion.camera import read_camera_setup, read_colmap_cameras
    from distortion.errors import DataError
    from distortion.tablefile import read_distortion_table
    from distortion.variation.profiles import read_profiles_csv

    data = b"\x89PNG\r\n\x1a\n\xd0\xff" * 40
    for name in ("cam.toml", "cal.yml", "cameras.txt", "t.csv"):
        (tmp_path / name).write_bytes(data)
    rc, _, err = run(["camera", "cooke-triplet-f4", "--camera", "cam.toml"], tmp_path, monkeypatch)
    assert rc == 2 and _one_line(err).endswith(
        "error: cam.toml: not UTF-8 text; a camera spec is a text file"
    ), err
    for read, name in (
        (read_camera_setup, "cam.toml"),
        (read_calibration, "cal.yml"),
        (read_colmap_cameras, "cameras.txt"),
        (read_distortion_table, "t.csv"),
        (read_profiles_csv, "t.csv"),
    ):
        with pytest.raises(DataError, match=rf"{name}: not UTF-8 text; an? [\w .]+ is a text file"):
            read(tmp_path / name)
