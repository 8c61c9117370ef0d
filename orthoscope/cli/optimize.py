"""CLI: ``orthoscope optimize SPEC.toml -o LENS.toml`` — a reproducible design run."""

from __future__ import annotations

import argparse
import datetime as _dt
import sys
import time
from dataclasses import replace
from pathlib import Path

from .common import CliError, print_json

EXIT_NOT_CONVERGED = 1


class _Progress:
    """One status line (iteration, merit, worst operand) on stderr, redrawn in place on a
    terminal and printed every few seconds otherwise."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.tty = sys.stderr.isatty()
        self.last = 0.0
        self.best = float("inf")

    def __call__(self, n: int, merit: float, worst) -> None:
        self.best = min(self.best, merit)
        if self.quiet:
            return
        now = time.monotonic()
        if now - self.last < (0.2 if self.tty else 5.0):
            return
        self.last = now
        line = (
            f"eval {n:6d}  merit {merit:12.6g}  best {self.best:12.6g}  worst "
            f"{worst.operand.label()} = {worst.value:.6g} (target {worst.operand.target:g})"
        )
        if self.tty:
            sys.stderr.write("\r" + line[:150].ljust(150))
        else:
            sys.stderr.write(line + "\n")
        sys.stderr.flush()

    def done(self) -> None:
        if self.tty and not self.quiet:
            sys.stderr.write("\n")


def provenance_notes(lens, spec, res, start_name: str) -> str:
    """Notes of a designed lens: provenance line first (see raytrace.files.native)."""
    date = _dt.date.today().isoformat()
    return (
        "provenance: derived\n"
        f"Designed with 'orthoscope optimize {Path(spec.path).name}' from the start lens "
        f"{start_name}; merit {res.merit:.9g} (start {res.merit_start:.9g}) after "
        f"{res.evaluations} evaluations; {date}."
    )


def cmd_optimize(args) -> int:
    from raytrace.files.native import write_lens
    from raytrace.files.output import check_output
    from raytrace.optimize import optimize, read_spec, start_lens

    spec = read_spec(args.spec)
    if args.max_evaluations is not None:
        if args.max_evaluations < 1:
            raise CliError("--max-evaluations must be at least 1")
        spec = replace(spec, max_evaluations=args.max_evaluations)
    out = Path(args.output)
    if out.suffix.lower() != ".toml":
        raise CliError(f"-o {out}: the output lens file must end in .toml")
    lens = start_lens(spec)
    inputs = [spec.path] + ([lens.path] if lens.path else [])
    check_output(out, inputs=inputs, overwrite=args.force, flag="--force")  # before the run
    prog = _Progress(args.quiet or args.json)
    res = optimize(lens, spec, progress=prog)
    prog.done()
    table = [
        {
            "operand": o.operand.label(),
            "value": o.value,
            "target": o.operand.target,
            "weight": o.operand.weight,
            "residual": o.residual,
        }
        for o in res.operands
    ]
    written = res.converged or args.write_anyway
    if written:
        designed = replace(
            res.lens,
            name=spec.name or res.lens.name,
            notes=provenance_notes(lens, spec, res, spec.start),
            source=f"derived by orthoscope optimize from {spec.start} with {Path(spec.path).name}",
        )
        if not res.converged:
            designed = replace(designed, notes=designed.notes + " NOT CONVERGED: " + res.message)
        write_lens(designed, out, inputs=inputs, overwrite=args.force, flag="--force")
    if args.json:
        print_json(
            {
                "spec": spec.path,
                "start": spec.start,
                "converged": res.converged,
                "message": res.message,
                "merit_start": res.merit_start,
                "merit": res.merit,
                "evaluations": res.evaluations,
                "seconds": res.seconds,
                "written": str(out) if written else None,
                "operands": table,
            }
        )
    else:
        print(f"{spec.name}: {res.message}")
        print(
            f"merit {res.merit_start:.6g} -> {res.merit:.6g} in {res.evaluations} evaluations "
            f"({res.seconds:.1f} s)"
        )
        print(f"{'operand':40} {'value':>14} {'target':>14} {'weighted resid.':>16}")
        for r in table:
            print(
                f"{r['operand'][:40]:40} {r['value']:14.6f} {r['target']:14.6f} "
                f"{r['residual']:16.6g}"
            )
        print(
            f"wrote {out}"
            if written
            else "NOT CONVERGED: no lens written (--write-anyway "
            "writes it, marked as not converged)"
        )
    return 0 if res.converged else EXIT_NOT_CONVERGED


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "optimize",
        help="Run a design spec (damped least squares) and write the resulting lens.",
        description=(
            "Optimize a lens from a TOML design spec: start lens, variables (curvature, thickness, "
            "index, conic, A4, A6, A8, A10 of 1-based surfaces, with bounds; a start value outside "
            "its bounds starts on the nearest bound), pick-ups, and operands with targets and "
            "weights (efl, m_e, HE0, HpE0p, distortion, distortion_rel, image_height, best_focus, "
            "rms_spot, center_thickness, edge_thickness). Progress (evaluation, merit, worst "
            "operand) goes to stderr. The lens is written with its provenance (start lens, spec, "
            "merit, date) only when the run converged (exit status 0); a run that did not "
            "converge or missed the spec's merit_goal exits with status 1 and writes nothing."
        ),
        epilog="Example: orthoscope optimize lenses/specs/twinplex-like-55-525.toml "
        "-o my-twinplex.toml",
    )
    q.add_argument("spec", metavar="SPEC.toml", help="Design spec file (see README).")
    q.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="LENS.toml",
        help="Where to write the designed lens.",
    )
    q.add_argument(
        "--max-evaluations", type=int, metavar="N", help="Override the spec's evaluation limit."
    )
    q.add_argument(
        "--write-anyway",
        action="store_true",
        help="Write the lens even when the run did not converge (marked in its notes).",
    )
    q.add_argument("--quiet", action="store_true", help="No progress display.")
    q.add_argument(
        "--force", action="store_true", help="Replace an existing output file (never an input)."
    )
    q.add_argument("--json", action="store_true", help="Print the result as JSON.")
    q.set_defaults(func=cmd_optimize)
