"""One vocabulary (docs/design.md, "Vocabulary"): the same plane or object asked for through the
command line and through the API, in the same words, gives the same numbers; old spellings still
work with a warning; values with units are read in their unit."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import orthoscope as osc
from orthoscope.cli import main
from raytrace.errors import TraceError

LENS = "cooke-triplet-f4"
FIELDS = [0.0, 7.0, 14.0, 20.0]


def _cli(capsys, *argv):
    rc = main(["distortion", LENS, "--fields", ",".join(map(str, FIELDS)), "--json", *argv])
    out, err = capsys.readouterr()
    assert rc == 0, err
    return json.loads(out)["distortion"], err


PLANES = [
    ("s_prime", [49.5, 50.5]),
    ("from_last_vertex", [42.6, 43.6]),
    ("defocus", [-0.4, 0.0, 0.4]),
]
OBJECTS = [
    ("object_distance", 600.0),
    ("object_s", -650.0),
    ("object_scale", 12.0),
]


@pytest.mark.parametrize("key,values", PLANES)
def test_planes_same_words_same_numbers(capsys, key, values):
    lens = osc.load_lens(LENS)
    d, _ = _cli(capsys, f"--{key.replace('_', '-')}", ",".join(map(str, values)))
    api = osc.characteristic_distortion(lens, fields_deg=FIELDS, **{key: values})
    assert [p[f"{key}_mm"] for p in d["planes"]] == pytest.approx(values, abs=1e-12)
    for i, p in enumerate(d["planes"]):
        np.testing.assert_array_equal(np.array(p["D0_mm"], float), api.D0[i])
    assert getattr(api, key) == pytest.approx(values, abs=1e-12)


def test_gaussian_plane_same_words_same_numbers(capsys):
    lens = osc.load_lens(LENS)
    d, _ = _cli(capsys, "--gaussian")
    api = osc.characteristic_distortion(lens, fields_deg=FIELDS, plane="gaussian")
    np.testing.assert_array_equal(np.array(d["planes"][0]["D0_mm"], float), api.D0[0])
    assert d["planes"][0]["defocus_mm"] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("key,value", OBJECTS)
def test_objects_same_words_same_numbers(capsys, key, value):
    lens = osc.load_lens(LENS)
    d, _ = _cli(capsys, f"--{key.replace('_', '-')}", str(value), "--gaussian")
    api = osc.characteristic_distortion(lens, fields_deg=FIELDS, **{key: value})
    assert d["object_distance_mm"] == pytest.approx(api.object_distance, rel=1e-15)
    np.testing.assert_array_equal(np.array(d["planes"][0]["D0_mm"], float), api.D0[0])


def test_object_keywords_mean_what_they_say():
    lens = osc.load_lens(LENS)
    p = osc.paraxial(lens)
    # object_s is Pestrecov's s from H: the object plane sits at z_H + s
    d = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_s=-650.0)
    assert -d.object_distance == pytest.approx(p.z_H - 650.0, abs=1e-9)
    # object_scale N: Gaussian magnification -1/N (Pestrecov Eq. 5)
    d = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_scale=12.0)
    assert d.gaussian_constant == pytest.approx(-1.0 / 12.0, rel=1e-12)
    # "12x" as an object distance is the same object
    e = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_distance="12x")
    assert e.object_distance == d.object_distance
    with pytest.raises(TraceError, match="one way"):
        osc.characteristic_distortion(lens, fields_deg=FIELDS, object_s=-650.0, object_scale=12)


def test_old_spellings_work_with_a_warning(capsys):
    new, _ = _cli(capsys, "--object-s", "-650", "--s-prime", "50.5")
    old, err = _cli(capsys, "--s", "-650", "--image-distance", "50.5")
    assert "deprecated" in err and "--object-s" in err and "--s-prime" in err
    assert old == new
    # calibrate's --criterion (now --method, which it requires): the old spelling still runs
    table = str(Path(__file__).parent / "data" / "pestrecov_table1.csv")
    assert main(["calibrate", table, "--method", "minimax", "--json"]) == 0
    new = capsys.readouterr().out
    assert main(["calibrate", table, "--criterion", "minimax", "--json"]) == 0
    cap = capsys.readouterr()
    assert cap.out == new and "--criterion is deprecated" in cap.err and "--method" in cap.err
    assert main(["calibrate", table]) == 2
    assert "the following argument is required: --method" in capsys.readouterr().err


def test_the_api_reads_lengths_and_scales_as_the_command_line_does():
    # README: "lengths may carry a unit" held only for the flags; the keywords raised
    lens = osc.load_lens(LENS)
    a = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_distance="1.5m")
    b = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_distance=1500.0)
    assert a.object_distance == b.object_distance == 1500.0
    np.testing.assert_array_equal(a.D0, b.D0)
    c = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_scale="12x")
    d = osc.characteristic_distortion(lens, fields_deg=FIELDS, object_scale=12)
    assert c.object_distance == d.object_distance
    with pytest.raises(osc.OrthoscopeError, match=r"^object_scale: 'abc' is not a number"):
        osc.characteristic_distortion(lens, fields_deg=FIELDS, object_scale="abc")
    # calibrate: the default needs no fields (minimax); at= may be written as on the CLI
    assert osc.calibrate(b).method == "minimax"
    two = osc.calibrate(b, "two-point", at=f"{FIELDS[-2]:g},{FIELDS[-1]:g}")
    assert two.Kc == osc.calibrate(b, "two-point", at=(FIELDS[-2], FIELDS[-1])).Kc
    with pytest.raises(osc.CalibrationError, match=r"at='a,b' is not a field value"):
        osc.calibrate(b, "two-point", at="a,b")


def test_an_object_inside_the_focal_length_is_explained(capsys):
    # 1.5 typed for 1.5 m: the object sits 1.5 mm in front of the lens, inside the front focal
    # length, and the error says so in one line (it once read "image plane the Gaussian ...")
    rc = main(["distortion", LENS, "--object-distance", "1.5", "--fields", "5"])
    err = [x for x in capsys.readouterr().err.splitlines() if "compiling" not in x]
    assert rc == 2 and len(err) == 1
    assert re.search(r"error: the Gaussian image plane lies -\d+\.\d+ mm from the last", err[0])
    assert "1.5 mm in front of the first vertex, is inside the front focal length" in err[0]
    assert "1.5m for metres" in err[0]


def test_lengths_and_wavelengths_with_units(capsys):
    a, _ = _cli(capsys, "--object-distance", "0.6m", "--s-prime", "5.05cm")
    b, _ = _cli(capsys, "--object-distance", "600", "--s-prime", "50.5")
    assert a == b
    c, _ = _cli(capsys, "--wavelength", "0.5461um")
    d, _ = _cli(capsys, "--wavelength", "546.1")
    assert c == d
    rc = main(["paraxial", LENS, "--wavelength", "0.5461"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "looks like micrometres" in err and "0.5461um" in err


def test_gaussian_adds_its_plane_to_a_list_of_planes(capsys):
    # "--s-prime 49,51 --gaussian": three planes, the last the Gaussian one (it was refused, with
    # a hint that led to another refusal)
    three, _ = _cli(capsys, "--s-prime", "49,51", "--gaussian")
    alone, _ = _cli(capsys, "--gaussian")
    assert [p["s_prime_mm"] for p in three["planes"][:2]] == [49.0, 51.0]
    assert three["planes"][2] == alone["planes"][0]
