"""Damped-least-squares optimizer: a toy problem with a classical optimum, spec errors, the CLI."""

from pathlib import Path

import pytest
from support import singlet, singlet_spec

from orthoscope.cli import main
from raytrace.optimize import (
    DesignSpec,
    Operand,
    Pickup,
    SpecError,
    Variable,
    evaluate,
    optimize,
    read_spec,
)
from raytrace.paraxial import paraxial


def test_singlet_bent_for_minimum_spherical_aberration():
    # Classical third-order result (e.g. Kingslake, Lens Design Fundamentals, ch. 4; Welford,
    # Aberrations of Optical Systems §7.2): a thin singlet with its object at infinity has the least
    # spherical aberration at the Coddington shape factor K = (c1 + c2)/(c1 - c2) = 2(n²-1)/(n+2).
    n = 1.5
    lens = singlet(n)
    res = optimize(lens, singlet_spec())
    c1, c2 = res.lens.surfaces[0].curvature, res.lens.surfaces[1].curvature
    K = (c1 + c2) / (c1 - c2)
    K_classical = 2 * (n * n - 1) / (n + 2)  # 0.7143 for n = 1.5 (R1/R2 = -1/6)
    assert paraxial(res.lens).efl == pytest.approx(100.0, rel=1e-6)
    # finite thickness (0.3 mm) and f/20 higher orders shift the optimum slightly
    assert K == pytest.approx(K_classical, abs=0.005)
    assert res.merit < res.merit_start


def test_pickup_keeps_symmetry():
    lens = singlet()
    spec = DesignSpec(
        start="x",
        variables=(Variable("curvature", 1),),
        pickups=(Pickup("curvature", 2, 1, factor=-1.0),),
        operands=(Operand("efl", 80.0, 1.0),),
    )
    res = optimize(lens, spec)
    s1, s2 = res.lens.surfaces
    assert s2.curvature == -s1.curvature
    # thick-lens EFL of an equiconvex lens: 1/f = (n-1)(2c) - (n-1)² t c² / n
    n, t, c = 1.5, 0.3, s1.curvature
    assert 1.0 / (2 * (n - 1) * c - (n - 1) ** 2 * t * c * c / n) == pytest.approx(80.0, rel=1e-9)


def test_impossible_target_is_not_converged():
    # The EFL of a singlet cannot reach -1e-3 mm with bounded curvatures: the run must say so.
    lens = singlet()
    spec = DesignSpec(
        start="x",
        variables=(Variable("curvature", 1, -0.05, 0.05),),
        operands=(Operand("efl", 1e-3, 1.0),),
        merit_goal=1e-6,
    )
    res = optimize(lens, spec)
    assert not res.converged
    assert "above the goal" in res.message
    # why the solver stopped, in the project's words: scipy's sentence ("`ftol` termination
    # condition is satisfied.") stood in brackets here and in every converged run's message
    assert "termination condition" not in res.message
    assert "(the solver stopped: the gradient fell below the tolerance" in res.message


def test_a_converged_run_says_why_in_our_words():
    res = optimize(singlet(), singlet_spec())
    assert res.converged
    assert res.message.startswith("converged: "), res.message
    assert "termination condition" not in res.message


@pytest.mark.parametrize(
    "spec, message",
    [
        (dict(variables=(Variable("radius", 1),)), "unknown variable kind"),
        (dict(variables=(Variable("curvature", 7),)), "the lens has 2 surfaces"),
        (dict(variables=(Variable("thickness", 1, 5.0, 1.0),)), "bounds inverted"),
        (
            dict(operands=(Operand("center_thickness", params={"surface": 9, "min": 1}),)),
            "does not exist",
        ),
        (dict(operands=(Operand("wavefront", 0.0),)), "unknown operand type"),
        (dict(operands=(Operand("distortion", 0.0),)), "needs a 'field'"),
        (dict(variables=(Variable("index", 2),)), "medium after it is air"),
    ],
)
def test_bad_specs(spec, message):
    base = dict(start="x", variables=(Variable("curvature", 1),), operands=(Operand("efl", 90.0),))
    base.update(spec)
    with pytest.raises(SpecError, match=message):
        optimize(singlet(), DesignSpec(**base))


