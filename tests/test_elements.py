"""Splitting and adding elements (raytrace.elements; raytrace.optimize.elements; ``orthoscope
optimize --split / --insert``).

References, none of them our own output: the thin-lens limit (a thin element cut in two thin
halves of the mean curvature has the same power: (n - 1)(c1 - c_m) + (n - 1)(c_m - c2) =
(n - 1)(c1 - c2)); the focal shift of a plane-parallel plate in a converging beam, t (1 - 1/n)
(paraxial; e.g. Smith, Modern Optical Engineering, §2.6); and the designer's rule that splitting
a lens into two reduces its least spherical aberration several times (two thin lenses of half
the power each contribute (1/2)³ of the single lens's at best form, and the second works at a
better conjugate: Kingslake & Johnson, Lens Design Fundamentals, 2nd ed., §6.4 "lens
splitting").
"""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from support import cooke_split_spec, run_cli, singlet, singlet_spec

from raytrace.elements import insert_element, split_element, surface_map
from raytrace.errors import LensError
from raytrace.files.library import load_lens
from raytrace.materials import fixed_index
from raytrace.optimize import (
    Operand,
    SpecError,
    Variable,
    check_spec,
    evaluate,
    optimize,
    split_design,
)
from raytrace.optimize.elements import insert_design
from raytrace.paraxial import element_power, paraxial


def test_a_thin_element_split_keeps_its_power():
    lens = singlet(n=1.5, f=100.0, t=1e-4)
    c1, c2 = lens.surfaces[0].curvature, lens.surfaces[1].curvature
    split = split_element(lens, 1, gap=1e-4)
    assert split.n_surfaces == 4
    s = split.surfaces
    assert [x.material.is_air for x in s] == [False, True, False, True]
    assert s[1].curvature == s[2].curvature == pytest.approx(0.5 * (c1 + c2), rel=1e-15)
    assert s[0].thickness == s[2].thickness == pytest.approx(0.5e-4)
    assert s[0].stop and not any(x.stop for x in s[1:])
    # each half has half the power, the whole the same (thin-lens limit)
    half = 0.5 * (1.5 - 1) * (c1 - c2)
    assert element_power(split, 1, 2) == pytest.approx(half, rel=1e-4)
    assert element_power(split, 3, 4) == pytest.approx(half, rel=1e-4)
    assert paraxial(split).efl == pytest.approx(paraxial(lens).efl, rel=1e-5)


def test_an_inserted_plate_shifts_the_focus_by_t_times_one_minus_one_over_n():
    lens = load_lens("cooke-triplet-f4")
    n, t = 1.6, 3.0
    last = lens.n_surfaces
    ins = insert_element(lens, last, fixed_index(n), thickness=t, gap=5.0)
    assert ins.n_surfaces == lens.n_surfaces + 2
    assert element_power(ins, last + 1, last + 2) == 0.0  # two flat surfaces
    # every old vertex stays where it was
    assert list(ins.vertex_z[:last]) == pytest.approx(list(lens.vertex_z))
    # the Gaussian image moves back by t (1 - 1/n), and the file's Gaussian image solve with it
    z0, z1 = paraxial(lens).z_gauss, paraxial(ins).z_gauss
    assert z1 - z0 == pytest.approx(t * (1 - 1 / n), rel=1e-9)
    assert lens.image_solve == ins.image_solve == "gaussian"
    assert ins.image_z - lens.image_z == pytest.approx(t * (1 - 1 / n), rel=1e-9)


def test_splitting_a_singlet_lowers_its_least_spherical_aberration():
    lens = singlet(n=1.5)
    spec = singlet_spec()
    one = optimize(lens, spec)
    lens2, spec2 = split_design(lens, spec, 1)
    assert [(v.kind, v.surface) for v in spec2.variables] == [
        ("curvature", 1),
        ("curvature", 4),
        ("curvature", 2),
        ("curvature", 3),
    ]
    two = optimize(lens2, replace(spec2, max_evaluations=800))
    rms1 = [o.value for o in one.operands if o.operand.type == "rms_spot"][0]
    rms2 = [o.value for o in two.operands if o.operand.type == "rms_spot"][0]
    assert paraxial(two.lens).efl == pytest.approx(100.0, rel=1e-5)
    assert rms2 < 0.4 * rms1, (rms1, rms2)


