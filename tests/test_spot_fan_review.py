"""Review of ``orthoscope spot`` / ``fan`` (and ``spot_diagram`` / ``ray_fan``): a field that
cannot be traced is reported, not fatal; the ray limit is the shared work limit and lifts with
--allow-large / allow_large=True; a square pattern without points says so; n is a whole number;
the CSV and JSON name the geometric radius alike."""

from __future__ import annotations

import csv
import dataclasses
import io
import json

import numpy as np
import pytest

import orthoscope as osc
from orthoscope.cli import main
from raytrace import limits
from raytrace.errors import TraceError
from raytrace.trace.fans import FieldNotTracedError

LENS = "cooke-triplet-f4"  # its chief ray of 30 deg fails (aim_failed); 0 and 20 deg trace


@pytest.fixture(scope="module")
def pinhole_front(tmp_path_factory, cooke):
    """The Cooke triplet with a 0.5 mm semi-diameter on its first surface: at 20 deg the chief
    ray traces (aimed without clipping) but every ray of the bundle is clipped."""
    s = list(cooke.surfaces)
    s[0] = dataclasses.replace(s[0], semi_diameter=0.5)
    lens = dataclasses.replace(cooke, surfaces=tuple(s))
    path = tmp_path_factory.mktemp("pinhole") / "pinhole.toml"
    osc.save_lens(lens, str(path))
    return lens, str(path)


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


# ---------------------------------------------------------------- 1: a failed field is reported
def test_spot_keeps_the_other_fields_when_one_chief_ray_fails(capsys):
    # was exit 2, "chief ray of field 30 deg fails (aim_failed)", and field 0 lost
    rc, out, err = run(capsys, "spot", LENS, "--fields", "0,30")
    assert (rc, err) == (0, "")
    rows = out.splitlines()
    assert "0 deg" in rows[2] and "217/217" in rows[2]
    assert "30 deg" in rows[3] and rows[3].endswith("aim_failed")
    assert rows[-1] == "fields not traced: 30: aim_failed"

    rc, out, _ = run(capsys, "spot", LENS, "--fields", "0,30", "--json")
    spots = json.loads(out)["spots"]
    assert rc == 0 and [s["status"] for s in spots] == ["ok", "aim_failed"]
    assert spots[0]["rays_ok"] == 217 and spots[0]["rms_radius_mm"] > 0
    bad = spots[1]
    assert (bad["field"], bad["angle_deg"], bad["rays"], bad["rays_ok"]) == (30.0, 30.0, 0, 0)
    assert bad["rms_radius_mm"] is None and bad["geometric_radius_mm"] is None
    assert bad["x_mm"] == [] and set(bad) == set(spots[0])

    rc, out, _ = run(capsys, "spot", LENS, "--fields", "0,30", "--csv")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert rc == 0 and [r["status"] for r in rows] == ["ok", "aim_failed"]
    assert rows[1]["rms_radius_mm"] == "" and float(rows[0]["rms_radius_mm"]) > 0


def test_strict_makes_a_field_not_traced_exit_2_after_the_output(capsys):
    rc, out, err = run(capsys, "spot", LENS, "--fields", "0,30", "--strict")
    assert rc == 2 and "217/217" in out and "fields not traced: 30: aim_failed" in out
    assert err.strip().endswith("1 field(s) could not be traced (see the output); --strict fails")
    assert run(capsys, "spot", LENS, "--fields", "0,20", "--strict")[0] == 0
    # the fans of both axes are one field: one field not traced
    rc, out, err = run(capsys, "fan", LENS, "--field", "30", "--axis", "both", "--strict")
    assert rc == 2 and "1 field(s) could not be traced" in err
    assert run(capsys, "fan", LENS, "--field", "20", "--strict")[0] == 0  # rim rays fail: a fan


