"""``orthoscope report`` / ``calibration_certificate`` after review: the work limit of the field
step (raytrace.limits, ``allow_large=`` / ``--allow-large``), long tables in the text and on the
page, the decentering of a centred lens printed as 0, and output paths that name a folder or a
folder that takes no files (orthoscope.cli.common, every command that writes through it).

Referees: the counts of the chief rays the certificate traces (counted here from its arrays),
the page's own text extents (matplotlib's renderer), and closed-form decentered fields (Brown
1966 with Fraser's P1/P2 placement, as in tests/test_certificate.py).
"""

from __future__ import annotations

import dataclasses
import math
import os
import re

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from support import run_cli

import distortion.certificate as dcert
import distortion.grid
from distortion.certificate import DENSE_FIELDS, calibration_certificate
from distortion.errors import DataError
from orthoscope.cli.common import check_output_path
from orthoscope.plots.certificate import plot_certificate
from orthoscope.plots.common import offscreen_figures
from orthoscope.report.certificate import (
    ACROSS_MAX_FIELDS,
    certificate_to_dict,
    format_certificate,
    page_field_indices,
    page_numbers,
)
from raytrace.files.library import load_lens
from raytrace.limits import MAX_FIELDS

DATE = "2026-01-31"
# the fixtures cooke (lens field 20 deg, semi-diagonals at 45 + k 90 deg) and topogon (lens
# field 45 deg): tests/conftest.py


def _no_trace(monkeypatch):
    """Any trace (or making the table's fields) fails the test: a refusal comes first."""

    def boom(*a, **k):
        raise AssertionError("traced before the work limit was checked")

    monkeypatch.setattr(distortion.grid, "grid_from_fields", boom)
    monkeypatch.setattr(dcert, "_table_fields", boom)


# ---------------------------------------------------------------- 1. the work limit
@pytest.mark.parametrize("step", [1e-7, 1e-6, 1e-4])
def test_api_refuses_a_tiny_step_before_any_trace(cooke, step, monkeypatch):
    _no_trace(monkeypatch)
    with pytest.raises(DataError, match=r"more than 100000 .*allow_large=True") as e:
        calibration_certificate(cooke, field_step_deg=step)
    n = math.floor(20.0 / step + 1e-9)
    assert f"{n} tabulated fields" in str(e.value)


def test_limit_is_the_chief_rays_the_certificate_traces(cooke, monkeypatch):
    """The limit counts exactly the semi-diagonals' rays: tabulated, dense and corner fields on
    each of the four (counted here from what the run traces)."""
    real = distortion.grid.grid_from_fields
    traced = []

    def counting(lens, FX, FY, kind, par, **kw):
        traced.append(np.size(FX))
        return real(lens, FX, FY, kind, par, **kw)

    monkeypatch.setattr(distortion.grid, "grid_from_fields", counting)
    c = calibration_certificate(cooke, field_step_deg=0.1)  # 200 fields
    rays = traced[0]
    assert rays == 4 * (c.fields_deg.size + DENSE_FIELDS + 4) == 4 * (200 + 95)
    monkeypatch.setattr(dcert, "MAX_FIELDS", rays)
    calibration_certificate(cooke, field_step_deg=0.1)  # exactly at the limit: runs
    monkeypatch.setattr(dcert, "MAX_FIELDS", rays - 1)
    with pytest.raises(DataError, match=f"{rays} chief rays"):
        calibration_certificate(cooke, field_step_deg=0.1)
    c2 = calibration_certificate(cooke, field_step_deg=0.1, allow_large=True)
    assert c2.fields_deg.size == 200


def test_the_suggested_step_runs(cooke, monkeypatch):
    monkeypatch.setattr(dcert, "MAX_FIELDS", 1000)
    with pytest.raises(DataError) as e:
        calibration_certificate(cooke, field_step_deg=0.01)
    step = float(re.search(r"a step of at least ([0-9.]+) deg", str(e.value)).group(1))
    c = calibration_certificate(cooke, field_step_deg=step)
    assert 4 * (c.fields_deg.size + DENSE_FIELDS + 4) <= 1000
    # and it is near the smallest: 10 % less is refused
    with pytest.raises(DataError):
        calibration_certificate(cooke, field_step_deg=0.9 * step)