def test_split_design_renumbers_the_spec_and_repeats_the_element_rules():
    lens = load_lens("cooke-triplet-f4")  # elements at 1-2, 3-4, 5-6
    spec = singlet_spec()
    spec = replace(
        spec,
        start="cooke-triplet-f4",
        variables=(
            Variable("curvature", 3, -0.2, 0.0),
            Variable("curvature", 4, 0.0, 0.2),
            Variable("thickness", 3, 0.8, 5.0),
            Variable("thickness", 4, 0.3, 20.0),
            Variable("curvature", 5),
        ),
        operands=(
            Operand("efl", 50.0, 1.0),
            Operand("edge_thickness", params={"surface": 3, "height": 5.0, "min": 0.5}),
            Operand("edge_thickness", params={"surface": 4, "height": 5.0, "min": 0.2}),
            Operand("ray_height", params={"surface": 6, "field": 10.0, "max": 20.0}),
            Operand("element_power", params={"surface": 1, "last": 6, "min": 0.0}),
        ),
    )
    new_lens, new = split_design(lens, spec, 3)
    check_spec(new_lens, new)
    where = surface_map(3)
    assert [where(j) for j in (1, 2, 3, 4, 5, 6)] == [1, 2, 3, 6, 7, 8]
    got = {(v.kind, v.surface): (v.lower, v.upper) for v in new.variables}
    assert got == {
        ("curvature", 3): (-0.2, 0.0),
        ("curvature", 6): (0.0, 0.2),
        ("thickness", 3): (0.8, 5.0),  # the first half
        ("thickness", 6): (0.3, 20.0),
        ("curvature", 7): (-float("inf"), float("inf")),
        ("curvature", 4): (-0.2, 0.2),  # the cut surfaces: the union of the element's bounds
        ("curvature", 5): (-0.2, 0.2),
        ("thickness", 5): (0.8, 5.0),  # the second half
        ("thickness", 4): (0.3, float("inf")),  # the gap: the spec's smallest air bound
    }
    assert new_lens.surfaces[3].thickness == 0.3  # the gap, raised from 0.1 to that bound
    ops = [(o.type, o.params) for o in new.operands]
    assert ("ray_height", {"surface": 8, "field": 10.0, "max": 20.0}) in ops
    assert ("element_power", {"surface": 1, "last": 8, "min": 0.0}) in ops
    assert ("edge_thickness", {"surface": 6, "height": 5.0, "min": 0.2}) in ops  # air after
    assert ("edge_thickness", {"surface": 5, "height": 5.0, "min": 0.5}) in ops  # second half
    assert ("edge_thickness", {"surface": 4, "height": 5.0, "min": 0.2}) in ops  # the gap
    # the operands evaluate on the split lens
    assert all(v.value == v.value for v in evaluate(new_lens, new.operands))


def test_insert_design_moves_the_air_space_variable_behind_the_new_element():
    lens = load_lens("cooke-triplet-f4")
    spec = replace(
        singlet_spec(),
        start="cooke-triplet-f4",
        variables=(Variable("thickness", 2, 0.5, 30.0), Variable("curvature", 1)),
        operands=(Operand("efl", 50.0, 1.0),),
    )
    new_lens, new = insert_design(lens, spec, 2, fixed_index(1.7), thickness=1.5, gap=0.5)
    check_spec(new_lens, new)
    got = {(v.kind, v.surface): (v.lower, v.upper) for v in new.variables}
    assert got == {
        ("curvature", 1): (-float("inf"), float("inf")),
        ("curvature", 3): (-float("inf"), float("inf")),
        ("curvature", 4): (-float("inf"), float("inf")),
        ("thickness", 3): (0.5, float("inf")),  # the new glass (no glass bound: MIN_GLASS)
        ("thickness", 4): (0.5, 30.0),  # the old air space, now behind the new element
        ("thickness", 2): (0.5, float("inf")),  # the gap in front of it
    }
    assert new_lens.surfaces[1].thickness == 0.5


