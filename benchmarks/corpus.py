"""Real-file reading benchmark: how many published lens files does orthoscope read?

    python benchmarks/corpus.py                    # the corpus in tests/data/corpus, a table
    python benchmarks/corpus.py --json             # the same, machine-readable, on stdout
    python benchmarks/corpus.py DIR_OR_FILE ...    # any other files (e.g. a larger scratch set)
    python benchmarks/corpus.py --referees         # also: do optiland / ray-optics read them?

Every file is read with orthoscope's own loader (``orthoscope.load_lens``; older layouts
``raytrace.library.load_lens`` / ``raytrace.files.library.load_lens`` are tried in turn) and
classified as

- ``read``: a :class:`~raytrace.lens.Lens` came back (InteropWarnings are counted per file);
- ``refused``: the reader raised ``PrescriptionError``, grouped by the reason its message names
  (see :data:`CATEGORIES`; the first matching group wins, so a file with a mirror *and* a tilt is
  counted under whichever the reader met first);
- ``crashed``: any other exception — a bug in the reader, listed with its traceback;
- ``hang``: the read took longer than ``--timeout`` seconds (also a bug).

The corpus and the source of every file are described in tests/data/corpus/SOURCES.md; the
test tests/test_corpus.py asserts that no file crashes or hangs.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import logging
import math
import re
import signal
import sys
import time
import traceback
import warnings
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CORPUS = ROOT / "tests" / "data" / "corpus"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

#: file suffixes counted as lens files (lower case): Zemax, CODE V, OSLO (.len) and Zemax
#: archives (.zar, refused with a PrescriptionError that says to unpack them).
LENS_SUFFIXES = (".zmx", ".seq", ".len", ".zar")

#: refusal groups, in the order they are tried on the PrescriptionError message (case-insensitive)
CATEGORIES: tuple[tuple[str, str], ...] = (
    (
        "file format",
        r"MODE NSC|non-sequential|TOML syntax|not a (zemax|code ?v|lens)|unsupported format|"
        r"cannot decode|encoding|binary file|archive|\.zar|\.len",
    ),
    ("mirror", r"mirror|\bREFL\b|reflect"),
    ("coordinate break", r"COORDBRK|coordinate break"),
    (
        "tilt/decenter",
        r"decent|tilt|\b(XDE|YDE|ZDE|ADE|BDE|CDE|DAR|BEN|REV|RET|DECX|DECY|TILT)\b",
    ),
    ("multi-config", r"multi-?config|configurations?\b|\bZOOM\b|\bMNUM\b|\bMCE\b|\bTHIC\b"),
    ("private glass", r"private glass|\bPRV\b|\bPWL\b|private"),
    ("unknown glass", r"glass|\bGLAS\b|catalog"),
    ("invalid value", r"must be positive|expected a (finite |whole )?number|must be (below|above)"),
    ("field type", r"field|\b(FTYP|YIM|XIM|YRI|XRI|YAN|XAN|YOB|XOB)\b"),
    (
        "aperture type",
        r"aperture type|float by stop|\b(FLOA|WFNO|OBNA|OBJNA|NAO|NA|EPD|FNO|ENPD)\b|f/#|"
        r"numerical aperture",
    ),
    (
        "surface type",
        r"surface type|\bTYPE\b|diffractive|gradient|toroid|grating|freeform|\bDIF\b|"
        r"special surface|\bSPS\b|\bXYP\b|\bHOE\b|\bPARM\b",
    ),
)
OTHER = "other"
CATEGORY_NAMES = tuple(c for c, _ in CATEGORIES) + (OTHER,)
_CATEGORY_RES = tuple((name, re.compile(rx, re.IGNORECASE)) for name, rx in CATEGORIES)


@dataclass(frozen=True)
class Outcome:
    """What happened when orthoscope read one file.

    path:      file path as given (relative to the corpus root when inside it).
    suffix:    lower-case suffix (".zmx", ".seq", ...).
    status:    "read" | "refused" | "crashed" | "hang".
    category:  refusal group (one of :data:`CATEGORY_NAMES`) for "refused", else None.
    message:   the exception's message (the PrescriptionError's reason when it has one).
    exc_type:  exception class name ("" when read).
    warnings:  messages of the warnings raised while reading.
    seconds:   wall time of the read.
    traceback: formatted traceback for "crashed" / "hang", else None.
    """

    path: str
    suffix: str
    status: str
    category: str | None
    message: str
    exc_type: str
    warnings: tuple[str, ...]
    seconds: float
    traceback: str | None


class ReadTimeout(Exception):
    """Raised by the alarm signal when one read takes too long."""


def find_loader() -> Callable[[Any], Any]:
    """orthoscope's public lens loader, wherever the current layout keeps it."""
    for mod, name in (
        ("orthoscope", "load_lens"),
        ("raytrace.library", "load_lens"),
        ("raytrace.files.library", "load_lens"),
    ):
        try:
            module = __import__(mod, fromlist=[name])
            return getattr(module, name)
        except (ImportError, AttributeError):
            continue
    raise ImportError("no orthoscope lens loader found (orthoscope.load_lens)")