def test_the_shared_limit_is_the_command_lines(cooke):
    assert dcert.MAX_FIELDS == MAX_FIELDS  # raytrace.limits, as every command's


def test_cli_refuses_in_its_own_words_and_allow_large_lifts_it(monkeypatch):
    _no_trace(monkeypatch)
    rc, out, err = run_cli(["report", "cooke-triplet-f4", "--field-step", "1e-6"])
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("orthoscope report: error: --field-step 1e-06")
    assert "--allow-large (before the command)" in err and "allow_large" not in err
    monkeypatch.undo()
    monkeypatch.setattr(dcert, "MAX_FIELDS", 400)  # 4 x (27 + 95) = 488 rays at 0.75 deg
    rc, _, err = run_cli(["report", "cooke-triplet-f4", "--field-step", "0.75"])
    assert rc == 2 and "--allow-large" in err
    rc, out, err = run_cli(["--allow-large", "report", "cooke-triplet-f4", "--field-step", "0.75"])
    assert rc == 0, err
    assert "one row per field (27 fields)" in out


# ---------------------------------------------------------------- 1b. long text tables
def _table_lines(text: str) -> list[str]:
    lines = text.splitlines()
    i = next(i for i, ln in enumerate(lines) if ln.startswith("Radial distortion (um)"))
    j = next(j for j in range(i, len(lines)) if lines[j] == "")
    return lines[i:j]


def test_text_tabulates_many_fields_one_row_per_field(cooke):
    c = calibration_certificate(cooke, field_step_deg=0.5, date=DATE)  # 40 fields
    d = certificate_to_dict(c)
    lines = _table_lines(format_certificate(d))
    assert "one row per field (40 fields)" in lines[0]
    rows = lines[4:]
    assert len(rows) == 40
    assert max(len(ln) for ln in lines) <= 100  # the old table was one 400-column line
    for j in (0, 19, 39):
        cells = rows[j].split()
        assert float(cells[0]) == pytest.approx(d["fields_deg"][j])
        assert float(cells[1]) == pytest.approx(d["radius_mm"][j], abs=5e-4)
        for i in range(4):
            assert float(cells[2 + i]) == pytest.approx(
                d["semi_diagonals"][i]["radial_um"][j], abs=0.05
            )
        assert float(cells[6]) == pytest.approx(d["mean_radial_um"][j], abs=0.05)
        assert float(cells[7]) == pytest.approx(d["decentering"]["profile_um"][j], abs=0.05)
    # up to ACROSS_MAX_FIELDS the USGS form stays: fields across
    d7 = certificate_to_dict(calibration_certificate(cooke, date=DATE))
    assert _table_lines(format_certificate(d7))[1].split()[-3:] == ["7.50", "15.00", "20.00"]


def test_fine_steps_print_distinct_field_angles(cooke):
    # 0.005 deg over a 0.25 deg format: at 2 decimals 0.005 and 0.010 both print "0.01"
    c = calibration_certificate(cooke, field_step_deg=0.005, max_field_deg=0.25, date=DATE)
    rows = _table_lines(format_certificate(c))[4:]
    fields = [ln.split()[0] for ln in rows]
    assert len(fields) == 50 and len(set(fields)) == 50
    assert fields[:2] == ["0.005", "0.010"]


# ---------------------------------------------------------------- 2. the page's table
def _table_texts(fig, d):
    """The page's number cells of the radial table and the profile row, by table row."""
    rows: dict[float, list] = {}
    for t in fig.texts:
        gid = t.get_gid() or ""
        if re.match(r"(fields_deg|radius_mm|mean_radial_um|decentering/profile_um)/\d", gid) or (
            re.match(r"semi_diagonals/\d/radial_um/\d", gid)
        ):
            rows.setdefault(round(t.get_position()[1], 6), []).append(t)
    return rows


