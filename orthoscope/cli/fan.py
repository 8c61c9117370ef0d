"""``orthoscope fan`` and ``orthoscope spot``: transverse ray aberrations and spot diagrams."""

from __future__ import annotations

import argparse

from .common import (
    MAX_SAMPLES,
    CliError,
    add_field_args,
    add_force_arg,
    add_lens_arg,
    add_object_args,
    add_output_args,
    add_plane_args,
    add_strict_arg,
    add_wavelength_arg,
    check_plot_path,
    check_traced_any,
    load_input,
    number,
    print_result,
    resolve_fields,
    resolve_object,
    resolve_one_plane,
    save_plot,
    strict_check,
)

#: Quick runs of these commands for the per-command tests (tests/test_hardening.py).
SAMPLES = [
    ["fan", "cooke-triplet-f4", "--field", "10", "--n", "5"],
    ["spot", "cooke-triplet-f4", "--fields", "0,10", "--rings", "2"],
]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png")]


def _common(lens, args):
    od = resolve_object(lens, args)
    (plane,) = resolve_one_plane(lens, args, "give one image plane")
    return {"object_distance": od, "plane": plane, "wavelength": args.wavelength}


def _field_kw(value: float, kind: str) -> dict:
    return {"field_deg": value} if kind == "angle" else {"object_height_mm": value}


def _check_rays(args, pattern: str, n: int, flags: str) -> int:
    """``n`` (``--n`` or ``--rings``, named in ``flags``) if the rays of ``pattern`` it makes are
    within :data:`raytrace.limits.MAX_SAMPLES` (or the run has --allow-large); else CliError
    naming the flag (:func:`raytrace.trace.pupil.check_sampling`, said with the flags)."""
    from raytrace.errors import TraceError
    from raytrace.trace.pupil import check_sampling

    words = (
        f"{flags} {{n}}",
        f"--pattern {{pattern}} {flags} {{n}}",
        "--allow-large (before the command)",
    )
    try:
        check_sampling(pattern, n, allow_large=getattr(args, "allow_large", False), words=words)
    except TraceError as e:
        raise CliError(str(e)) from None
    return n


def _trace_each(items, trace):
    """``trace(item)`` for each item; a field that cannot be traced
    (:class:`~raytrace.trace.fans.FieldNotTracedError`) as a
    :class:`~orthoscope.report.rays.NotTraced` in its place, so the other fields are kept."""
    from raytrace.trace.fans import FieldNotTracedError

    from ..report.rays import NotTraced

    out = []
    for item in items:
        try:
            out.append(trace(item))
        except FieldNotTracedError as e:
            out.append(NotTraced(e, axis=item if isinstance(item, str) else None))
    return out


def _output(args, lens, key, items, to_dict, to_csv, to_text, what) -> None:
    """``items`` (ray fans or spot diagrams, or :class:`~orthoscope.report.rays.NotTraced` for a
    field that could not be traced) as JSON (``{"lens", key: [...]}``), CSV or text on stdout,
    and the plot of ``--plot`` of the traced ones (:func:`orthoscope.plots.rays.plot_ray_fan`
    for ``key="fans"``, :func:`~orthoscope.plots.rays.plot_spot` for ``"spots"``); with
    ``--strict``, exit 2 after them when a field was not traced."""
    from ..report.rays import NotTraced, field_status

    print_result(
        args,
        json=lambda: {"lens": lens.name, key: [to_dict(i) for i in items]},
        csv=lambda: to_csv(items),
        text=lambda: to_text(items),
    )
    if args.plot:
        traced = [i for i in items if not isinstance(i, NotTraced)]
        check_traced_any(bool(traced), see=" (see the output)")
        from ..plots.rays import plot_ray_fan, plot_spot

        plot = plot_ray_fan if key == "fans" else plot_spot
        save_plot(lambda: plot(traced, title=f"{lens.name}: {what}"), args.plot, args)
    status = field_status(items)
    if key == "fans":  # the fans of both axes are one field, about one chief ray
        status = status[:1]
    strict_check(args, status, see=" (see the output)")