def find_prescription_error() -> type[Exception]:
    """The project's PrescriptionError class."""
    for mod in ("raytrace.errors", "raytrace", "orthoscope"):
        try:
            module = __import__(mod, fromlist=["PrescriptionError"])
            return module.PrescriptionError
        except (ImportError, AttributeError):
            continue
    raise ImportError("no PrescriptionError found (raytrace.errors)")


def classify(message: str) -> str:
    """Refusal group of a PrescriptionError message (first matching pattern, else "other")."""
    for name, rx in _CATEGORY_RES:
        if rx.search(message):
            return name
    return OTHER


def lens_files(paths: list[Path]) -> list[Path]:
    """Lens files under ``paths`` (files as given, directories searched recursively), sorted."""
    out: list[Path] = []
    for p in paths:
        if p.is_dir():
            out.extend(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in LENS_SUFFIXES)
        elif p.is_file():
            out.append(p)
        else:
            raise FileNotFoundError(p)
    return sorted(set(out))


def display_path(path: Path) -> str:
    """``path`` relative to the corpus root when it lies inside it, else as given."""
    try:
        return str(path.resolve().relative_to(CORPUS.resolve()))
    except ValueError:
        return str(path)


@contextlib.contextmanager
def time_limit(seconds: float, error: BaseException | type[BaseException] = ReadTimeout):
    """Raise ``error`` (an exception or its class) in the block after ``seconds`` (main thread,
    POSIX; no limit otherwise). The tests' time limit too (tests/support.py)."""

    def handler(signum, frame):  # noqa: ARG001 - signal handler signature
        raise error

    usable = seconds > 0 and hasattr(signal, "setitimer")
    if usable:
        try:
            old = signal.signal(signal.SIGALRM, handler)
        except ValueError:  # not the main thread
            usable = False
    if not usable:
        yield
        return
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def read_one(
    path: Path,
    loader: Callable[[Any], Any] | None = None,
    prescription_error: type[Exception] | None = None,
    timeout: float = 30.0,
) -> Outcome:
    """Read ``path`` with orthoscope's loader and classify the outcome (never raises for a
    reader failure; KeyboardInterrupt and SystemExit pass through)."""
    loader = loader or find_loader()
    perr = prescription_error or find_prescription_error()
    caught: list[warnings.WarningMessage] = []
    t0 = time.perf_counter()
    status, category, message, exc_type, tb = "read", None, "", "", None
    try:
        with warnings.catch_warnings(record=True) as caught, time_limit(timeout):
            warnings.simplefilter("always")
            loader(path)
    except ReadTimeout:
        status, exc_type = "hang", "ReadTimeout"
        message = f"no result after {timeout:g} s"
        tb = traceback.format_exc()
    except perr as e:
        status, exc_type = "refused", type(e).__name__
        message = str(getattr(e, "reason", None) or e)
        category = classify(message)
    except Exception as e:  # noqa: BLE001 - any other exception is what we are looking for
        status, exc_type = "crashed", type(e).__name__
        message = str(e)
        tb = traceback.format_exc()
    seconds = time.perf_counter() - t0
    return Outcome(
        path=display_path(path),
        suffix=path.suffix.lower(),
        status=status,
        category=category,
        message=" ".join(message.split()),
        exc_type=exc_type,
        warnings=tuple(_strip_path(" ".join(str(w.message).split()), path) for w in caught),
        seconds=seconds,
        traceback=tb,
    )


def _strip_path(message: str, path: Path) -> str:
    """``message`` without a leading "<path>: " (the readers' warnings start with the file)."""
    for p in (str(path), str(path.resolve())):
        if message.startswith(p + ": "):
            return message[len(p) + 2 :]
    return message


