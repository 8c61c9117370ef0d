"""CLI: ``orthoscope tolerance LENS SPEC`` — how much distortion scatters over a production batch
and which tolerance drives it: the sensitivity table (``--sensitivity``) or a seeded Monte Carlo
run (:mod:`distortion.tolerance`; spec format: docs/tolerance.md)."""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path

from . import EXIT_INTERRUPTED
from .common import (
    CliError,
    add_force_arg,
    add_output_args,
    check_dask,
    check_size,
    parse_list,
    print_json,
)

#: raytrace.tolerance.COMPENSATORS, spelled here so that building the parser imports no kernels
#: (tests/test_tolerance_cli.py checks they are equal)
COMPENSATORS = ("paraxial-refocus", "best-focus", "fixed-sensor")
#: instances held in memory without --allow-large (outputs ~ 8 bytes x (3 fields + 30) each);
#: the API's allow_large limit, the same number (raytrace.limits)
from raytrace.limits import MAX_INSTANCES  # noqa: E402

#: the API's keywords in its messages, as this command says them (orthoscope.cli.CLI_FLAGS
#: translates only ``key=NUMBER`` and a bare ``key=``)
_API_WORDS = (
    ("overwrite=True", "--force"),
    ("allow_large=True", "--allow-large (before the command)"),
    ("a new out_dir", "a new -o folder"),
    ("a new or empty out_dir", "a new or empty -o folder"),
    ("another out_dir", "another -o folder"),
)
_LIMIT = re.compile(r"^\s*([0-9.eE+-]+)\s*(um|µm|μm)?\s*@\s*([0-9.eE+-]+)\s*(deg|°)?\s*$")


def _bundled_example(name: str) -> str:
    """Path of a bundled example spec, found without importing the lens library."""
    import importlib.util

    found = importlib.util.find_spec("orthoscope_lenses")
    base = Path(next(iter(found.submodule_search_locations))) if found else Path("lenses")
    return str(base / "tolerances" / f"{name}.toml")


#: Quick runs of this command for the per-command tests (tests/test_hardening.py); the spec is
#: the bundled example's path (a bundled name would collide with the lens name the tests copy).
SAMPLES = [
    ["tolerance", "cooke-triplet-f4", _bundled_example("cooke-triplet-f4"), "--samples", "16",
     "--fields", "0,10,20", "--plot", "{tmp}/tolerance.png"],
    ["tolerance", "cooke-triplet-f4", _bundled_example("cooke-triplet-f4"), "--sensitivity",
     "--fields", "0,10,20", "--json"],
]  # fmt: skip
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png")]


def parse_limits(values: list[str] | None) -> list[tuple[float, float]]:
    """``['20@35', '15um@30deg']`` → [(20.0, 35.0), (15.0, 30.0)] (µm, degrees)."""
    out = []
    for v in values or []:
        m = _LIMIT.match(v)
        if not m:
            raise CliError(
                f"--limit {v!r}: write the limit in micrometres and the field in degrees as "
                "UM@DEG, e.g. --limit 20@35"
            )
        try:
            lim, deg = float(m.group(1)), float(m.group(3))
        except ValueError:
            raise CliError(f"--limit {v!r}: not numbers; write e.g. --limit 20@35") from None
        if not (math.isfinite(lim) and lim > 0):
            raise CliError(f"--limit {v!r}: the limit must be a positive number of µm")
        if not (math.isfinite(deg) and deg >= 0):
            raise CliError(f"--limit {v!r}: the field must be an angle >= 0 in degrees")
        out.append((lim, deg))
    return out


