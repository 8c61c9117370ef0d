"""CLI: ``orthoscope optimize SPEC.toml -o LENS.toml [--method M] [--global ...]`` — a
reproducible design run: damped least squares (or, with ``--method minimax`` / the spec's
``method = "minimax"``, minimax) from the spec's start lens, or (``--global``) the global search
around that method with glass substitution (:func:`raytrace.optimize.global_optimize`)."""

from __future__ import annotations

import argparse
import datetime as _dt
import math
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

from . import EXIT_INTERRUPTED
from .common import (
    CliError,
    add_force_arg,
    add_output_args,
    check_dask,
    print_json,
    refuse_flags,
)

EXIT_NOT_CONVERGED = 1


class _Progress:
    """One status line (iteration, merit, worst operand) on stderr, redrawn in place on a
    terminal and printed every few seconds otherwise; ``label`` names the merit."""

    def __init__(self, quiet: bool, label: str = "merit") -> None:
        self.quiet = quiet
        self.label = label
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
            f"eval {n:6d}  {self.label} {merit:12.6g}  best {self.best:12.6g}  worst "
            f"{worst.operand.label()} = {worst.value:.6g} ({_aim(worst.operand).strip()})"
        )
        if self.tty:
            sys.stderr.write("\r" + line[:150].ljust(150))
        else:
            sys.stderr.write(line + "\n")
        sys.stderr.flush()

    def done(self) -> None:
        if self.tty and not self.quiet:
            sys.stderr.write("\n")


class GlobalProgress:
    """Progress of the global search on stderr: a tqdm bar over the starts on a terminal when
    tqdm is installed, plain lines otherwise (one per ended start: "done", or "cut short" by a
    stop, and the best merit every ``every`` seconds while a start runs)."""

    def __init__(self, starts: int, quiet: bool, *, stream=None, every: float = 10.0) -> None:
        self.stream = stream or sys.stderr
        self.quiet = quiet
        self.every = every
        self.last = time.monotonic()
        self.bar = None
        if quiet:
            return
        if getattr(self.stream, "isatty", lambda: False)():
            try:
                from tqdm import tqdm
            except ImportError:
                tqdm = None
            if tqdm is not None:
                self.bar = tqdm(total=starts, desc="starts", unit="start", file=self.stream)

    def __call__(self, ev) -> None:
        if self.quiet:
            return
        if self.bar is not None:
            if ev.event == "start":
                self.bar.update(1)
            self.bar.set_postfix_str(f"best merit {ev.best:.6g}", refresh=True)
            return
        now = time.monotonic()
        if ev.event == "start" and ev.stopped:  # its merit: its best design by then
            line = (
                f"start {ev.start} cut short ({_stop_words(ev.stopped)}; "
                f"{ev.starts_done}/{ev.starts} ended): merit {ev.merit:.6g}, best {ev.best:.6g}, "
                f"{ev.elapsed_s:.1f} s"
            )
        elif ev.event == "start":
            line = (
                f"start {ev.start} done ({ev.starts_done}/{ev.starts}): merit {ev.merit:.6g}, "
                f"best {ev.best:.6g}, {ev.elapsed_s:.1f} s"
            )
        elif ev.event == "polish":
            line = f"polished: merit {ev.merit:.6g}, {ev.elapsed_s:.1f} s"
        elif now - self.last >= self.every:
            hop = "" if ev.hop < 0 else f" hop {ev.hop}"
            line = (
                f"start {ev.start}{hop}: merit {ev.merit:.6g}, best {ev.best:.6g}, "
                f"{ev.elapsed_s:.1f} s"
            )
        else:
            return
        self.last = now
        self.stream.write(line + "\n")
        self.stream.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["optimize", "{data}/specs/cooke-efl.toml", "-o", "{tmp}/designed.toml"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("-o", ".toml")]


#: how the CLI names the merit of each method (OptimizationResult.merit)
MERIT_NAMES = {"least_squares": "merit", "minimax": "max weighted residual"}