def run(paths: list[Path], timeout: float = 30.0) -> list[Outcome]:
    """Read every lens file under ``paths``."""
    loader = find_loader()
    perr = find_prescription_error()
    return [read_one(f, loader, perr, timeout) for f in lens_files(paths)]


def summarize(outcomes: list[Outcome]) -> dict[str, Any]:
    """Counts and fractions: overall, per status, per refusal group, per suffix."""
    n = len(outcomes)
    status = Counter(o.status for o in outcomes)
    groups = Counter(o.category for o in outcomes if o.status == "refused")
    by_suffix: dict[str, dict[str, int]] = {}
    for o in outcomes:
        d = by_suffix.setdefault(o.suffix, {"files": 0, "read": 0})
        d["files"] += 1
        d["read"] += o.status == "read"
    return {
        "files": n,
        "read": status["read"],
        "read_fraction": status["read"] / n if n else math.nan,
        "read_with_warnings": sum(1 for o in outcomes if o.status == "read" and o.warnings),
        "refused": status["refused"],
        "crashed": status["crashed"],
        "hang": status["hang"],
        "refused_by_category": {c: groups[c] for c in CATEGORY_NAMES if groups[c]},
        "by_suffix": by_suffix,
    }


def format_report(outcomes: list[Outcome], summary: dict[str, Any], per_file: bool = True) -> str:
    """Plain-text report: per-file table (optional), refusal groups, crashes, the fraction."""
    lines: list[str] = []
    if per_file:
        w = max([len(o.path) for o in outcomes] + [4])
        lines.append(f"{'file'.ljust(w)}  {'outcome':<26}  reason")
        for o in outcomes:
            what = o.status if o.status != "refused" else f"refused: {o.category}"
            if o.status == "read" and o.warnings:
                what = f"read ({len(o.warnings)} warning{'s' * (len(o.warnings) > 1)})"
            why = o.message if o.status != "read" else "; ".join(o.warnings)
            lines.append(f"{o.path.ljust(w)}  {what:<26}  {why[:110]}")
        lines.append("")
    n = summary["files"]
    lines.append("outcome                    files  fraction")
    rows = [("read", summary["read"])]
    rows += [(f"refused: {c}", k) for c, k in summary["refused_by_category"].items()]
    rows += [("crashed (bug)", summary["crashed"]), ("hang (bug)", summary["hang"])]
    for name, k in rows:
        lines.append(f"{name:<26} {k:>5}  {k / n if n else math.nan:8.1%}")
    lines.append(f"{'total':<26} {n:>5}")
    sfx = ", ".join(
        f"{s} {d['read']}/{d['files']}" for s, d in sorted(summary["by_suffix"].items())
    )
    lines.append(f"read by suffix: {sfx}")
    lines.append(
        f"read {summary['read']} of {n} files ({summary['read_fraction']:.1%}); "
        f"{summary['read_with_warnings']} of them with warnings (skipped commands)"
    )
    bad = [o for o in outcomes if o.status in ("crashed", "hang")]
    if bad:
        lines.append("")
        lines.append(f"BUGS: {len(bad)} file(s) crashed or hung the reader:")
        for o in bad:
            lines.append(f"--- {o.path}: {o.exc_type}: {o.message}")
            lines.append((o.traceback or "").rstrip())
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# Referees: do the independent tools read the same files? (optional; lazy imports)
# --------------------------------------------------------------------------------------------


def _quiet():
    """Silence stdout and the root logger while a foreign reader runs."""
    stack = contextlib.ExitStack()
    stack.enter_context(contextlib.redirect_stdout(io.StringIO()))
    stack.enter_context(warnings.catch_warnings())
    warnings.simplefilter("ignore")
    previous = logging.root.manager.disable
    logging.disable(logging.CRITICAL)
    stack.callback(logging.disable, previous)
    return stack


def referee_optiland(path: Path) -> dict[str, Any]:
    """optiland: read the file (``optiland.fileio.load_zemax_file`` / ``load_codev_file`` /
    ``load_oslo_file``) and take its paraxial EFL at its primary wavelength."""
    from optiland.fileio import load_codev_file, load_oslo_file, load_zemax_file

    readers = {".zmx": load_zemax_file, ".seq": load_codev_file, ".len": load_oslo_file}
    reader = readers.get(path.suffix.lower())
    if reader is None:
        return {"status": "no reader"}
    op = reader(str(path))
    return {
        "status": "read",
        "efl": float(op.paraxial.f2()),
        "wavelength_nm": float(op.primary_wavelength) * 1000.0,
    }