@pytest.mark.parametrize("step", [3.75, 2.5, 1.0, 0.25])
def test_page_table_never_overprints(topogon, step):
    """Neighbouring numbers of each table row keep at least 2 pt between them (the old page
    overprinted from 12 columns, 3.75 deg on the Topogon), and at most ACROSS_MAX_FIELDS
    columns are printed; every printed number is the page's cell (page_numbers)."""
    d = certificate_to_dict(calibration_certificate(topogon, field_step_deg=step, date=DATE))
    with offscreen_figures():
        fig = plot_certificate(d)
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        r = canvas.get_renderer()
        rows = _table_texts(fig, d)
        assert len(rows) == 8  # fields, r, four semi-diagonals, mean, and the profile row
        for texts in rows.values():
            boxes = sorted((t.get_window_extent(r) for t in texts), key=lambda b: b.x0)
            assert len(boxes) <= ACROSS_MAX_FIELDS
            gap_px = min(b.x0 - a.x1 for a, b in zip(boxes, boxes[1:], strict=False))
            assert gap_px >= 2.0 * fig.dpi / 72.0, (step, gap_px)
        gids = {t.get_gid() for t in fig.texts if t.get_gid()}
    assert gids == set(page_numbers(d))
    idx, k = page_field_indices(d)
    assert idx[-1] == len(d["fields_deg"]) - 1  # the edge is always on the page
    note = any("The page tabulates one field in every" in t.get_text() for t in fig.texts)
    assert note == (k > 1)


def test_page_picks_a_round_step_for_many_fields(cooke):
    d = certificate_to_dict(calibration_certificate(cooke, field_step_deg=0.01, date=DATE))
    idx, k = page_field_indices(d)
    assert len(d["fields_deg"]) == 2000 and k == 200
    assert [round(d["fields_deg"][j], 9) for j in idx] == [2.0 * i for i in range(1, 11)]


# ---------------------------------------------------------------- 3. a centred lens: zero
def test_centred_lens_decentering_prints_zero(cooke):
    c = calibration_certificate(cooke, date=DATE)
    dec = c.decentering
    assert dec["P1"] == 0.0 and dec["P2"] == 0.0 and dec["J"] == 0.0  # not 7e-19
    assert dec["S1"] == 0.0 and dec["S2"] == 0.0
    assert np.all(c.decentering_profile_um == 0.0)
    assert math.isnan(dec["axis_deg"])
    text = format_certificate(c)
    p1 = next(ln for ln in text.splitlines() if ln.strip().startswith("P1 "))
    assert p1.split()[1] == "0.0000e+00", p1
    assert "e-1" not in text.split("Decentering distortion")[1].split("Radial distortion")[0]
    assert any("given as 0" in n for n in c.notes)


def _brown(t, c, P1, P2):
    x, y = c * t[..., 0], c * t[..., 1]
    r2 = x * x + y * y
    xp = x + P1 * (r2 + 2 * x * x) + 2 * P2 * x * y
    yp = y + 2 * P1 * x * y + P2 * (r2 + 2 * y * y)
    return np.stack([xp, yp], axis=-1)


@pytest.mark.parametrize("J,kept", [(1e-11, True), (1e-13, False)])
def test_only_decentering_below_the_floor_is_zeroed(cooke, monkeypatch, J, kept):
    """A synthetic decentered field (the traced points replaced by Brown's model): J r^2 at the
    edge (18.3 mm) of 3.3e-9 mm is above the 1e-9 mm floor and recovered; 3.3e-11 mm is
    below it and given as 0."""
    real = distortion.grid.grid_from_fields
    P1, P2 = 0.6 * J, -0.8 * J

    def fake(lens, FX, FY, kind, par, **kw):
        g = real(lens, FX, FY, kind, par, **kw)
        c = float(g.camera_constant[0])
        t = np.stack([g.tx, g.ty], axis=-1)
        return dataclasses.replace(g, actual=_brown(t, c, P1, P2)[None], axial_xy=np.zeros((1, 2)))

    monkeypatch.setattr(distortion.grid, "grid_from_fields", fake)
    c = calibration_certificate(cooke, reference_point="axial")
    if kept:
        assert c.decentering["J"] == pytest.approx(J, rel=1e-4)
        assert c.decentering["P1"] == pytest.approx(P1, rel=1e-4)
        assert math.isfinite(c.decentering["axis_deg"])
    else:
        assert c.decentering["J"] == 0.0 and c.decentering["P1"] == 0.0
        assert math.isnan(c.decentering["axis_deg"])