def test_fan_reports_a_field_whose_chief_ray_fails(capsys):
    # was exit 2 with "the chief ray of field 30 deg fails (aim_failed)"
    rc, out, err = run(capsys, "fan", LENS, "--field", "30", "--axis", "both")
    assert (rc, err) == (0, "")
    lines = [ln for ln in out.splitlines() if ln]
    assert len(lines) == 2 and all("field 30 deg" in ln for ln in lines)
    assert all(ln.endswith("not traced (aim_failed: the real chief ray fails)") for ln in lines)

    rc, out, _ = run(capsys, "fan", LENS, "--field", "30", "--json")
    (fan,) = json.loads(out)["fans"]
    assert rc == 0 and fan["field_status"] == "aim_failed" and fan["pupil"] == []
    rc, out, _ = run(capsys, "fan", LENS, "--field", "14", "--json")
    assert json.loads(out)["fans"][0]["field_status"] == "ok"

    rc, out, _ = run(capsys, "fan", LENS, "--field", "30", "--axis", "both", "--csv")
    assert rc == 0 and out.splitlines()[1:] == ["y,30.0,,,,aim_failed", "x,30.0,,,,aim_failed"]


def test_a_plot_of_no_traced_field_is_refused_and_of_some_draws_those(capsys, tmp_path):
    png = tmp_path / "fan.png"
    rc, _, err = run(capsys, "fan", LENS, "--field", "30", "--plot", str(png))
    assert rc == 2 and "no field could be traced" in err and not png.exists()
    png = tmp_path / "spots.png"
    rc, out, _ = run(capsys, "spot", LENS, "--fields", "0,30", "--plot", str(png))
    assert rc == 0 and png.stat().st_size > 1000


def test_a_field_whose_rays_all_fail_is_reported_too(capsys, pinhole_front):
    lens, path = pinhole_front
    # the API raises for its one field, with the rays' status
    with pytest.raises(FieldNotTracedError, match=r"no ray of field 20 deg .*217 clipped") as e:
        osc.spot_diagram(lens, 20.0)
    assert (e.value.status_name, e.value.rays, e.value.field) == ("clipped", 217, 20.0)
    # was exit 2 with "no ray of field 20 reaches the image plane"
    rc, out, err = run(capsys, "spot", path, "--fields", "0,20", "--json")
    spots = json.loads(out)["spots"]
    assert rc == 0 and [s["status"] for s in spots] == ["ok", "clipped"]
    assert spots[1]["rays"] == 217 and spots[1]["rays_ok"] == 0
    assert spots[1]["x_mm"] == [None] * 217


def test_the_api_raises_for_its_one_field_with_the_status(cooke):
    for call in (lambda: osc.spot_diagram(cooke, 30.0), lambda: osc.ray_fan(cooke, 30.0)):
        with pytest.raises(FieldNotTracedError, match="chief ray of field 30 deg fails") as e:
            call()
        assert isinstance(e.value, TraceError)
        assert (e.value.status_name, e.value.field, e.value.field_kind) == (
            "aim_failed",
            30,
            "angle",
        )


# ---------------------------------------------------------------- 2: the shared work limit
def test_allow_large_lifts_the_fan_limit_and_the_api_has_no_smaller_cap(capsys, cooke):
    # was "pupil sampling n must be an integer 1..10000" even with --allow-large
    rc, out, err = run(capsys, "--allow-large", "fan", LENS, "--n", "20000", "--json")
    assert rc == 0 and len(json.loads(out)["fans"][0]["pupil"]) == 20000
    assert osc.ray_fan(cooke, 0.0, n=20000).pupil.size == 20000
    # over the limit: the flag is named, and what lifts it
    rc, out, err = run(capsys, "fan", LENS, "--n", str(limits.MAX_SAMPLES + 1))
    assert rc == 2 and out == ""
    assert f"--n {limits.MAX_SAMPLES + 1}: {limits.MAX_SAMPLES + 1} rays, more than" in err
    assert "give --allow-large" in err and "pupil sampling n" not in err
    with pytest.raises(TraceError, match="give allow_large=True"):
        osc.ray_fan(cooke, 0.0, n=limits.MAX_SAMPLES + 1)