def referee_rayoptics(path: Path) -> dict[str, Any]:
    """ray-optics: read the file with its non-GUI readers (``rayoptics.zemax.zmxread.
    read_lens_file`` / ``rayoptics.codev.cmdproc.read_lens``) and take its paraxial EFL at its
    central wavelength; glasses it substituted are listed (they change the numbers)."""
    suffix = path.suffix.lower()
    if suffix == ".zmx":
        from rayoptics.zemax.zmxread import read_lens_file as reader
    elif suffix == ".seq":
        from rayoptics.codev.cmdproc import read_lens as reader
    else:
        return {"status": "no reader"}
    opm, (_, substituted) = reader(path)
    fod = opm["analysis_results"]["parax_data"].fod
    return {
        "status": "read",
        "efl": float(fod.efl),
        "wavelength_nm": float(opm["optical_spec"]["wvls"].central_wvl),
        "substituted_glasses": sorted(substituted),
    }


def orthoscope_efl(path: Path) -> float | None:
    """orthoscope's paraxial EFL at the lens's own wavelength (None when not read)."""
    try:
        from orthoscope import paraxial
    except ImportError:  # older layout
        from raytrace.paraxial import paraxial
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return float(paraxial(find_loader()(path)).efl)
        except Exception:  # noqa: BLE001 - refusals are reported by the main run
            return None


def run_referees(files: list[Path], timeout: float = 60.0) -> list[dict[str, Any]]:
    """For each file: which referees read it, and the EFL each one (and orthoscope) computes."""
    rows = []
    for f in files:
        row: dict[str, Any] = {"path": display_path(f), "orthoscope_efl": orthoscope_efl(f)}
        for name, fn in (("optiland", referee_optiland), ("rayoptics", referee_rayoptics)):
            try:
                with _quiet(), time_limit(timeout):
                    row[name] = fn(f)
            except ImportError as e:
                row[name] = {"status": "not installed", "error": str(e)}
            except ReadTimeout:
                row[name] = {"status": "hang"}
            except Exception as e:  # noqa: BLE001 - a referee's failure is data here
                row[name] = {"status": "failed", "error": f"{type(e).__name__}: {e}"[:200]}
        rows.append(row)
    return rows


def format_referees(rows: list[dict[str, Any]]) -> str:
    """Table: EFL per file from orthoscope, optiland and ray-optics, and who reads what."""

    def cell(r: dict[str, Any]) -> str:
        if r.get("status") != "read":
            return r.get("status", "?")
        s = f"{r['efl']:.9g}"
        if r.get("substituted_glasses"):
            s += " (subst. " + ",".join(r["substituted_glasses"]) + ")"
        return s

    w = max([len(r["path"]) for r in rows] + [4])
    lines = [f"{'file'.ljust(w)}  {'orthoscope EFL':>16}  {'optiland EFL':>16}  rayoptics EFL"]
    for r in rows:
        o = "-" if r["orthoscope_efl"] is None else f"{r['orthoscope_efl']:.9g}"
        lines.append(f"{r['path'].ljust(w)}  {o:>16}  {cell(r['optiland']):>16}  "
                     f"{cell(r['rayoptics'])}")  # fmt: skip
    n = len(rows)
    for name in ("optiland", "rayoptics"):
        k = sum(1 for r in rows if r[name].get("status") == "read")
        lines.append(f"{name} reads {k} of {n} files")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="*", type=Path, help="files or directories (default: corpus)")
    ap.add_argument("--json", action="store_true", help="print JSON instead of the table")
    ap.add_argument("--summary", action="store_true", help="no per-file table")
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds per file (hang limit)")
    ap.add_argument(
        "--referees", action="store_true", help="also read each file with optiland and ray-optics"
    )
    args = ap.parse_args(argv)
    paths = args.paths or [CORPUS]
    outcomes = run(paths, timeout=args.timeout)
    summary = summarize(outcomes)
    referees = run_referees(lens_files(paths)) if args.referees else None
    if args.json:
        doc: dict[str, Any] = {
            "summary": summary,
            "files": [asdict(o) for o in outcomes],
        }
        if referees is not None:
            doc["referees"] = referees
        print(json.dumps(doc, indent=1))
    else:
        print(format_report(outcomes, summary, per_file=not args.summary))
        if referees is not None:
            print()
            print(format_referees(referees))
    return 1 if summary["crashed"] or summary["hang"] else 0


if __name__ == "__main__":
    sys.exit(main())
