"""``orthoscope distortion LENS --definition NAME``: distortion against a named definition
(F-tanθ, F-θ, calibrated, fisheye projections; :mod:`distortion.definitions`).

Not a command of its own: :mod:`orthoscope.cli.distortion` adds these options with
:func:`add_definition_args` and hands over to :func:`run_definition` when ``--definition`` is
given."""

from __future__ import annotations

import argparse

from .common import CliError, print_result, refuse_flags, strict_check

DEFINITION_HELP = (
    "Measure the distortion against a named definition instead of Pestrecov's (object at "
    "infinity; theta = field angle): 'f-tan-theta' (y_ref = f tan theta) and 'f-theta' "
    "(f theta) with the paraxial f of the plane (= EFL in the Gaussian plane; OpticStudio's and "
    "optiland's scale), 'calibrated-f-tan-theta' / 'calibrated-f-theta' with a least-squares f "
    "over the fields (our criterion: OpticStudio does not document its own), fisheye "
    "'equidistant', 'equisolid-angle' (2f sin(theta/2)), 'stereographic' (2f tan(theta/2)), "
    "'orthographic' (f sin theta) with a least-squares f (or --focal paraxial)."
)
FOCAL_HELP = (
    "Focal length of a fisheye --definition: 'least-squares' (default; sum(g y')/sum(g^2) over "
    "the fields) or 'paraxial' (F0 of the plane)."
)


def add_definition_args(q: argparse.ArgumentParser) -> None:
    """``--definition NAME`` and ``--focal`` on the distortion command."""
    from distortion.definitions import DEFINITIONS, FOCALS

    g = q.add_argument_group("named definitions (F-tan(theta), F-theta, fisheye)")
    g.add_argument("--definition", metavar="NAME", choices=list(DEFINITIONS), help=DEFINITION_HELP)
    g.add_argument("--focal", choices=list(FOCALS), help=FOCAL_HELP)


def run_definition(lens, fields, kind, od, planes, args) -> int:
    """The distortion command with ``--definition``: text (default), ``--json`` or ``--csv``."""
    from distortion.definitions import projection_distortion

    from ..report.definitions import format_projection, projection_csv, projection_to_dict

    refuse_flags(
        "--definition does not combine with {}",
        (
            ("--reference", args.reference != "characteristic"),
            ("--calibrate", args.calibrate is not None),
            ("--at", args.at is not None),
            ("--value", args.value is not None),
            ("--plot", args.plot is not None),
            ("--plot-rotation", args.plot_rotation is not None),
            ("--layout", args.layout is not None),
        ),
    )
    if kind == "height":
        raise CliError("--definition takes field angles (object at infinity), not object heights")
    res = projection_distortion(
        lens,
        fields,
        definition=args.definition,
        focal=args.focal,
        plane=planes,
        object_distance=od,
        wavelength=args.wavelength,
        wavelengths=getattr(args, "wavelengths", None),
        scale=getattr(args, "scale", "reference"),
    )
    print_result(
        args,
        json=lambda: {"projection_distortion": projection_to_dict(res)},
        csv=lambda: projection_csv(res),
        text=lambda: format_projection(res, layout=args.table_layout),
    )
    strict_check(args, res.status)
    return 0