def test_edits_refuse_what_is_not_an_element_or_an_air_space():
    lens = load_lens("cooke-triplet-f4")
    with pytest.raises(LensError, match=r"surfaces 2-3 are not a single element in air"):
        split_element(lens, 2)
    with pytest.raises(LensError, match=r"no element starts at surface 6"):
        split_element(lens, 6)
    with pytest.raises(LensError, match=r"the space after surface 1 is not air"):
        insert_element(lens, 1, fixed_index(1.5))
    with pytest.raises(LensError, match=r"too short for an element 5 mm thick 1 mm behind"):
        insert_element(lens, 2, fixed_index(1.5), thickness=5.0, gap=1.0)
    with pytest.raises(LensError, match=r"gap must be positive .* space after surface 2 is 6 mm"):
        insert_element(lens, 2, fixed_index(1.5), thickness=10.0)  # in the middle: no room
    with pytest.raises(LensError, match=r"a cemented group cannot be split"):
        split_element(load_lens("tessar-fr1066698"), 7)  # the rear of the cemented doublet
    with pytest.raises(LensError, match=r"must be a surface number \(an integer\), got True"):
        split_element(lens, True)
    # a mirror in air: the space after it is air the light returns into, but not a place for a
    # plate (the thicknesses after it are negative)
    s1, s2 = lens.surfaces[:2]
    mirror = replace(s2, curvature=0.0, thickness=-40.0, mirror=True)
    folded = replace(lens, surfaces=(replace(s1, stop=True), replace(s2, thickness=20.0), mirror))
    with pytest.raises(LensError, match=r"surface 3 is a mirror; insert the element after a refr"):
        insert_element(folded, 3, fixed_index(1.5))


def test_cli_split_writes_a_lens_that_records_the_edit(tmp_path):
    spec = tmp_path / "singlet.toml"
    lens = tmp_path / "start.toml"
    from raytrace.files import save_lens

    save_lens(singlet(n=1.5), lens)
    spec.write_text(
        'start = "start.toml"\nmax_evaluations = 600\n'
        'variables = [ { kind = "curvature", surface = 1 }, { kind = "curvature", surface = 2 } ]\n'
        'operands = [ { type = "efl", target = 100, weight = 100 },\n'
        '  { type = "rms_spot", plane = "best", target = 0, weight = 1000 } ]\n',
        encoding="utf-8",
    )
    cmd = ["optimize", str(spec), "--quiet", "-o"]
    out = tmp_path / "two.toml"
    rc, _, err = run_cli([*cmd, str(out), "--split", "1"])
    assert rc == 0, err
    two = load_lens(str(out))
    assert two.n_surfaces == 4
    assert "edited by --split 1" in two.notes
    for flag, msg in (
        ("--split=2", "no element starts at surface 2"),
        ("--insert=1", "AFTER:GLASS"),
    ):
        rc, _, err = run_cli([*cmd, str(tmp_path / "x.toml"), flag])
        lines = [x for x in err.splitlines() if "compiling" not in x]
        assert rc == 2 and len(lines) == 1 and msg in lines[0], err
    assert not (tmp_path / "x.toml").exists()