def test_the_limit_counts_rays_in_the_api_and_the_command_alike(capsys, cooke, monkeypatch):
    monkeypatch.setattr(limits, "MAX_SAMPLES", 30)  # hexapolar, 3 rings: 37 rays
    with pytest.raises(TraceError, match=r"pattern='hexapolar' with n=3: 37 rays, more than 30"):
        osc.spot_diagram(cooke, 0.0, n=3)
    assert osc.spot_diagram(cooke, 0.0, n=3, allow_large=True).x.size == 37
    assert osc.spot_diagram(cooke, 0.0, n=2).x.size == 19
    with pytest.raises(TraceError, match=r"n=31: 31 rays"):
        osc.ray_fan(cooke, 0.0, n=31)
    assert osc.ray_fan(cooke, 0.0, n=31, allow_large=True).pupil.size == 31

    rc, _, err = run(capsys, "spot", LENS, "--fields", "0", "--rings", "3")
    assert rc == 2 and "--pattern hexapolar --rings 3: 37 rays, more than 30" in err
    assert "give --allow-large (before the command)" in err
    rc, out, _ = run(capsys, "--allow-large", "spot", LENS, "--fields", "0", "--rings", "3")
    assert rc == 0 and "37/37" in out


# ---------------------------------------------------------------- 3: a square pattern too coarse
@pytest.mark.parametrize("rings", ["1", "2"])
def test_a_square_grid_without_points_in_the_pupil_says_so(capsys, cooke, rings):
    # was "no ray of field 0 reaches the image plane"
    rc, out, err = run(capsys, "spot", LENS, "--pattern", "square", "--rings", rings)
    assert rc == 2 and out == ""
    assert f"--pattern square --rings {rings}: " in err and "no point inside the pupil" in err
    assert "give --rings 3 or more" in err
    with pytest.raises(TraceError, match="no point inside the pupil.*give n=3 or more"):
        osc.spot_diagram(cooke, 0.0, pattern="square", n=int(rings))
    assert osc.spot_diagram(cooke, 0.0, pattern="square", n=3).x.size == 5


# ---------------------------------------------------------------- 4: n is a whole number
@pytest.mark.parametrize("n", [2.5, 3.0, True, "3"])
def test_n_must_be_a_whole_number(cooke, n):
    # spot_diagram(L, 0, n=2.5) ran as n=2
    with pytest.raises(TraceError, match="must be a whole number"):
        osc.spot_diagram(cooke, 0.0, n=n)
    with pytest.raises(TraceError, match="must be a whole number"):
        osc.ray_fan(cooke, 0.0, n=n)


def test_numpy_integers_are_whole_numbers(cooke):
    assert osc.spot_diagram(cooke, 0.0, n=np.int64(2)).x.size == 19
    assert osc.ray_fan(cooke, 0.0, n=np.int32(5)).pupil.size == 5


# ---------------------------------------------------------------- 5: one name for the radius
def test_csv_and_json_name_the_geometric_radius_alike(capsys):
    # the CSV said geo_radius_mm where the JSON says geometric_radius_mm
    _, out, _ = run(capsys, "spot", LENS, "--fields", "0,20", "--csv")
    head = out.splitlines()[0].split(",")
    _, js, _ = run(capsys, "spot", LENS, "--fields", "0,20", "--json")
    spot = json.loads(js)["spots"][1]
    assert "geometric_radius_mm" in head and "geo_radius_mm" not in head
    assert set(head) <= set(spot), set(head) - set(spot)
    row = next(r for r in csv.DictReader(io.StringIO(out)) if r["field"] == "20.0")
    for key in head:
        if key != "status":
            assert float(row[key]) == pytest.approx(spot[key], rel=1e-15)
    assert row["status"] == spot["status"] == "ok"


# ---------------------------------------------------------------- image planes with units
@pytest.mark.parametrize(
    ("kw", "text", "mm"), [("s_prime", "50.5mm", 50.5), ("defocus", "20um", 0.02)]
)
def test_fans_and_spots_take_image_planes_with_a_unit(cooke, kw, text, mm):
    # were float()ed: "could not convert string to float: '50.5mm'"; --s-prime 50.5mm worked
    for call, ys in ((osc.ray_fan, "ey"), (osc.spot_diagram, "y")):
        with_unit, bare = call(cooke, 10, **{kw: text}), call(cooke, 10, **{kw: mm})
        assert with_unit.z_plane == bare.z_plane
        assert np.array_equal(getattr(with_unit, ys), getattr(bare, ys), equal_nan=True)