class Progress:
    """Monte Carlo progress on stderr: a tqdm bar on a terminal, otherwise one plain line per
    ``every`` seconds and one at the end."""

    def __init__(self, quiet: bool, *, stream=None, every: float = 5.0) -> None:
        self.stream = stream or sys.stderr
        self.quiet = quiet
        self.every = every
        self.last = 0.0
        self.bar = None
        self.t0 = time.monotonic()
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def __call__(self, done: int, total: int) -> None:
        if self.quiet:
            return
        if self.tty:
            try:
                from tqdm import tqdm
            except ImportError:
                tqdm = None
            if tqdm is not None:
                if self.bar is None:
                    self.bar = tqdm(total=total, desc="instances", unit="inst", file=self.stream)
                self.bar.update(done - self.bar.n)
                return
        now = time.monotonic()
        if done < total and now - self.last < self.every:
            return
        self.last = now
        rate = done / max(now - self.t0, 1e-9)
        self.stream.write(
            f"tolerance: {done}/{total} instances ({100.0 * done / max(total, 1):.0f} %, "
            f"{rate:,.0f}/s)\n"
        )
        self.stream.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def _fields(args):
    import numpy as np

    if args.fields is None:
        return None
    f = parse_list(args.fields, "--fields")
    if np.any(f < 0):
        raise CliError("--fields: the curve is traced along +y; give angles >= 0 (degrees)")
    check_size(f.size, 10_000, "--fields (count)", args)
    return f


def cmd_tolerance(args) -> int:
    import numpy as np

    from raytrace.files.library import load_lens
    from raytrace.files.output import check_output
    from raytrace.tolerance import check_against_lens, read_tolerance_spec
    from raytrace.tolerance.spec import resolve_spec_path

    from ..report.tolerance import (
        format_monte_carlo,
        format_sensitivity,
        monte_carlo_to_dict,
        sensitivity_to_dict,
    )

    check_dask(args.dask)
    if args.sensitivity and args.samples is None:
        for flag, v in (("--dask", args.dask), ("-o", args.output), ("--seed", args.seed)):
            if v is not None:
                raise CliError(
                    f"{flag} belongs to the Monte Carlo run; drop --sensitivity or add --samples"
                )
    limits = parse_limits(args.limit)
    fields = _fields(args)
    spec_path = resolve_spec_path(args.spec)
    lens = load_lens(args.lens)
    spec = read_tolerance_spec(spec_path)
    if args.compensator is not None:
        spec = spec.with_compensator(args.compensator)
    check_against_lens(spec, lens)
    inputs = [str(spec_path)] + ([lens.path] if getattr(lens, "path", None) else [])
    if args.plot is not None:
        plot = Path(args.plot)
        # an input named as the output is the worse mistake: say that first
        check_output(args.plot, inputs=inputs, overwrite=args.force, flag="--force")
        if plot.suffix.lower() not in (".png", ".svg", ".pdf"):
            raise CliError(f"--plot {plot}: use a .png, .svg or .pdf file")
    for lim, deg in limits:
        top = float(np.max(fields)) if fields is not None else float(lens.field.value)
        if deg > top:
            raise CliError(
                f"--limit {lim:g}@{deg:g}: the field {deg:g} deg is beyond the curve's largest "
                f"field {top:g} deg; give a field inside it"
            )
    kw = {} if fields is None else {"fields_deg": fields}
    if args.g_object_distance is not None:
        kw["g_object_distance"] = _g_distance(args.g_object_distance)
    run_mc = not args.sensitivity or args.samples is not None
    if run_mc:
        _run_size(args, spec)
        if args.dask is not None:  # before the sensitivity table (--plot) and the run
            from raytrace.executors import require_dask

            require_dask()
    else:  # the Monte Carlo run checks its limits (and says when one looks like mm)
        from distortion.tolerance.checks import check_yield_limit

        for lim, deg in limits:
            check_yield_limit(lim, deg, "--limit")
    sens = None
    if args.sensitivity or args.plot is not None:
        from distortion.tolerance import sensitivity

        sens = sensitivity(lens, spec, **kw)
    mc = None
    if run_mc:
        mc = _monte_carlo(args, lens, spec, kw, limits)
        if mc is None:
            return EXIT_INTERRUPTED
    if args.plot is not None:
        from ..plots.common import offscreen_figures
        from ..plots.save import save_figure
        from ..plots.tolerance import plot_tolerance

        with offscreen_figures():
            fig = plot_tolerance(mc, sens, limits=limits)
        save_figure(fig, args.plot, overwrite=args.force, inputs=inputs, flag="--force")
    if args.json:
        out = {"lens": lens.name, "spec": str(spec_path)}
        if sens is not None and args.sensitivity:
            out["sensitivity"] = sensitivity_to_dict(sens)
        if mc is not None:
            out["monte_carlo"] = monte_carlo_to_dict(mc, limits)
        if args.plot is not None:
            out["plot"] = str(args.plot)
        print_json(out)
    else:
        blocks = []
        if sens is not None and args.sensitivity:
            blocks.append(format_sensitivity(sens))
        if mc is not None:
            blocks.append(format_monte_carlo(mc, limits, lens.name))
        if args.plot is not None:
            blocks.append(f"wrote {args.plot}")
        print("\n\n".join(blocks))
    return 0