def test_split_design_carries_pickups_element_power_and_only_minimum_rules():
    from raytrace.optimize import Pickup, SpecError

    lens = load_lens("cooke-triplet-f4")
    spec = replace(
        singlet_spec(),
        start="cooke-triplet-f4",
        variables=(Variable("thickness", 1, 1.0, 5.0), Variable("index", 1, 1.5, 1.9)),
        pickups=(Pickup("thickness", 5, 1), Pickup("index", 5, 1)),  # the symmetric triplet
        operands=(
            Operand("element_power", 0.0, 1.0, {"surface": 5, "min": 0.0}),
            Operand("center_thickness", 2.0, 1.0, {"surface": 5}),  # a target: first half only
            Operand("center_thickness", params={"surface": 5, "min": 0.8}),  # a rule: both
        ),
    )
    new_lens, new = split_design(lens, spec, 5)
    check_spec(new_lens, new)
    assert set(new.pickups) == {
        Pickup("thickness", 5, 1, 0.5, 0.0),  # the element's thickness, shared by its halves
        Pickup("thickness", 7, 1, 0.5, 0.0),
        Pickup("index", 5, 1),
        Pickup("index", 7, 1),
    }
    ops = [(o.type, o.target, o.params) for o in new.operands]
    assert ("element_power", 0.0, {"surface": 5, "last": 8, "min": 0.0}) in ops  # the element
    assert ("center_thickness", 2.0, {"surface": 5}) in ops
    assert ("center_thickness", 2.0, {"surface": 7}) not in ops
    assert ("center_thickness", 0.0, {"surface": 7, "min": 0.8}) in ops
    # the element still has its power: the split keeps it in the thin-lens limit
    (p0,) = evaluate(lens, spec.operands[:1])
    (p1,) = evaluate(new_lens, new.operands[:1])
    assert p1.value == pytest.approx(p0.value, rel=0.05)
    # an element whose thickness feeds a pick-up cannot be split blindly
    with pytest.raises(SpecError, match=r"thickness of surface 1 is the source of a pick-up"):
        split_design(lens, spec, 1)
    # the spec is checked against the start lens first: errors in the user's numbering
    bad = replace(
        spec,
        operands=(Operand("edge_thickness", params={"surface": -10, "height": 3, "min": 0.1}),),
    )
    with pytest.raises(SpecError, match=r"surface -10"):
        split_design(lens, bad, 3)


def test_a_minimax_start_that_cannot_be_traced_is_a_clean_error():
    from raytrace.errors import TraceError

    lens = load_lens("cooke-triplet-f4")
    spec = replace(
        singlet_spec(),
        start="cooke-triplet-f4",
        method="minimax",
        operands=(Operand("ray_height", 0.0, 1.0, {"surface": 6, "field": 40.0, "max": 10.0}),),
    )
    # the f/4 rim ray at 40 deg does not get through the Cooke triplet (a trace failure)
    with pytest.raises(TraceError, match=r"ray_height\(surface=6, field=40.0"):
        optimize(lens, spec)
    # a field no object can have is refused before any trace, naming the operand
    bad = replace(spec, operands=(Operand("ray_height", 0.0, 1.0, {"surface": 2, "field": 95.0}),))
    with pytest.raises(
        SpecError, match=r"operands\[0\] \(ray_height\(.*field 95 deg: field angles"
    ):
        optimize(lens, bad)


def test_scan_splits_tries_every_element_and_the_cli_keeps_the_best(tmp_path):
    from raytrace.optimize import scan_splits

    lens = load_lens("cooke-triplet-f4")
    spec = cooke_split_spec(80)
    trials = scan_splits(lens, spec)
    assert [t.surface for t in trials] == [1, 3, 5]
    assert all(t.result is not None and math.isfinite(t.merit) for t in trials)
    # each trial is the run split_design + optimize gives (deterministic)
    l3, s3 = split_design(lens, spec, 3)
    assert trials[1].merit == optimize(l3, s3).merit
    best = min(trials, key=lambda t: t.merit)
    # the CLI: --split auto writes the best split and names every merit in the notes
    from raytrace.files import save_lens

    save_lens(lens, tmp_path / "start.toml")
    text = 'start = "start.toml"\nmax_evaluations = 80\nvariables = ['
    text += ", ".join(f'{{ kind = "curvature", surface = {k} }}' for k in range(1, 7)) + " ]\n"
    text += 'operands = [ { type = "efl", target = 50, weight = 100 },\n'
    text += '  { type = "rms_spot", field = 0, plane = "best", target = 0, weight = 1000 } ]\n'
    (tmp_path / "s.toml").write_text(text, encoding="utf-8")
    out = tmp_path / "best.toml"
    cmd = ["optimize", str(tmp_path / "s.toml"), "-o", str(out)]
    rc, _, err = run_cli([*cmd, "--split", "auto", "--write-anyway"])
    assert rc in (0, 1), err
    for t in trials:
        assert f"--split {t.surface}: merit {t.merit:.6g}" in err
    written = load_lens(str(out))
    assert written.n_surfaces == 8
    assert f"edited by --split {best.surface} (best of --split auto" in written.notes
    rc, _, err = run_cli([*cmd, "--split", "auto", "--global"])
    assert rc == 2 and "--split auto tries each element alone" in err