def cmd_fan(args) -> int:
    from raytrace.trace import ray_fan

    from ..report.rays import fan_to_dict, fans_csv, format_fans

    lens = load_input(args)
    check_plot_path(args.plot, "--plot", args)
    kind = args.field_kind or lens.field.kind
    field = number(args.field, "--field")
    axes = ["y", "x"] if args.axis == "both" else [args.axis]
    n = _check_rays(args, "fan_y", args.n, "--n")
    common = _common(lens, args)
    fans = _trace_each(
        axes,
        lambda a: ray_fan(lens, **_field_kw(field, kind), n=n, axis=a, allow_large=True, **common),
    )
    _output(args, lens, "fans", fans, fan_to_dict, fans_csv, format_fans, "ray fans")
    return 0


def cmd_spot(args) -> int:
    from raytrace.trace import spot_diagram

    from ..report.rays import format_spots, spot_to_dict, spots_csv

    lens = load_input(args)
    check_plot_path(args.plot, "--plot", args)
    fields, kind = resolve_fields(lens, args)
    n = _check_rays(args, args.pattern, args.rings, "--rings")
    common = _common(lens, args)
    spots = _trace_each(
        [float(f) for f in fields],
        lambda f: spot_diagram(
            lens, **_field_kw(f, kind), pattern=args.pattern, n=n, allow_large=True, **common
        ),
    )
    _output(args, lens, "spots", spots, spot_to_dict, spots_csv, format_spots, "spot diagrams")
    return 0


def _add_image_args(q: argparse.ArgumentParser, plot_help: str) -> None:
    """What fan and spot share after their own flags: object, image plane, wavelength, --plot
    (``plot_help``), --strict, --force, --json / --csv."""
    add_object_args(q)
    add_plane_args(q)
    add_wavelength_arg(q)
    q.add_argument("--plot", metavar="FILE", help=plot_help)
    add_strict_arg(q)
    add_force_arg(q)
    add_output_args(q)


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "fan",
        help="Ray fan: transverse ray aberrations of one field across the pupil.",
        description="Trace a fan of real rays across the paraxial entrance pupil, centred on the "
        "real chief ray of one field, and report the transverse ray aberration (intercept "
        "minus the chief ray's, mm) in the image plane: tangential (eps_y against py) and/or "
        "sagittal (eps_x against px). A field whose chief ray fails is reported as not traced "
        "(exit 0; 2 with --strict).",
        epilog="Example: orthoscope fan cooke-triplet-f4 --field 14 --axis both --plot fan.png",
    )
    add_lens_arg(q)
    q.add_argument("--field", default="0", metavar="F", help="Field: degrees or object mm.")
    q.add_argument("--field-kind", choices=["angle", "height"], help="What --field is.")
    q.add_argument("--axis", choices=["y", "x", "both"], default="y", help="Fan direction.")
    q.add_argument(
        "--n", type=int, default=21,
        help=f"Rays across the pupil (more than {MAX_SAMPLES} need --allow-large).",
    )  # fmt: skip
    _add_image_args(q, "Save the ray-fan plot (.png/.svg/.pdf).")
    q.set_defaults(func=cmd_fan)

    q = sub.add_parser(
        "spot",
        help="Spot diagrams with RMS and geometric radius per field.",
        description="Trace rays over the pupil (aimed about the real chief ray) for each field "
        "and report the spot in the image plane relative to the chief ray: centroid, RMS radius "
        "and geometric radius about the centroid (mm in JSON, µm in the table). A field whose "
        "chief ray fails, or whose rays all fail, is reported as not traced (exit 0; 2 with "
        "--strict).",
        epilog="Example: orthoscope spot cooke-triplet-f4 --fields 0,10,20 --plot spots.png",
    )
    add_lens_arg(q)
    add_field_args(q)
    q.add_argument(
        "--pattern", choices=["hexapolar", "rings", "square"], default="hexapolar",
        help="Pupil sampling.",
    )  # fmt: skip
    q.add_argument(
        "--rings", type=int, default=8,
        help="Rings (or points across: at least 3 for square) of the pattern; more than "
        f"{MAX_SAMPLES} rays need --allow-large.",
    )  # fmt: skip
    _add_image_args(q, "Save the spot diagrams (.png/.svg/.pdf).")
    q.set_defaults(func=cmd_spot)