def test_distortion_operand_matches_definition():
    # D0 = y' - F0 tan(alpha) in the Gaussian plane (Pestrecov Eq. 9): cross-check against the
    # distortion module, which is written independently of the optimizer.
    from distortion.characteristic import characteristic_distortion
    from raytrace.files.library import load_lens

    lens = load_lens("cooke-triplet-f4")
    vals = evaluate(lens, (Operand("distortion", 0.0, 1.0, {"field": 20.0}),))
    res = characteristic_distortion(lens, [0.0, 20.0])
    assert vals[0].value == pytest.approx(float(res.D0[0, 1]), abs=1e-12)


SPEC = """
name = "cooke-efl-48"
start = "cooke-triplet-f4"
max_evaluations = 200
merit_goal = 1e-12
variables = [ {{ kind = "curvature", surface = 6 }} ]
operands = [ {{ type = "efl", target = {target}, weight = 1 }} ]
"""


def test_cli_optimize_writes_lens_with_provenance(tmp_path: Path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(target=48.0))
    out = tmp_path / "out.toml"
    assert main(["optimize", str(spec), "-o", str(out), "--quiet"]) == 0
    from raytrace.files.native import provenance, read_lens

    lens = read_lens(out)
    assert paraxial(lens).efl == pytest.approx(48.0, abs=1e-9)
    assert provenance(lens) == "derived"
    assert "cooke-triplet-f4" in lens.notes and "merit" in lens.notes
    assert "wrote" in capsys.readouterr().out


def test_cli_optimize_refuses_to_write_unconverged(tmp_path: Path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text(
        SPEC.format(target=-5.0).replace("surface = 6 }", "surface = 6, min = -0.06, max = 0.0 }")
    )
    out = tmp_path / "out.toml"
    assert main(["optimize", str(spec), "-o", str(out), "--quiet"]) == 1
    assert not out.exists()
    assert "NOT CONVERGED" in capsys.readouterr().out


def test_cli_optimize_bad_spec_exit_2(tmp_path: Path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text(
        'start = "cooke-triplet-f4"\nvariables = [ { kind = "curvatur", surface = 1 } ]\n'
        'operands = [ { type = "efl", target = 50 } ]\n'
    )
    assert main(["optimize", str(spec), "-o", str(tmp_path / "o.toml")]) == 2
    err = capsys.readouterr().err
    assert "unknown variable kind 'curvatur'" in err and "Traceback" not in err
    spec.write_text("start = [\n")
    assert main(["optimize", str(spec), "-o", str(tmp_path / "o.toml")]) == 2


def test_read_spec_unknown_key(tmp_path: Path):
    spec = tmp_path / "s.toml"
    spec.write_text('start = "x"\nvariabels = []\n')
    with pytest.raises(SpecError, match="unknown key 'variabels'"):
        read_spec(spec)


def test_gaussian_image_solve_is_kept(tmp_path: Path):
    # A start lens whose last thickness is a Gaussian solve keeps it through the optimization:
    # the written file must not carry the start lens's stale image distance.
    from raytrace.files.library import load_lens
    from raytrace.files.native import read_lens

    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(target=48.0))
    out = tmp_path / "out.toml"
    assert load_lens("cooke-triplet-f4").image_solve == "gaussian"
    assert main(["optimize", str(spec), "-o", str(out), "--quiet"]) == 0
    lens = read_lens(out)
    assert lens.image_solve == "gaussian"
    assert lens.surfaces[-1].thickness == pytest.approx(paraxial(lens).bfl, abs=1e-9)
    assert 't = "gaussian"' in out.read_text().replace("  ", " ")


@pytest.mark.parametrize("method", ["least_squares", "minimax"])
def test_cli_evaluation_limit_is_said_in_our_words(tmp_path: Path, capsys, method):
    # --max-evaluations reached with the merit above the spec's goal: damped least squares
    # printed scipy's own sentence ("The maximum number of function evaluations is exceeded.")
    # as the reason; both methods now name the limit and how to raise it
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.format(target=48.0))
    out = tmp_path / "out.toml"
    argv = ["optimize", str(spec), "-o", str(out), "--quiet", "--max-evaluations", "2"]
    assert main([*argv, "--method", method]) == 1
    first = capsys.readouterr().out.splitlines()[0]
    assert "maximum number of function evaluations" not in first
    assert "evaluation limit (2" in first, first
    assert "raise it: max_evaluations in the spec, or --max-evaluations" in first, first
    if method == "least_squares":
        assert "is above the goal 1e-12" in first, first
    assert not out.exists()