# ---------------------------------------------------------------- 4. output paths
def test_trailing_slash_is_a_folder_and_nothing_is_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, out, err = run_cli(["report", "cooke-triplet-f4", "-o", "d.pdf/"])
    assert rc == 2 and out == ""  # refused before the certificate was printed
    assert err.count("\n") == 1 and "names a folder" in err, err
    assert list(tmp_path.iterdir()) == []


needs_proc = pytest.mark.skipif(
    not os.path.isdir("/proc/self"), reason="needs /proc: a folder that takes no new files"
)


@needs_proc
@pytest.mark.parametrize(
    "argv",
    [
        ["report", "cooke-triplet-f4", "-o", "/proc/c.pdf"],
        ["colour", "cooke-triplet-f4", "--plot", "/proc/c.png"],
    ],
)
def test_a_folder_that_takes_no_files_is_refused_before_the_work(argv):
    rc, out, err = run_cli(argv)
    assert rc == 2 and out == "", out[:200]  # the old run printed the whole table first
    assert err.count("\n") == 1 and "does not take new files" in err, err


class _Args:
    force = False
    _inputs: list = []


@pytest.mark.parametrize("name", ["x.png/", "sub/x.pdf/"])
def test_check_output_path_refuses_a_folder_name(tmp_path, name):
    from raytrace.errors import OutputError

    with pytest.raises(OutputError, match="names a folder"):
        check_output_path(f"{tmp_path}{os.sep}{name}", _Args())


def test_every_writer_refuses_a_folder_name(tmp_path):
    # the check lives in raytrace.files.output.check_output, so the API's writers have it too
    # (convert wrote 'x.toml' for 'x.toml/', as report did for 'd.pdf/')
    import orthoscope as osc
    from raytrace.errors import OutputError

    lens = osc.load_lens("cooke-triplet-f4")
    with pytest.raises(OutputError, match="names a folder"):
        osc.convert("cooke-triplet-f4", f"{tmp_path}{os.sep}x.toml{os.sep}")
    with pytest.raises(OutputError, match="names a folder"):
        osc.save_lens(lens, f"{tmp_path}{os.sep}y.zmx{os.sep}")
    assert list(tmp_path.iterdir()) == []


def test_the_folder_probe_leaves_nothing_behind(tmp_path):
    check_output_path(str(tmp_path / "x.pdf"), _Args())
    assert list(tmp_path.iterdir()) == []
    if hasattr(os, "geteuid") and os.geteuid() != 0:  # root writes anywhere the bits say not
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        try:
            with pytest.raises(Exception, match="not writable|does not take new files"):
                check_output_path(str(ro / "x.pdf"), _Args())
        finally:
            ro.chmod(0o755)


@pytest.mark.parametrize("bad", ["not a date", "2026-13-01", "31.01.2026"])
def test_the_api_refuses_a_date_that_is_not_one(bad):
    # the CLI's --date refused these; the API printed them on the certificate
    lens = load_lens("cooke-triplet-f4")
    with pytest.raises(DataError, match="is not a date; write it as YYYY-MM-DD"):
        calibration_certificate(lens, date=bad)
    assert calibration_certificate(lens, date="2026-01-31").date == "2026-01-31"


@pytest.mark.parametrize(
    "argv",
    [
        ["camera", "convert", "cooke-triplet-f4-synthetic-2m", "--model", "opencv", "-o", "-"],
        ["report", "cooke-triplet-f4", "-o", "-"],
        ["distortion", "cooke-triplet-f4", "--plot", "-"],
    ],
)
def test_a_dash_is_standard_output_and_no_file_is_written(tmp_path, monkeypatch, argv):
    # `-o -` wrote a file literally named "-" ("wrote -")
    monkeypatch.chdir(tmp_path)
    rc, out, err = run_cli(argv)
    assert rc == 2 and err.count("\n") == 1 and "names standard output" in err, err
    assert list(tmp_path.iterdir()) == []
