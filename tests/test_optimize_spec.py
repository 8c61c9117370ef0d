"""The spec language (raytrace.optimize.read_spec; docs/spec.md): every key checked, typos
answered with the nearest valid key, wrong types refused (``surface = 1.5`` is not 1), all
problems of a file reported together one line each; the glass pool; the shipped specs."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from support import ROOT, read_spec_text

from raytrace.glass import catalog_glasses
from raytrace.optimize import (
    GlassSettings,
    SpecError,
    availability,
    check_spec,
    glass_pool,
    parse_duration,
    read_spec,
    start_lens,
)

HEAD = 'start = "cooke-triplet-f4"\n'
OK_VAR = 'variables = [ { kind = "curvature", surface = 1 } ]\n'
OK_OP = 'operands = [ { type = "efl", target = 50 } ]\n'


_read = read_spec_text


@pytest.mark.parametrize(
    "text, message",
    [
        (HEAD + "variabels = []\n" + OK_OP, "unknown key 'variabels' (did you mean 'variables'?)"),
        (
            HEAD + 'variables = [ { kind = "curvature", sufrace = 1 } ]\n' + OK_OP,
            "unknown key 'sufrace' (did you mean 'surface'?)",
        ),
        (
            HEAD + 'variables = [ { kind = "curvature", surface = 1.5 } ]\n' + OK_OP,
            "'surface' must be an integer (1-based), got 1.5",
        ),
        (
            HEAD + 'variables = [ { kind = "curvatur", surface = 1 } ]\n' + OK_OP,
            "unknown variable kind 'curvatur' (did you mean 'curvature'?)",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "distortion", feild = 20 } ]\n',
            "unknown key 'feild' for operand distortion (did you mean 'field'?)",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "distortion_slop", field = 20 } ]\n',
            "unknown operand type 'distortion_slop' (did you mean 'distortion_slope'?)",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "distortion", field = 20, '
            "plane = { s_prim = 425 } } ]\n",
            "plane: unknown key 's_prim' (did you mean 's_prime'?)",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "distortion", field = "20" } ]\n',
            "'field' must be a number",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "efl", target = 50, weight = -1 } ]\n',
            "'weight' must be a non-negative number",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "center_thickness", surface = true, '
            "min = 1 } ]\n",
            "'surface' must be an integer (1-based), got True",
        ),
        (
            HEAD + OK_VAR + 'operands = [ { type = "distortion", field = 20, object_s = -55, '
            "object_distance = 40 } ]\n",
            "give the object one way",
        ),
        (HEAD + OK_VAR + OK_OP + "[global]\nstrats = 4\n", "[global]: unknown key 'strats'"),
        (HEAD + OK_VAR + OK_OP + '[global]\ntime = "10 minutes"\n', "bad duration"),
        (HEAD + OK_VAR + OK_OP + "[global]\nstarts = 2.0\n", "'starts' must be an integer"),
        (
            HEAD + OK_VAR + OK_OP + '[glass]\ncatalogs = ["Shott"]\n',
            "unknown glass catalog 'Shott' (did you mean 'Schott'?)",
        ),
        (
            HEAD + OK_VAR + OK_OP + '[glass]\navailability = ["curent"]\n',
            "unknown availability class 'curent' (did you mean 'current'?)",
        ),
        (
            HEAD + 'variables = [ { kind = "glass", surface = 1, min = 1 } ]\n' + OK_OP,
            "unknown key 'min'",
        ),
        (
            HEAD + OK_VAR + OK_OP + 'pickups = [ { kind = "glass", surface = 5, source = 1, '
            "factor = 2 } ]\n",
            "a glass pick-up copies the glass",
        ),
        ("variables = []\noperands = []\n", "'start' (the start lens"),
    ],
)
def test_spec_errors_name_the_problem(tmp_path: Path, text: str, message: str):
    with pytest.raises(SpecError) as e:
        _read(tmp_path, text)
    assert message in str(e.value)
    assert str(tmp_path / "s.toml") in str(e.value)


def test_all_problems_one_line_each(tmp_path: Path):
    text = (
        'strat = "cooke-triplet-f4"\n'
        'variables = [ { kind = "curvature", surface = 1.5 },\n'
        '  { kind = "thikness", surface = 2 } ]\n'
        'operands = [ { type = "efl", targt = 50 } ]\n'
    )
    with pytest.raises(SpecError) as e:
        _read(tmp_path, text)
    lines = str(e.value).splitlines()
    assert lines[0].endswith("5 problems:")
    body = lines[1:]
    assert len(body) == 5
    assert any("unknown key 'strat' (did you mean 'start'?)" in ln for ln in body)
    assert any("'start' (the start lens" in ln for ln in body)
    assert any("variables[1]: 'surface' must be an integer" in ln for ln in body)
    assert any("variables[2]: unknown variable kind 'thikness'" in ln for ln in body)
    assert any("operands[1] (efl): unknown key 'targt'" in ln for ln in body)


def test_full_spec_parses(tmp_path: Path):
    spec = _read(
        tmp_path,
        HEAD + 'variables = [ { kind = "curvature", surface = 1, min = -0.1, max = "inf" },\n'
        '  { kind = "glass", surface = 1, nd = [1.5, 1.7], glasses = ["N-BK7", "N-SK16"] },\n'
        '  { kind = "glass", surface = 3 } ]\n'
        'pickups = [ { kind = "glass", surface = 5, source = 1 } ]\n'
        "operands = [\n"
        '  { type = "distortion", field = 45, object_s = -55.0009, plane = { s_prime = 425 } },\n'
        '  { type = "distortion_slope", field = 45, object_s = -55.0009, weight = 1e4 },\n'
        '  { type = "landing_angle", field = 20, target = 3.5 },\n'
        '  { type = "axial_color", wavelengths = [486.1327, 656.2725] },\n'
        '  { type = "rms_spot", field = 14, plane = "best", wavelength = 486.1327 },\n'
        '  { type = "edge_thickness", surface = 1, height = 6, min = 0.8 },\n'
        "]\n"
        '[glass]\ncatalogs = ["Schott", "ohara"]\navailability = ["current", "withdrawn"]\n'
        "neighbours = 4\n"
        '[global]\nstarts = 16\nseed = 3\nhops = 2\ntime = "1h30m"\nworkers = 2\n',
    )
    v1, g1, g3 = spec.variables
    assert (v1.lower, v1.upper) == (-0.1, math.inf)
    assert g1.glass.nd == (1.5, 1.7) and g1.glass.glasses == ("N-BK7", "N-SK16")
    assert g1.glass.catalogs == ("Schott", "Ohara")  # the spec-level pool, then overridden
    assert g3.glass is None and spec.glass_settings(g3).neighbours == 4
    assert spec.search.starts == 16 and spec.search.time_budget_s == 5400.0
    assert spec.operands[0].params["plane"] == {"s_prime": 425}
    assert [o.type for o in spec.operands][1:3] == ["distortion_slope", "landing_angle"]
    check_spec(start_lens(spec), spec)


@pytest.mark.parametrize(
    "text, seconds",
    [("90s", 90.0), ("10m", 600.0), ("1h30m", 5400.0), ("2.5h", 9000.0), (45, 45.0), ("20", 20.0)],
)
def test_durations(text, seconds):
    assert parse_duration(text) == seconds


@pytest.mark.parametrize("text", ["10 minutes", "", "-5m", "0s", "m", True])
def test_bad_durations(text):
    with pytest.raises(SpecError):
        parse_duration(text)


SHIPPED = [
    p for p in sorted((ROOT / "lenses" / "specs").glob("*.toml")) if not p.stem.endswith("-start")
]


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_specs_still_read_and_apply(path: Path):
    spec = read_spec(path)
    check_spec(start_lens(spec), spec, need_continuous=False)


# --------------------------------------------------------------------------- glass pool
def test_glass_pool_filters_and_classes():
    current = glass_pool(GlassSettings(catalogs=("Schott",)))
    every = glass_pool(
        GlassSettings(catalogs=("Schott",), availability=("current", "withdrawn", "legacy"))
    )
    assert 0 < len(current) < len(every)
    assert all(availability(g) == "current" for g in current.glasses)
    # Schott's current catalog: N-BK7 and its HT / HTi twins (same nd, vd) enter once
    names = [g.name for g in current.glasses]
    assert "N-BK7" in names and "N-BK7HT" not in names
    n_distinct = len({(g.nd, g.vd) for g in catalog_glasses("Schott") if g.status == ""})
    assert len(current) == n_distinct
    win = glass_pool(GlassSettings(catalogs=("Schott",), nd=(1.5, 1.6), vd=(50, 70)))
    assert all(1.5 <= g.nd <= 1.6 and 50 <= g.vd <= 70 for g in win.glasses)
    # nearest on the glass map (glass-code units): N-BK7 itself for 517/642
    i = int(current.nearest(1.5168, 64.17)[0])
    assert current.glasses[i].name == "N-BK7"
    assert i not in current.neighbours(i, 3) and len(current.neighbours(i, 3)) == 3


def test_glass_pool_errors():
    with pytest.raises(SpecError, match="unknown glass 'N-BK77'"):
        glass_pool(GlassSettings(glasses=("N-BK77",)))
    with pytest.raises(SpecError, match="widen the windows"):
        glass_pool(GlassSettings(nd=(3.0, 3.1)))


def test_glass_max_price_key(tmp_path):
    head = 'start = "cooke-triplet-f4"\nvariables = [ { kind = "curvature", surface = 1 } ]\n'
    head += 'operands = [ { type = "efl", target = 50 } ]\n'
    spec = _read(tmp_path, head + "[glass]\nmax_price = 3\n")
    assert spec.glass.max_price == 3.0
    spec = _read(
        tmp_path,
        head.replace(
            "variables = [", 'variables = [ { kind = "glass", surface = 1, max_price = 1.5 },'
        )
        + "[glass]\nmax_price = 3\n",
    )
    assert spec.glass_settings(spec.variables[0]).max_price == 1.5
    with pytest.raises(SpecError, match=r"max_price.*positive number"):
        _read(tmp_path, head + "[glass]\nmax_price = -1\n")


def test_a_misspelt_key_is_one_problem_not_two(tmp_path):
    # docs/spec.md shows "2 problems" for two typos; each typo also produced a "missing key"
    # line (4 problems) until the reader remembered which key a misspelling stood for
    p = tmp_path / "my.toml"
    p.write_text(
        'name = "x"\nstart = "cooke-triplet-f4"\n'
        'variables = [ { kind = "curvature", surface = 1 }, { kind = "thickness", sufrace = 2 } ]\n'
        'operands = [ { type = "efl", target = 50 }, '
        '{ type = "distortion", feild = 20, target = 0 } ]\n'
    )
    with pytest.raises(SpecError) as e:
        read_spec(p)
    lines = str(e.value).splitlines()
    assert lines[0].endswith("2 problems:")
    assert "variables[2]: unknown key 'sufrace' (did you mean 'surface'?)" in lines[1]
    assert "unknown key 'feild' for operand distortion (did you mean 'field'?)" in lines[2]


def test_a_path_with_a_folder_is_never_a_bundled_name(tmp_path, monkeypatch):
    # nodir/twinplex-like-55-525 (a folder that does not exist) ran the bundled spec in silence
    from raytrace.optimize import read_spec
    from raytrace.tolerance.spec import resolve_spec_path

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SpecError, match="no such"):
        read_spec("nodir/twinplex-like-55-525")
    assert read_spec("twinplex-like-55-525").start  # the bare name still finds it
    assert resolve_spec_path("nodir/cooke-triplet-f4") == Path("nodir/cooke-triplet-f4")
    assert resolve_spec_path("cooke-triplet-f4").is_file()


def test_cli_a_missing_spec_path_names_the_bundled_spec_of_that_name(tmp_path, monkeypatch, capsys):
    # the docs' path lenses/specs/twinplex-like-55-525.toml, typed outside the repository
    from orthoscope.cli import main

    monkeypatch.chdir(tmp_path)
    spec = "lenses/specs/twinplex-like-55-525.toml"
    assert main(["optimize", spec, "-o", "out.toml"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line == (
        f"orthoscope optimize: error: {spec}: no such spec file; the bundled spec of that name "
        "is `orthoscope optimize twinplex-like-55-525`"
    )
    # a name no bundled spec has: the plain error
    assert main(["optimize", "lenses/specs/no-such-design.toml", "-o", "out.toml"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.endswith("no-such-design.toml: no such spec file")
    assert not (tmp_path / "out.toml").exists()


def test_a_bare_spec_file_name_with_toml_finds_the_bundled_spec(tmp_path, monkeypatch):
    # NAME.toml with no folder and no such local file: the bundled spec, as calibrate and camera
    # find their bundled files by NAME.csv / NAME.yml (it was "no such spec file")
    from raytrace.optimize import read_spec
    from raytrace.tolerance.spec import resolve_spec_path

    monkeypatch.chdir(tmp_path)
    spec = read_spec("twinplex-like-55-525.toml")
    assert Path(spec.path).parent.name == "specs"
    assert spec.start == read_spec("twinplex-like-55-525").start
    assert resolve_spec_path("cooke-triplet-f4.toml").is_file()
    assert resolve_spec_path("nodir/cooke-triplet-f4.toml") == Path("nodir/cooke-triplet-f4.toml")
    # a local file of that name is read first
    (tmp_path / "twinplex-like-55-525.toml").write_text("start = 1\n")
    with pytest.raises(SpecError, match="'start'"):
        read_spec("twinplex-like-55-525.toml")


def test_cli_a_lens_given_as_spec_says_so_in_one_line(tmp_path, monkeypatch, capsys):
    # a bundled spec's start lens (lenses/specs/*-start.toml) by its name printed a 9-line
    # "unknown key 'source'" error
    from orthoscope.cli import main

    monkeypatch.chdir(tmp_path)
    for name in ("twinplex-like-55-525-start", "twinplex-like-55-525-start.toml"):
        assert main(["optimize", name, "-o", "out.toml"]) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert line == (
            f"orthoscope optimize: error: {name} is a lens (a spec's start lens), not a design "
            "spec: give a spec, e.g. `orthoscope optimize twinplex-like-55-525`"
        )
    # any lens file: no spec starts from it, so the bundled spec names
    lens = Path(__file__).parents[1] / "lenses" / "cooke-triplet-f4.toml"
    assert main(["optimize", str(lens), "-o", "out.toml"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"orthoscope optimize: error: {lens} is a lens, not a design spec")
    assert "twinplex-like-55-525, " in line or line.endswith("twinplex-like-55-525")
    # the docs' folder path of a start lens, typed outside the repository
    spec = "lenses/specs/twinplex-like-55-525-start.toml"
    assert main(["optimize", spec, "-o", "out.toml"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"orthoscope optimize: error: {spec}: no such spec file; ")
    assert line.endswith("give a spec, e.g. `orthoscope optimize twinplex-like-55-525`")
    assert not (tmp_path / "out.toml").exists()


GLOBAL_AT_ONCE = ["--global", "--starts", "1", "--workers", "1", "--time", "0.001"]


@pytest.mark.parametrize(
    "edit,search",
    [(["--split", "1"], []), (["--insert", "4:N-BK7"], []), (["--split", "1"], GLOBAL_AT_ONCE)],
    ids=["split", "insert", "split-global"],
)
def test_cli_an_edited_start_lens_whose_chief_ray_fails_says_the_word_and_the_fix(
    tmp_path, capsys, edit, search
):
    # `optimize twinplex-like-55-525 --split 1` (or --insert 4:N-BK7) ended "error:
    # distortion(field=45.0): the chief ray fails (status 4)": the code, not its word, and no
    # fix. The edit makes the start lens: a split element's halves are half as thick and an
    # inserted plate's flat face cuts the concave surface 4, so the 45 deg chief ray meets
    # overlapping surfaces (another element, e.g. --split 6, passes it). A global search that
    # gave no design (its time ran out at once here) keeps that start lens and says so
    from orthoscope.cli import main

    out = tmp_path / "out.toml"
    assert main(["optimize", "twinplex-like-55-525", *edit, *search, "-o", str(out)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(
        f"orthoscope optimize: error: {' '.join(edit)}: on the start lens this makes, "
        "distortion(field=45.0): the chief ray fails (aim_failed: "
    )
    assert "status 4" not in line
    fix = "; split another element or insert elsewhere"
    if search:
        assert f", and no start of the search gave a design{fix}, or lower" in line
    else:
        assert f"{fix} (--split auto tries every element), or lower" in line
    assert not out.exists()