def _stop_words(stopped: str) -> str:
    """Why a run or a start was cut short (``stopped``), in words
    (:func:`raytrace.optimize.global_search.stop_words`)."""
    from raytrace.optimize.global_search import stop_words

    return stop_words(stopped)


def provenance_notes(lens, spec, res, start_name: str) -> str:
    """Notes of a designed lens: provenance line first (see raytrace.files.native); a run cut
    short (``res.stopped``, Ctrl-C) says so, as the global search's notes do."""
    date = _dt.date.today().isoformat()
    how = " --method minimax" if res.method == "minimax" else ""
    text = (
        "provenance: derived\n"
        f"Designed with 'orthoscope optimize {Path(spec.path).name}{how}' from the start lens "
        f"{start_name}; {MERIT_NAMES[res.method]} {res.merit:.9g} (start "
        f"{res.merit_start:.9g}) after {res.evaluations} evaluations; {date}."
    )
    if res.stopped:
        text += (
            f" Run stopped early ({res.stopped}) before converging: the best design evaluated "
            "by then."
        )
    return text


def global_provenance_notes(spec, res, start_name: str, dask: str | None = None) -> str:
    """Notes of a lens designed by the global search: provenance line first, then how to
    reproduce it (seed, starts) and what it found (``dask``: the --dask cluster it ran on). A
    search cut short by a stop says how many starts finished of how many (those cut short
    counted apart) and that it was stopped; a stopped design that misses the spec's goal says
    so in words, not as NOT CONVERGED (it was stopped, not failed)."""
    from raytrace.optimize.global_search import goal_missed, starts_count

    date = _dt.date.today().isoformat()
    glasses = "; ".join(f"S{g.surface} {g.name} ({g.catalog})" for g in res.glasses)
    count = starts_count(res.starts_finished, res.starts_stopped, res.starts, bool(res.stopped))
    origin = (
        f"start {res.best_start}" + (", cut short" if res.best_start_cut_short else "")
        if res.best_start >= 0
        else "the start lens, kept"
    )
    found = (
        f"the best design found ({origin}; {count})"
        if res.stopped
        else f"best of {count} ({origin})"
    )
    text = (
        "provenance: derived\n"
        f"Designed with 'orthoscope optimize {Path(spec.path).name} --global --seed {res.seed} "
        f"--starts {res.starts}{' --method minimax' if res.method == 'minimax' else ''}' "
        f"({spec.search.hops} hops per start, local method "
        f"{res.method}) from the start lens {start_name}; {res.merit_is} "
        f"{res.merit:.9g} (start {res.merit_start:.9g}), {found}, {res.evaluations} "
        f"evaluations, {res.seconds:.0f} s with {res.workers} worker(s)"
        + (f" on Dask ({dask})" if dask else "")
        + f"; {date}."
    )
    if glasses:
        text += f" Glasses: {glasses}."
    if res.stopped:
        text += f" Search stopped early ({res.stopped}): the best design found by then."
        if not res.converged:
            missed = goal_missed(res.method, res.merit, res.violation, spec.merit_goal)
            text += f" It does not meet the spec's goal: {missed}."
    return text


def _aim(op) -> str:
    """What an operand aims at: its target, or its bounds (a one-sided operand)."""
    if not op.bounded:
        return f"{op.target:.6f}"
    lo, hi = op.limits
    return " ".join(
        s
        for s in (f">= {lo:.6g}" if lo > -math.inf else "", f"<= {hi:.6g}" if hi < math.inf else "")
        if s
    )


def _operand_table(operands) -> list[dict]:
    """One row per operand; a bound operand has ``min`` / ``max`` and no target (None)."""
    rows = []
    for o in operands:
        op = o.operand
        row = {
            "operand": op.label(),
            "value": o.value,
            "target": None if op.bounded else op.target,
            "weight": op.weight,
            "residual": o.residual,
        }
        if op.bounded:
            lo, hi = op.limits
            row["min"] = lo if lo > -math.inf else None
            row["max"] = hi if hi < math.inf else None
        row["aim"] = _aim(op)
        rows.append(row)
    return rows