def _g_distance(text: str):
    """--g-object-distance as the API takes it: a number is mm, ``inf``, a length with a unit
    (``2m``) or an image scale (``10x``) stay text (resolved against the lens by the API)."""
    t = text.strip()
    try:
        return float(t) if t.lower() not in ("inf", "infinity") else t
    except ValueError:
        return t


def _run_size(args, spec) -> tuple[int, int]:
    """(instances, chunk size) of the run, checked before any work."""
    n = args.samples
    if n is None:
        n = int(spec.monte_carlo.get("samples", 1000))
    check_size(n, MAX_INSTANCES, "--samples", args, per_item_bytes=1200)
    if args.seed is not None and args.seed < 0:
        raise CliError(f"--seed must be a whole number >= 0, got {args.seed}")
    if args.chunk is not None and args.chunk < 1:
        raise CliError(f"--chunk must be at least 1, got {args.chunk}")
    return n, args.chunk or int(spec.monte_carlo.get("chunk", 256))


def command_words(message: str) -> str:
    """An error of the Monte Carlo API (its folder of chunks) in this command's words."""
    for api, cli in _API_WORDS:
        message = message.replace(api, cli)
    return message


def _monte_carlo(args, lens, spec, kw, limits):
    from distortion.tolerance import monte_carlo
    from raytrace.errors import OutputError

    n, chunk = _run_size(args, spec)
    prog = Progress(args.quiet or args.json)
    try:
        return monte_carlo(
            lens,
            spec,
            n,
            seed=args.seed,
            chunk_size=chunk,
            out_dir=args.output,
            resume=True,
            overwrite=args.force,
            executor=args.dask,
            progress=prog,
            limits=limits,
            summary=args.summary,
            allow_large=bool(getattr(args, "allow_large", False)),
            **kw,
        )
    except OutputError as e:
        raise OutputError(command_words(str(e))) from None
    except KeyboardInterrupt:
        prog.close()
        kept = (
            f"; the finished chunks are kept in {args.output}: run the same command again to resume"
            if args.output
            else " (give -o DIR to keep finished chunks and resume)"
        )
        print(f"orthoscope tolerance: interrupted{kept}", file=sys.stderr)
        return None
    finally:
        prog.close()


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "tolerance",
        help="Tolerancing of distortion: sensitivity table or Monte Carlo over a batch.",
        description=(
            "How much will distortion scatter over a production batch, and which tolerance "
            "drives it? SPEC is a tolerance spec (TOML, docs/tolerance.md; or a .zmx file's TOL "
            "lines; or the name of a bundled example in lenses/tolerances/). --sensitivity: "
            "each tolerance alone at its limits, compensator applied, ranked by its effect on "
            "the calibrated distortion at the largest field. Otherwise a seeded Monte Carlo "
            "run of --samples perturbed lenses (instance i is the same lens whatever the "
            "chunking or workers): percentile envelopes of the distortion curve along +y, "
            "spreads of F0, Fc, principal point and P1/P2 — raw, and after removing what a "
            "calibration absorbs — Fraser & Shortis's g_ss' with --g-object-distance, and the "
            "yield against --limit. With -o DIR the chunks and a "
            "manifest are written as they finish: Ctrl-C (exit status 130) keeps them and the "
            "same command resumes. Progress: a bar on a terminal, plain lines otherwise."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope tolerance topogon-like-pestrecov topogon-like-pestrecov --sensitivity\n"
            "  orthoscope tolerance cooke-triplet-f4 cooke-triplet-f4 --samples 500 --seed 1 "
            "--limit 20@20 -o run1 --plot tol.png\n"
            "Add --dask local:2 (a LocalCluster of 2 workers) or --dask tcp://HOST:PORT to run the "
            "chunks on Dask."
        ),
    )
    q.add_argument("lens", metavar="LENS", help="Lens file or bundled lens name.")
    q.add_argument(
        "spec",
        metavar="SPEC",
        help="Tolerance spec: .toml (docs/tolerance.md), a .zmx with TOL lines, or a bundled "
        "example name (lenses/tolerances/NAME.toml).",
    )
    q.add_argument(
        "--sensitivity",
        action="store_true",
        help="The sensitivity table (each item at its limits), ranked; with --samples also the "
        "Monte Carlo run.",
    )
    q.add_argument(
        "--samples", type=int, metavar="N", help="Monte Carlo instances (default: the spec's, "
        "else 1000)."
    )  # fmt: skip
    q.add_argument(
        "--seed", type=int, metavar="S", help="Root seed >= 0 (default: the spec's, else 0)."
    )
    q.add_argument(
        "--chunk", type=int, metavar="N", help="Instances per chunk (default: the spec's, else "
        "256): one kernel launch, one file, one Dask task."
    )  # fmt: skip
    q.add_argument(
        "--dask",
        metavar="local[:N]|tcp://HOST:PORT",
        help="Run the chunks on Dask: a LocalCluster of N worker processes, or a running "
        "scheduler (pip install 'orthoscope[dask]'). Default: this process, numba threads.",
    )
    q.add_argument(
        "-o",
        "--output",
        metavar="DIR",
        help="Folder for the chunks, manifest.json and summary.json; a rerun resumes there.",
    )
    q.add_argument(
        "--fields",
        metavar="A1,A2,...",
        help="Field angles (deg, >= 0) of the distortion curve along +y (default: 50 fields "
        "from 0 to the lens's field).",
    )
    q.add_argument(
        "--g-object-distance",
        metavar="D",
        help="Also compute Fraser & Shortis's variation factor g_ss' of every lens (Eq. 6): the "
        "lens focused at its object distance s by the compensator, the object plane s' at D "
        "(mm from the object plane to the first vertex; or 2m, inf, or an image scale such as "
        "10x). Its spread, histogram and sensitivity are reported. Default: the spec's "
        "[outputs] g_object_distance, else g is not computed.",
    )
    q.add_argument(
        "--compensator",
        choices=COMPENSATORS,
        help="Override the spec's compensator (paraxial-refocus, best-focus, fixed-sensor).",
    )
    q.add_argument(
        "--limit",
        action="append",
        metavar="UM@DEG",
        help="Yield against a limit: the share of lenses with |D| < UM micrometres at DEG "
        "degrees, raw and calibrated (repeatable: --limit 20@35 --limit 10@20).",
    )
    q.add_argument(
        "--plot",
        metavar="FILE",
        help="Draw the envelope, histograms and sensitivity bars (.png, .svg, .pdf).",
    )
    q.add_argument(
        "--summary",
        choices=("auto", "exact", "streaming"),
        default="auto",
        help="How the statistics are taken: exact (every lens gathered in memory), streaming "
        "(chunk by chunk, for very large runs: percentiles from 4096-bin histograms, within one "
        "bin width), or auto (exact up to 100,000 lenses; default).",
    )
    add_output_args(q, csv=False, json_help="Print JSON (keys carry units).")
    q.add_argument("--quiet", action="store_true", help="No progress display.")
    add_force_arg(
        q,
        help="Replace an existing plot, and a chunk folder (-o) that holds a different run; use "
        "a non-empty -o folder that holds no run (its chunk files are replaced).",
    )
    q.set_defaults(func=cmd_tolerance)