def _print_table(table: list[dict]) -> None:
    w = max([len("operand"), *(len(r["operand"]) for r in table)])  # whole labels: two rim
    print(f"{'operand':{w}} {'value':>14} {'target / bound':>20} {'weighted resid.':>16}")
    for r in table:  # rays on one surface differ only at the end of theirs
        print(f"{r['operand']:{w}} {r['value']:14.6f} {r['aim']:>20} {r['residual']:16.6g}")


def _search_overrides(args) -> dict:
    from raytrace.optimize import SpecError, parse_duration

    over = {}
    if args.time is not None:
        try:
            over["time_budget_s"] = parse_duration(args.time)
        except SpecError as e:  # say it with the flag's name
            raise CliError(f"--time: {e}") from None
    for name, lo in (("seed", 0), ("starts", 1), ("workers", 1), ("hops", 0)):
        v = getattr(args, name)
        if v is not None:
            if v < lo:
                raise CliError(f"--{name} must be at least {lo}, got {v}")
            over[name] = v
    return over


def _toml_table(path: Path) -> dict | None:
    """The TOML table of the file ``path``, or None when it cannot be read as one."""
    import tomllib

    from raytrace.files.text import read_capped

    try:
        return tomllib.loads(read_capped(path).decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return None


def _is_lens(d: dict | None) -> bool:
    """Whether a TOML table is a lens prescription (surfaces, no variables or operands)."""
    return d is not None and "surfaces" in d and not ("variables" in d or "operands" in d)


def _not_a_spec(what: str, lens: Path) -> str:
    """One line for a lens prescription given as SPEC: the bundled spec whose start it is, else
    the bundled spec names."""
    from raytrace.files.library import library_dir

    specs = {}  # bundled spec name -> its start lens (resolved path), when a file
    for f in sorted((library_dir() / "specs").glob("*.toml"), key=lambda f: f.stem):
        d = _toml_table(f)
        if d is not None and not _is_lens(d) and isinstance(d.get("start"), str):
            specs[f.stem] = (f.parent / d["start"]).resolve()
    mine = [n for n, start in specs.items() if start == lens.resolve()]
    if mine:
        return (
            f"{what} is a lens (a spec's start lens), not a design spec: give a spec, e.g. "
            f"`orthoscope optimize {mine[0]}`"
        )
    return (
        f"{what} is a lens, not a design spec: give a spec (docs/spec.md), e.g. a bundled one, "
        f"`orthoscope optimize NAME` with NAME one of {', '.join(specs)}"
    )


def _read_spec(text: str):
    """The spec SPEC.toml; a path that does not exist but names a bundled spec says how to run
    that one (a spec path copied from the docs, run outside the repository), and a lens
    prescription (e.g. a bundled spec's start lens) given as SPEC says it is no spec."""
    from raytrace.files.library import bundled_file
    from raytrace.optimize import SpecError, read_spec
    from raytrace.optimize.spec import resolve_spec_path

    try:
        return read_spec(text)
    except SpecError as e:
        p = resolve_spec_path(text)
        if p.is_file() and _is_lens(_toml_table(p)):
            raise SpecError(_not_a_spec(text, p)) from None
        b = None if p.exists() or p.suffix.lower() != ".toml" else bundled_file("specs", p.stem)
        if b is None:
            raise
        if _is_lens(_toml_table(b)):
            raise SpecError(f"{e}; {_not_a_spec(f'the bundled {b.stem}', b)}") from None
        raise SpecError(
            f"{e}; the bundled spec of that name is `orthoscope optimize {b.stem}`"
        ) from None


def cmd_optimize(args) -> int:
    from raytrace.files.output import check_output
    from raytrace.optimize import start_lens

    if not args.global_search:
        refuse_flags(
            "{} belong(s) to the global search: add --global",
            (
                ("--time", args.time is not None),
                ("--seed", args.seed is not None),
                ("--starts", args.starts is not None),
                ("--workers", args.workers is not None),
                ("--hops", args.hops is not None),
                ("--glass-map", args.glass_map is not None),
                ("--dask", args.dask is not None),
            ),
        )
    if args.dask is not None and args.workers is not None:
        raise CliError("--workers is for local processes; with --dask the cluster has its own")
    check_dask(args.dask)
    spec = _read_spec(args.spec)
    if args.method is not None:
        spec = replace(spec, method=args.method)
    if args.max_evaluations is not None:
        if args.max_evaluations < 1:
            raise CliError("--max-evaluations must be at least 1")
        spec = replace(spec, max_evaluations=args.max_evaluations)
    out = Path(args.output)
    if out.suffix.lower() != ".toml":
        raise CliError(f"-o {out}: the output lens file must end in .toml")
    over = _search_overrides(args) if args.global_search else {}
    lens = start_lens(spec)
    inputs = [spec.path] + ([lens.path] if lens.path else [])
    lens, spec = _edit_elements(args, lens, spec)
    # every output is checked before the run
    check_output(args.output, inputs=inputs, overwrite=args.force, flag="--force")  # as typed
    if args.glass_map is not None:
        gm = Path(args.glass_map)
        if not any(v.kind == "glass" for v in spec.variables):
            raise CliError(f"--glass-map: the spec {spec.path} has no glass variables to map")
        if gm.suffix.lower() not in (".png", ".svg", ".pdf"):
            raise CliError(f"--glass-map {gm}: use a .png, .svg or .pdf file")
        if gm.resolve() == out.resolve():
            raise CliError("--glass-map and -o name the same file")
        check_output(args.glass_map, inputs=inputs, overwrite=args.force, flag="--force")
    if args.global_search:
        return _run_global(args, spec, lens, out, inputs, over)
    if args.split == ["auto"]:
        return _run_split_scan(args, spec, lens, out, inputs)
    return _run_local(args, spec, lens, out, inputs)


def _run_split_scan(args, spec, lens, out, inputs) -> int:
    """--split auto: every element split in turn, a local run each; the best goes on."""
    from raytrace.optimize import scan_splits, split_design

    quiet = args.quiet or args.json

    def said(t) -> None:
        if not quiet:
            what = f"merit {t.merit:.6g}" if t.result is not None else f"no run: {t.error}"
            print(f"--split {t.surface}: {what}", file=sys.stderr, flush=True)

    trials = scan_splits(lens, spec, progress=said)  # a Ctrl-C ends it with the trials so far
    stopped = next((t.stopped for t in trials if t.stopped), "")
    done = [t for t in trials if t.result is not None]
    if not done:
        raise CliError(
            "--split auto: no element could be split and optimized ("
            + "; ".join(f"{t.surface}: {t.error}" for t in trials)
            + ")"
        )
    best = min(done, key=lambda t: (t.merit, t.surface))
    tried = ", ".join(
        f"{t.surface}: {t.merit:.4g}" if t.result is not None else f"{t.surface}: no run"
        for t in trials
    )
    if stopped:
        tried += f"; {_stop_words(stopped)} at element {trials[-1].surface}"
    lens, spec = split_design(lens, spec, best.surface)
    spec = replace(
        spec,
        start=f"{spec.start} edited by --split {best.surface} (best of --split auto, merits "
        f"by element {tried})",
    )
    return _run_local(args, spec, lens, out, inputs, res=best.result, stopped=stopped)


def _edit_elements(args, lens, spec):
    """Apply --split K and --insert K:GLASS to the start lens and renumber the spec (surface
    numbers of the start lens; applied from the last surface back so each keeps its meaning)."""
    if args.split and "auto" in args.split:
        if len(args.split) > 1 or args.insert or args.global_search:
            raise CliError(
                "--split auto tries each element alone with a local run: give it without "
                "other --split / --insert and without --global (run --global on its result)"
            )
        return lens, spec
    splits = []
    for text in args.split or ():
        if not str(text).strip().isdigit():
            raise CliError(f"--split {text}: give the element's first surface number, or auto")
        splits.append(int(text))
    edits = [(k, "split", None) for k in splits]
    for text in args.insert or ():
        after, sep, glass = str(text).partition(":")
        if not (sep and after.strip().isdigit() and glass.strip()):
            raise CliError(
                f"--insert {text}: use AFTER:GLASS, e.g. --insert 4:N-BK7 (a catalog glass) or "
                "--insert 4:1.62/60.3 (nd/vd model glass)"
            )
        edits.append((int(after), "insert", glass.strip()))
    if not edits:
        return lens, spec
    places = [(k, what) for k, what, _ in edits]
    twice = sorted({f"--{w} {k}" for k, w in places if places.count((k, w)) > 1})
    if twice:
        raise CliError(
            f"{', '.join(twice)} given twice: each element is split (each air space filled) "
            "once per run; run again on the result for more"
        )
    from raytrace.optimize import insert_design, split_design

    flags = _edit_flags(args)
    for k, what, glass in sorted(edits, key=lambda e: e[0], reverse=True):
        if what == "split":
            lens, spec = split_design(lens, spec, k)
        else:
            lens, spec = insert_design(lens, spec, k, _glass_material(glass))
    return lens, replace(spec, start=f"{spec.start} edited by {' '.join(flags)}")


def _edit_flags(args) -> list[str]:
    """The --split K / --insert K:GLASS flags that edited the start lens (none for auto)."""
    if args.split == ["auto"]:
        return []
    flags = [f"--split {k}" for k in args.split or ()]
    return flags + [f"--insert {t}" for t in args.insert or ()]


def _edited_start_error(args, spec, err):
    """The error for a start lens on which an operand's chief ray fails (``err``, a
    :class:`raytrace.optimize.solver.StartLensError`): when --split / --insert made that lens,
    the fix is another edit (each half of a split element is half as thick, so its surfaces
    meet nearer the axis; a plate's flat face can cut a concave neighbour: the chief ray of a
    large field then meets overlapping surfaces); else ``err`` as it is."""
    from raytrace.optimize.operands import ChiefRayError

    flags = _edit_flags(args)
    if not flags or not isinstance(err.cause, ChiefRayError):
        return err
    search = ", and no start of the search gave a design" if args.global_search else ""
    auto = "" if args.global_search else " (--split auto tries every element)"
    return CliError(
        f"{' '.join(flags)}: on the start lens this makes, {err.cause.problem}{search}; split "
        f"another element or insert elsewhere{auto}, or lower the operand's field in {spec.path}"
    )


def _glass_material(text: str):
    """--insert's glass: a catalog name (N-BK7, N-BK7_SCHOTT) or a model glass in the forms the
    lens files take (nd/vd, nd:vd, a glass code; :func:`raytrace.glass.parse_glass_code`)."""
    from raytrace.glass import lookup_glass, parse_glass_code

    model = parse_glass_code(text)
    if model is not None:
        return model
    if "/" in text:
        raise CliError(
            f"--insert ...:{text}: an nd/vd model glass is two numbers (nd > 1, vd > 0), "
            "e.g. 1.62/60.3"
        )
    return lookup_glass(text).material


def _write_design(
    args, res, spec, out, inputs, notes, source: str, *, stopped: str = "", said: bool = False
) -> bool:
    """Write the optimized lens ``res.lens`` to ``out`` when it converged, or was interrupted
    (``stopped``: the best design found is kept), or with ``--write-anyway``; one that did not
    converge has its notes marked NOT CONVERGED unless they say so already (``said``: a run
    cut short by a stop, which was stopped, not failed, and whose notes say so). ``notes()``
    gives its provenance notes and ``source`` its origin. Returns whether it was written."""
    from raytrace.files.native import write_lens

    written = res.converged or args.write_anyway or stopped == "interrupted"
    if written:
        designed = replace(res.lens, name=spec.name or res.lens.name, notes=notes(), source=source)
        if not (res.converged or said):
            designed = replace(designed, notes=designed.notes + " NOT CONVERGED: " + res.message)
        write_lens(designed, out, inputs=inputs, overwrite=args.force, flag="--force")
    return written


def _result_json(spec, res, out, written, table, before=None, after=None) -> dict:
    """The JSON of an optimization run: spec, start, ``before`` (the global search's
    settings), convergence, merit, evaluations, seconds, ``after`` (the chosen glasses), the
    file written (or None) and the operand table."""
    return {
        "spec": spec.path,
        "start": spec.start,
        **(before or {}),
        "converged": res.converged,
        "message": res.message,
        "merit_start": res.merit_start,
        "merit": res.merit,
        "evaluations": res.evaluations,
        "seconds": res.seconds,
        **(after or {}),
        "written": str(out) if written else None,
        "operands": table,
    }


def _run_local(args, spec, lens, out, inputs, res=None, stopped: str = "") -> int:
    """A local run (or its result ``res``, already computed; ``stopped``: why the work that
    gave it was cut short) reported and written. Ctrl-C during the run ends it with the best
    design evaluated so far, written and marked as interrupted (exit status 130), as --global
    does; a Ctrl-C before the start lens is evaluated keeps nothing."""
    from raytrace.optimize import optimize
    from raytrace.optimize.solver import StartLensError

    name = MERIT_NAMES[spec.method]
    if res is None:
        prog = _Progress(args.quiet or args.json, "max|r|" if spec.method == "minimax" else "merit")
        try:
            res = optimize(lens, spec, progress=prog)
        except StartLensError as e:
            raise _edited_start_error(args, spec, e) from None
        finally:
            prog.done()
    stopped = res.stopped or stopped
    table = _operand_table(res.operands)
    written = _write_design(
        args, res, spec, out, inputs,
        lambda: provenance_notes(lens, spec, res, spec.start),
        f"derived by orthoscope optimize from {spec.start} with {Path(spec.path).name}",
        stopped=stopped, said=bool(res.stopped),
    )  # fmt: skip
    if args.json:
        extra = {
            "method": res.method,
            "merit_is": name,
            "violation": res.violation,
            "stopped": stopped or None,
        }
        print_json(_result_json(spec, res, out, written, table, after=extra))
    else:
        print(f"{spec.name}: {res.message}")
        print(
            f"{name} {res.merit_start:.6g} -> {res.merit:.6g} in {res.evaluations} evaluations "
            f"({res.seconds:.1f} s)"
        )
        if res.method == "minimax":
            worst = max(res.operands, key=lambda o: abs(o.residual))
            print(
                f"method minimax: the merit is max |weight x (value - target)| over the target "
                f"operands; largest bound violation {res.violation:.3g}; worst operand "
                f"{worst.operand.label()}"
            )
        _print_table(table)
        print(
            f"wrote {out}"
            if written
            else "NOT CONVERGED: no lens written (--write-anyway "
            "writes it, marked as not converged)"
        )
    if stopped == "interrupted":
        print("orthoscope optimize: interrupted; the best design found was kept", file=sys.stderr)
        return EXIT_INTERRUPTED
    return 0 if res.converged else EXIT_NOT_CONVERGED


def _run_global(args, spec, lens, out, inputs, over) -> int:
    from raytrace.optimize import global_optimize
    from raytrace.optimize.solver import StartLensError

    spec = replace(spec, search=replace(spec.search, **over))  # the notes tell the settings
    prog = GlobalProgress(spec.search.starts, args.quiet or args.json)
    try:
        res = global_optimize(lens, spec, progress=prog, executor=args.dask)
    except StartLensError as e:
        raise _edited_start_error(args, spec, e) from None
    finally:
        prog.close()
    table = _operand_table(res.operands)
    written = _write_design(
        args, res, spec, out, inputs,
        lambda: global_provenance_notes(spec, res, spec.start, args.dask),
        f"derived by orthoscope optimize --global from {spec.start} with {Path(spec.path).name}",
        stopped=res.stopped, said=bool(res.stopped),
    )  # fmt: skip
    if args.glass_map is not None:
        from raytrace.optimize import glass_pool

        from ..plots.glassmap import plot_glass_map
        from ..plots.save import save_figure

        pools = {}
        for v in spec.variables:
            if v.kind == "glass":
                p = glass_pool(spec.glass_settings(v))
                pools.update({(g.name, g.catalog): g for g in p.glasses})
        fig = plot_glass_map(
            pools.values(), res.glasses, title=f"{spec.name}: glass pool and chosen glasses"
        )
        save_figure(fig, args.glass_map, overwrite=args.force, inputs=inputs, flag="--force")
    if args.json:
        search = {
            "global": True,
            "seed": res.seed,
            "starts": res.starts,
            "starts_done": res.starts_done,
            "starts_stopped": res.starts_stopped,
            "best_start": res.best_start,
            "start_merits": [None if m != m else float(m) for m in res.start_merits],
            "workers": res.workers,
            "stopped": res.stopped or None,
            "method": res.method,
            "merit_is": res.merit_is,
            "violation": res.violation,
        }
        glasses = {
            "glasses": [
                {
                    "surface": g.surface,
                    "name": g.name,
                    "catalog": g.catalog,
                    "nd": g.nd,
                    "vd": g.vd,
                    "availability": g.availability,
                    "relative_price": g.price,
                }
                for g in res.glasses
            ],
        }
        print_json(_result_json(spec, res, out, written, table, search, glasses))
    else:
        print(f"{spec.name}: {res.message}")
        name = res.merit_is
        print(
            f"{name} {res.merit_start:.6g} -> {res.merit:.6g}; {res.evaluations} evaluations "
            f"({res.seconds:.1f} s, {res.workers} worker(s))"
        )
        if res.method == "minimax":
            print(f"method minimax in every local run; largest bound violation {res.violation:.3g}")
        fin = [m for m in res.start_merits if m == m]
        if fin:
            print(
                f"{name} per start: min {min(fin):.6g}, median "
                f"{statistics.median(fin):.6g}, max {max(fin):.6g}"
            )
        for g in res.glasses:
            print(
                f"glass after surface {g.surface}: {g.name} ({g.catalog}, nd {g.nd:.5f}, "
                f"vd {g.vd:.2f}, {g.availability}"
                + (f", relative price {g.price:g}" if g.price == g.price else "")
                + ")"
            )
        _print_table(table)
        if written:
            print(f"wrote {out}")
        elif res.stopped:  # stopped (time budget, cluster lost) short of the goal: not a failure
            print(
                f"no lens written: the search stopped ({_stop_words(res.stopped)}) "
                "short of the spec's goal (--write-anyway writes it)"
            )
        else:
            print("NOT CONVERGED: no lens written (--write-anyway writes it, marked as such)")
        if args.glass_map is not None:
            print(f"wrote {args.glass_map}")
    if res.stopped == "interrupted":
        from raytrace.optimize.global_search import starts_count

        count = starts_count(res.starts_finished, res.starts_stopped, res.starts, True)
        print(
            f"orthoscope optimize: interrupted with {count}; the best design found was kept",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    if res.stopped == "cluster":
        kept = "; the best design found was kept" if written else ""
        print(f"orthoscope optimize: {res.message}{kept}", file=sys.stderr)
        return 1
    return 0 if res.converged else EXIT_NOT_CONVERGED


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "optimize",
        help="Run a design spec (damped least squares, or --global search) and write the lens.",
        description=(
            "Optimize a lens from a TOML design spec (the language: docs/spec.md): start lens, "
            "variables (curvature, thickness, index, abbe, conic, A4, A6, A8, A10 of 1-based "
            "surfaces, with bounds; glass = substitution among real catalog glasses, --global "
            "only), pick-ups, and operands with targets and weights (efl, m_e, HE0, HpE0p, "
            "distortion, distortion_rel, distortion_slope, image_height, landing_angle, "
            "best_focus, rms_spot, ray_height, axial_color, element_power, center_thickness, "
            "edge_thickness; any operand "
            "may give min / max instead of a target: a one-sided bound). Without --global: "
            "damped least squares from the start lens, or minimax (--method minimax, or the "
            'spec\'s method = "minimax": the largest weighted residual is minimised, the '
            "bounds are constraints); progress (evaluation, merit, worst operand) goes to "
            "stderr. With --global: many starts and basin hops around "
            "the local method (damped least squares or minimax), glass substitution, in "
            "parallel worker processes; seeded "
            "and deterministic (the same seed gives the same lens whatever --workers); a "
            "progress bar on a terminal (tqdm) or plain lines; --time stops it and keeps the "
            "best design found. The lens is written with its "
            "provenance (start lens, spec, seed, merit, date) when the run converged / met the "
            "spec's merit_goal (exit status 0); otherwise the exit status is 1 and nothing is "
            "written (--write-anyway writes it, marked). Ctrl-C stops a run, local or --global, "
            "and writes the best design evaluated so far, its notes marked as interrupted "
            "(exit status 130; nothing is written when no design was evaluated yet)."
        ),
        epilog="Examples: orthoscope optimize lenses/specs/twinplex-like-55-525.toml "
        "-o my-twinplex.toml;  orthoscope optimize lenses/specs/twinplex-like-55-525.toml "
        "--global --starts 2 --seed 1 -o my-global.toml",
    )
    q.add_argument("spec", metavar="SPEC.toml", help="Design spec file (docs/spec.md).")
    q.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="LENS.toml",
        help="Where to write the designed lens.",
    )
    q.add_argument(
        "--method",
        choices=("least_squares", "minimax"),
        help="Override the spec's method: damped least squares (merit: sum of squared weighted "
        "residuals) or minimax (merit: the largest |weighted residual| of the target operands, "
        "the operands with min / max as constraints); with --global, the method of every local "
        "run.",
    )
    q.add_argument(
        "--max-evaluations",
        type=int,
        metavar="N",
        help="Override the spec's evaluation limit (with --global: of the final polish, and of "
        "each local run unless the spec's [global] local_evaluations says otherwise).",
    )
    g = q.add_argument_group("global search (the spec's [global] table gives the defaults)")
    g.add_argument(
        "--global",
        dest="global_search",
        action="store_true",
        help="Global search: many starts and basin hopping around the local method (damped "
        "least squares, or minimax), with glass substitution for the spec's glass variables.",
    )
    g.add_argument(
        "--time", metavar="T", help="Time budget, e.g. 90s, 10m, 1h30m; the best design is kept."
    )
    g.add_argument("--seed", type=int, metavar="S", help="Root seed (integer >= 0).")
    g.add_argument("--starts", type=int, metavar="N", help="Number of starts.")
    g.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="Worker processes (default: the spec's, else 1); the result does not depend on it.",
    )
    g.add_argument("--hops", type=int, metavar="N", help="Basin hops per start.")
    g.add_argument(
        "--dask",
        metavar="EXECUTOR",
        help="Run the starts on a Dask cluster: local:N (N worker processes here) or "
        "tcp://HOST:PORT (a running scheduler); the same design as without it. Needs the dask "
        "extra (pip install 'orthoscope[dask]').",
    )
    g.add_argument(
        "--glass-map",
        metavar="FILE",
        help="Also draw the glass pool and the chosen glasses (.png, .svg, .pdf).",
    )
    q.add_argument(
        "--write-anyway",
        action="store_true",
        help="Write the lens even when the run did not converge (marked in its notes).",
    )
    e = q.add_argument_group("elements (surface numbers of the start lens; the spec follows)")
    e.add_argument(
        "--split",
        action="append",
        metavar="K",
        help="Split the element whose first surface is K in two (cut at the mean curvature, "
        "0.1 mm apart), with variables and rules for the new half; repeatable. 'auto': try "
        "every element with a local run and keep the best (not with --global).",
    )
    e.add_argument(
        "--insert",
        action="append",
        metavar="K:GLASS",
        help="Insert a 2 mm plate of GLASS (a catalog name, or nd/vd such as 1.62/60.3) in the "
        "middle of the air space after surface K (free curvatures, thickness variable); "
        "repeatable.",
    )
    q.add_argument("--quiet", action="store_true", help="No progress display.")
    add_force_arg(q)
    add_output_args(q, csv=False, json_help="Print the result as JSON.")
    q.set_defaults(func=cmd_optimize)
