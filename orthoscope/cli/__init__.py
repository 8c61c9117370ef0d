"""The ``orthoscope`` command line: one module per subcommand in this package.

Every subcommand prints a readable table by default, ``--json`` (stable keys with units, see the
README) or ``--csv`` for programs. Errors a person can cause print one line naming the file, line
or surface and exit with status 2; Ctrl-C exits with 130 and one line; there is never a traceback
(set ORTHOSCOPE_DEBUG=1 to see one).

The command registry is :data:`COMMANDS`: each module defines ``register(subparsers)`` that adds
its parser and sets ``func`` to a handler ``handler(args) -> int``. Tests iterate over the
registry, so a new command is covered by the per-command tests without anyone remembering to.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from collections.abc import Sequence

EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

#: subcommands that never run a numba kernel (no "compiling" notice for them)
NO_KERNELS = {"lenses", "prescription", "paraxial", "calibrate", "convert", "glass"}

#: The subcommands, in the order ``orthoscope --help`` lists them (module names in this package).
COMMANDS: tuple[str, ...] = (
    "lenses",
    "prescription",
    "paraxial",
    "trace",
    "fan",
    "distortion",
    "pupils",
    "report",
    "colour",
    "calibrate",
    "compensate",
    "variation",
    "coefficients",
    "camera",
    "optimize",
    "tolerance",
    "convert",
    "glass",
)


def _version() -> str:
    from .. import __version__

    return __version__


class _VersionAction(argparse._VersionAction):
    """``--version``: the version is read when asked for (importlib.metadata costs about 20 ms
    of every run otherwise)."""

    def __call__(self, parser, namespace, values, option_string=None):
        self.version = f"orthoscope {_version()}"
        super().__call__(parser, namespace, values, option_string)


class HelpFormatter(argparse.HelpFormatter):
    """Help with the defaults shown (where there is one) and text with line breaks (the examples
    of an epilog) kept as written; other paragraphs are wrapped."""

    def _get_help_string(self, action: argparse.Action) -> str:
        h = action.help or ""
        d = action.default
        if d in (None, False, argparse.SUPPRESS, []) or "default" in h.lower():
            return h
        return h + " (default: %(default)s)"

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        if "\n" in text:
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``PROG: error: WHAT (see PROG --help)``, exit status 2, and
    defaults shown in the help."""

    def __init__(self, *args, **kw) -> None:
        kw["formatter_class"] = HelpFormatter
        super().__init__(*args, **kw)

    def error(self, message: str):  # type: ignore[override]
        import difflib
        import re

        m = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
        if m:
            choices = re.findall(r"'([^']*)'", m.group(2))
            close = difflib.get_close_matches(m.group(1), choices, n=1)
            if close:
                message += f"; did you mean '{close[0]}'?"
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _subparser(parser: argparse.ArgumentParser, name: str | None):
    """The parser of subcommand ``name`` (None if there is none)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices.get(name)
    return None


_SIGNED = re.compile(r"^-(\d|\.\d)")


def signed_values(argv: Sequence[str]) -> list[str]:
    """``--fields -10,0,10`` → ``--fields=-10,0,10``: a value that starts with a minus sign and a
    digit is joined to the long option before it (argparse would take it for an option; no
    option of orthoscope starts with a digit)."""
    out: list[str] = []
    for tok in argv:
        if out and _SIGNED.match(tok) and out[-1].startswith("--") and "=" not in out[-1]:
            out[-1] = f"{out[-1]}={tok}"
        else:
            out.append(tok)
    return out


def command_of(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` runs, when that is plain without parsing: the first word after
    the global options ``--allow-large`` and ``--threads N``, and one of :data:`COMMANDS`.
    None otherwise (any other option first, such as ``--help``, or no such word)."""
    i = 0
    while i < len(argv):
        tok = argv[i]
        if tok == "--threads":
            i += 2
        elif tok == "--allow-large" or tok.startswith("--threads="):
            i += 1
        elif tok.startswith("-"):
            return None
        else:
            return tok if tok in COMMANDS else None
    return None


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command-line parser. With ``command`` (a name of :data:`COMMANDS`, see
    :func:`command_of`) only that command's module is imported and registered: parsing that
    command is the same, and the other modules' imports are saved."""
    p = Parser(
        prog="orthoscope",
        description=(
            "Lens distortion toolkit: paraxial data, real chief rays and Pestrecov's "
            "characteristic and calibrated distortion in Gaussian and non-Gaussian image planes. "
            "LENS is a path to a prescription file (.toml, .zmx, .seq, .len) or the name of a "
            "bundled lens (see 'orthoscope lenses'). Distances in mm; light travels toward +z; "
            "signs follow Pestrecov (1958) Fig. 1."
        ),
        epilog="Run 'orthoscope COMMAND --help' for each command's options.",
    )
    p.add_argument("--version", action=_VersionAction)
    p.add_argument(
        "--allow-large",
        action="store_true",
        help="Lift the work limits (fields, radii, rays per command) that protect against a "
        "mistyped count.",
    )
    p.add_argument(
        "--threads",
        type=int,
        metavar="N",
        help="Numba threads for bulk traces (default: numba's setting, NUMBA_NUM_THREADS).",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    names = COMMANDS if command is None else (command,)
    for name in names:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    if command is not None and command not in sub.choices:  # a module of another name
        for name in COMMANDS:
            if name != command:
                importlib.import_module(f"{__name__}.{name}").register(sub)
    return p


#: API keywords (as the science packages' errors name them: "at=") -> the flags that give them
CLI_FLAGS = {
    "at": "--at",
    "value": "--value",
    "format": "--format",
    "object_s": "--object-s",
    "object_distance": "--object-distance",
    "object_scale": "--object-scale",
    "s_prime": "--s-prime",
    "from_last_vertex": "--from-last-vertex",
    "defocus": "--defocus",
    "n_coefficients": "--coefficients",
    "pixel_size_mm": "--pitch (or --sensor)",
    "camera_id": "--camera-id",
    "magnification": "--magnification",
    "r_min": "--r-min",
    "r_max": "--r-max",
    "threshold_um": "--threshold-um",
    "field_step_deg": "--field-step",
    "max_field_deg": "--max-field",
}


def cli_words(message: str) -> str:
    """An error of the API said with the command line's flags: ``at=`` -> ``--at`` (the same
    words, docs/design.md "Vocabulary"); ``name=value`` examples are left as they are."""
    import re

    message = message.replace("pixel_size_mm=(pitch_x, pitch_y) in mm", "--pitch (or --sensor)")
    message = message.replace("allow_large=True", "--allow-large (before the command)")
    keys = "|".join(CLI_FLAGS)
    message = re.sub(  # key=6 -> --flag 6 (a number the person gave)
        rf"(?<![\w.])({keys})=(-?[0-9][0-9.eE+-]*)\b",
        lambda m: f"{CLI_FLAGS[m.group(1)]} {m.group(2)}",
        message,
    )
    return re.sub(  # key= -> --flag (the flag named, no value)
        rf"(?<![\w.])({keys})=(?![\w'\"(\[-])", lambda m: CLI_FLAGS[m.group(1)], message
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 a run that did not succeed, 2 a
    usage or input error, 130 interrupted)."""
    restore = _sigint_outside_llvm()
    _HELD.update(since=None, command="orthoscope")
    try:
        return _run(argv)
    except KeyboardInterrupt:  # before the command is known (while the engine is imported)
        print("orthoscope: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        restore()
        # the notice and the matplotlib finder belong to this run only (main() runs many times
        # in one process in tests and notebooks; library use after it must not print)
        if _NOTICE:
            _NOTICE[0].quiet = True
        sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, _BeforeMatplotlib)]


def _sigint_outside_llvm():
    """Ctrl-C that arrives while numba loads or compiles a kernel (LLVM calls back into Python
    there) is delivered again 50 ms later instead of at once: a KeyboardInterrupt raised inside
    llvmlite's callbacks is lost ("Exception ignored on calling ctypes callback", the command
    then ran to its end) or leaves LLVM's state broken (a rare segmentation fault). Returns the
    function that puts the previous handler back (nothing changes outside the main thread or
    when a handler of another kind is installed)."""
    import signal
    import threading

    old = signal.getsignal(signal.SIGINT)
    if old is not signal.default_int_handler or threading.current_thread() is not (
        threading.main_thread()
    ):
        return lambda: None

    signal.signal(signal.SIGINT, _sigint_handler)
    return lambda: signal.signal(signal.SIGINT, old)


#: seconds a Ctrl-C is held back while numba works before the run ends at once
SIGINT_HOLD_S = 1.0
#: (monotonic time of the first Ctrl-C held back, the running command's name for its one line)
_HELD: dict[str, object] = {"since": None, "command": "orthoscope"}


def _sigint_handler(signum, frame) -> None:
    """KeyboardInterrupt, unless the main thread is inside llvmlite or numba's compiler: then
    SIGINT again in 50 ms (:func:`_sigint_outside_llvm`). Loading a cached kernel takes
    milliseconds, so the Ctrl-C soon lands outside and the command stops the usual way (keeping
    what it has finished); compiling kernels on a new machine keeps numba on the stack for about
    a minute, so a Ctrl-C held back for more than :data:`SIGINT_HOLD_S` ends the process at once
    (one line, status 130), with nothing finished to keep. That exit (``os._exit``) runs no
    atexit handlers: the temporary matplotlib folder (:func:`_matplotlib_folder`) is removed
    first; every file a command writes is written atomically, so none is left half written."""
    import signal
    import threading
    import time

    f = frame
    while f is not None:
        if f.f_globals.get("__name__", "").startswith(("llvmlite", "numba.core")):
            now = time.monotonic()
            if _HELD["since"] is None:
                _HELD["since"] = now
            elif now - _HELD["since"] > SIGINT_HOLD_S:
                sys.stdout.flush()
                print(f"{_HELD['command']}: interrupted", file=sys.stderr, flush=True)
                _remove_temporary_folders()  # os._exit runs no atexit handler
                os._exit(EXIT_INTERRUPTED)
            t = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
            t.daemon = True
            t.start()
            return
        f = f.f_back
    _HELD["since"] = None
    raise KeyboardInterrupt


def _run(argv: Sequence[str] | None) -> int:
    """:func:`main` once a Ctrl-C during its first imports is taken care of."""
    import warnings

    from raytrace.errors import OrthoscopeError

    debug = os.environ.get("ORTHOSCOPE_DEBUG", "") not in ("", "0")
    command = "orthoscope"
    warnings.showwarning = _one_line_warning
    _PRINTED.clear()
    _PER_CATEGORY.clear()
    _ascii_safe_streams()
    # the command line only writes figures to files (no window): a broken MPLBACKEND must not
    # stop it
    os.environ.pop("MPLBACKEND", None)
    bad = _bad_environment()
    if bad:
        print(f"orthoscope: error: {bad}", file=sys.stderr)
        return EXIT_USAGE
    try:
        words = signed_values(sys.argv[1:] if argv is None else list(argv))
        parser = build_parser(command_of(words))
        try:
            args, extra = parser.parse_known_args(words)
            if extra:  # said by the subcommand's parser: its name, its --help
                sub = _subparser(parser, getattr(args, "command", None)) or parser
                sub.error(f"unrecognized arguments: {' '.join(extra)}")
        except SystemExit as e:  # --help, --version, or a usage error already printed
            return e.code if isinstance(e.code, int) else EXIT_USAGE
        command = f"orthoscope {args.command}"
        _HELD["command"] = command
        from .common import refuse_both_spellings

        refuse_both_spellings(args)  # a deprecated spelling with its flag, before any work
        if args.threads is not None:
            _set_threads(args.threads)
        if args.command not in NO_KERNELS:
            _numba_without_blas_probe()
            _compile_notice()
        _before_matplotlib()
        with warnings.catch_warnings():
            if getattr(args, "strict", False):  # a glass evaluated outside its range fails
                from raytrace.materials import OutOfRangeWarning

                warnings.filterwarnings("error", category=OutOfRangeWarning)
            status = int(args.func(args) or 0)
        if status < EXIT_USAGE:  # the flags were accepted (not refused, not interrupted)
            from .common import warn_deprecated

            warn_deprecated(args)  # the deprecated spellings given, after the command's checks
        return status
    except KeyboardInterrupt:
        print(f"{command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except OrthoscopeError as e:
        if debug:
            raise
        print(f"{command}: error: {cli_words(str(e))}", file=sys.stderr)
        return EXIT_USAGE
    except UserWarning as e:  # a warning that --strict turned into an error
        print(
            f"{command}: error: {e}; --strict fails: use wavelengths inside the data range (or "
            "leave out --strict)",
            file=sys.stderr,
        )
        return EXIT_USAGE
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except OSError as e:  # the output itself cannot be written (full disk, /dev/full, EIO)
        if debug:
            raise
        _silence_stdout()
        print(f"{command}: error: cannot write the output: {e.strerror or e}", file=sys.stderr)
        return 1
    except Exception as e:  # never a traceback for a person
        if debug:
            raise
        print(
            f"{command}: internal error: {type(e).__name__}: {e} "
            f"(set ORTHOSCOPE_DEBUG=1 for a traceback and please report it)",
            file=sys.stderr,
        )
        return 1


_ASCII = {
    "α": "alpha", "β": "beta", "γ": "gamma", "θ": "theta", "ρ": "rho", "ε": "eps", "δ": "d",
    "Δ": "D",
    "µ": "u", "μ": "u", "—": "-", "–": "-", "−": "-", "′": "'", "±": "+/-", "×": "x", "≤": "<=",
    "≥": ">=", "∞": "inf", "°": " deg", "√": "sqrt", "→": "->",
    "Σ": "sum", "≈": "~", "…": "...", "’": "'", "“": '"', "”": '"', "ü": "u", "é": "e",
    "λ": "lambda", "σ": "sigma", "φ": "phi", "ψ": "psi", "π": "pi", "∂": "d", "·": "*",
    "≠": "!=", "⇒": "=>", "⇔": "<=>",
}  # fmt: skip
#: a run of superscripts is one exponent ("mm⁻¹" -> "mm^-1"), of subscripts one index ("Kᵢ" ->
#: "K_i", "Σᵢ₌₁³" -> "sum_i=1^3")
_SCRIPTS = {
    "^": dict(zip("⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺", "0123456789-+", strict=True)),
    "_": dict(zip("₀₁₂₃₄₅₆₇₈₉₋₊₌ᵢⱼₖ", "0123456789-+=ijk", strict=True)),
}


def _ascii_fallback(err: UnicodeError):
    """Codec error handler: Greek letters, dashes and units in ASCII words (non-UTF-8 locales)."""
    bad = err.object[err.start : err.end]
    out, i = [], 0
    while i < len(bad):
        for mark, table in _SCRIPTS.items():
            j = i
            while j < len(bad) and bad[j] in table:
                j += 1
            if j > i:
                out.append(mark + "".join(table[c] for c in bad[i:j]))
                i = j
                if i < len(bad) and _ASCII.get(bad[i], "?")[:1].isalpha():
                    out.append(" ")  # "K_i lambda^2", not "K_ilambda^2"
                break
        else:
            out.append(_ASCII.get(bad[i], "?"))
            i += 1
    return "".join(out), err.end


def _ascii_safe_streams() -> None:
    """Under a locale that cannot encode the tables' symbols (``LANG=C``), write them in ASCII
    instead of failing."""
    import codecs

    codecs.register_error("orthoscope-ascii", _ascii_fallback)
    for stream in (sys.stdout, sys.stderr):
        enc = getattr(stream, "encoding", None) or "ascii"
        try:
            "α—µ".encode(enc)
        except (UnicodeEncodeError, LookupError):
            try:
                stream.reconfigure(errors="orthoscope-ascii")
            except (AttributeError, ValueError):  # not a TextIOWrapper (a test's capture)
                pass


def _bad_environment() -> str | None:
    """A one-line reason when an environment variable the engine reads is unusable."""
    v = os.environ.get("NUMBA_NUM_THREADS")
    if v is not None and not (v.strip().isdigit() and int(v) > 0):
        return (
            f"NUMBA_NUM_THREADS={v!r} must be a positive whole number (the threads numba may "
            "use); unset it or set e.g. NUMBA_NUM_THREADS=2"
        )
    return None


#: the warnings printed in this run (a warning raised again, e.g. for each evaluation of the
#: lens at an extrapolated wavelength, is printed once)
_PRINTED: set[str] = set()
#: distinct texts printed per warning category; past :data:`WARNINGS_PER_CATEGORY` one line says
#: the rest are not shown (an optimization that fits model glasses outside their range makes a
#: new nd/vd, so a new text, at every evaluation)
_PER_CATEGORY: dict[str, int] = {}
WARNINGS_PER_CATEGORY = 10


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings on the command line: one line, no source path, each text once per run, at most
    :data:`WARNINGS_PER_CATEGORY` texts of one category."""
    text = str(message)
    if text in _PRINTED:
        return
    _PRINTED.add(text)
    kind = getattr(category, "__name__", str(category))
    seen = _PER_CATEGORY[kind] = _PER_CATEGORY.get(kind, 0) + 1
    if seen > WARNINGS_PER_CATEGORY + 1:
        return
    if seen == WARNINGS_PER_CATEGORY + 1:
        text = f"more warnings like these ({kind}) are not shown"
    print(f"orthoscope: warning: {text}", file=sys.stderr)


def _silence_stdout() -> None:
    """After a closed pipe, point stdout at devnull so the interpreter's final flush is quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


class _NoBlasProbe:
    """Import hook (``sys.meta_path``) that runs ``numba.np.arraymath``'s module code with
    ``scipy.linalg.cython_blas`` absent, whenever numba imports it (before a compilation, or
    for a cached kernel that refers to it)."""

    def find_spec(self, name, path=None, target=None):
        if name != "numba.np.arraymath":
            return None
        from importlib.machinery import PathFinder

        spec = PathFinder.find_spec(name, path)
        loader = getattr(spec, "loader", None)
        if loader is None or not hasattr(loader, "exec_module"):
            return None  # not a plain source module: the usual import
        run = loader.exec_module

        def exec_module(module) -> None:
            key = "scipy.linalg.cython_blas"
            had = key in sys.modules
            if not had:
                sys.modules[key] = None  # type: ignore[assignment]
            try:
                run(module)
            finally:
                if not had:
                    sys.modules.pop(key, None)

        loader.exec_module = exec_module
        return spec


def _numba_without_blas_probe() -> None:
    """Let numba import its numpy support without its BLAS probe.

    numba checks at import of ``numba.np.arraymath`` whether SciPy's BLAS is available (for
    ``np.dot`` in jitted code) by importing ``scipy.linalg.cython_blas`` — a quarter of a second.
    The kernels of this project use no BLAS, and the command line compiles no other code, so the
    probe is answered "absent" for numba alone; SciPy itself imports normally afterwards. The
    module is imported only when numba needs it (a compilation, or a cached kernel whose
    environment names it): a warm run of most commands never loads it (``raytrace.kernels.jit``).
    """
    if "numba.np.arraymath" in sys.modules or any(
        isinstance(f, _NoBlasProbe) for f in sys.meta_path
    ):
        return
    sys.meta_path.insert(0, _NoBlasProbe())


#: what the CLI says when a kernel compiles (a cache miss), once per run
COMPILE_NOTICE = (
    "orthoscope: compiling ray-tracing kernels (the first time this machine runs a command "
    "that needs them; up to about a minute)"
)


def _compile_notice() -> None:
    """One line on stderr when this run starts to compile one of the project's kernels: numba's
    ``numba:compile`` event fires on a cache miss only (a first run, or the first command that
    needs a kernel no earlier command used: ``report`` after ``distortion`` compiles for 30 s),
    never when machine code loads from the cache. Quiet when no cache folder can be written
    (the :class:`~raytrace.kernels.jit.KernelCacheWarning` line has said that every run
    compiles)."""
    from numba.core import event

    if _NOTICE:  # main() run again in one process: the listener is registered, say it anew
        _NOTICE[0].quiet = False  # main() sets it back when the run ends
        return

    from raytrace.kernels.jit import uncached

    class Notice(event.Listener):
        quiet = False  # True once said, and outside a run of main()

        def on_start(self, ev) -> None:
            func = getattr(ev.data.get("dispatcher"), "py_func", None)
            if self.quiet or not getattr(func, "__module__", "").startswith("raytrace."):
                return
            self.quiet = True
            if not uncached():
                print(COMPILE_NOTICE, file=sys.stderr, flush=True)

        def on_end(self, ev) -> None:
            return None

    _NOTICE.append(Notice())
    event.register("numba:compile", _NOTICE[0])


_NOTICE: list = []


def _before_matplotlib() -> None:
    """Run :func:`_matplotlib_folder` when this run first imports matplotlib (a plot), through a
    finder at the head of ``sys.meta_path`` that takes itself out at once."""
    if "matplotlib" in sys.modules or any(isinstance(f, _BeforeMatplotlib) for f in sys.meta_path):
        return
    sys.meta_path.insert(0, _BeforeMatplotlib())


class _BeforeMatplotlib:
    def find_spec(self, name, path=None, target=None):
        if name == "matplotlib":
            sys.meta_path.remove(self)
            _matplotlib_folder()
        return None  # the usual finders import it


def _matplotlib_folder() -> None:
    """A plot with a read-only home made matplotlib print two lines of its own ("mkdir -p failed
    for path ...", "Matplotlib created a temporary cache directory ..."): where its config or
    cache folder cannot be made writable (its own test: mkdir, then ``os.access(W_OK)``), give
    it a temporary folder, removed at exit, as it would make itself, without the lines."""
    if "MPLCONFIGDIR" in os.environ:
        return
    from pathlib import Path

    try:
        home = Path.home()
    except RuntimeError:  # no HOME and no password entry
        home = Path("/nonexistent")
    for folder in (
        Path(os.environ.get("XDG_CONFIG_HOME") or home / ".config") / "matplotlib",
        Path(os.environ.get("XDG_CACHE_HOME") or home / ".cache") / "matplotlib",
    ):
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            break
        if not (folder.is_dir() and os.access(folder, os.W_OK)):
            break
    else:
        return
    import atexit
    import shutil
    import tempfile

    tmp = tempfile.mkdtemp(prefix="orthoscope-matplotlib-")
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    _TEMPORARY_FOLDERS.append(tmp)
    os.environ["MPLCONFIGDIR"] = tmp


#: temporary folders this process made (:func:`_matplotlib_folder`), removed at exit by atexit,
#: or by :func:`_remove_temporary_folders` before an exit that skips atexit
_TEMPORARY_FOLDERS: list[str] = []


def _remove_temporary_folders() -> None:
    """Remove :data:`_TEMPORARY_FOLDERS`, best effort, never raising: before ``os._exit``
    (:func:`_sigint_handler`), which runs no atexit handler."""
    try:
        import shutil

        for tmp in _TEMPORARY_FOLDERS:
            shutil.rmtree(tmp, ignore_errors=True)
    except BaseException:  # a second Ctrl-C, anything: the exit goes on
        pass


def _set_threads(n: int) -> None:
    """--threads N: numba threads for this run (1 .. NUMBA_NUM_THREADS)."""
    import numba

    from .common import CliError

    top = numba.config.NUMBA_NUM_THREADS
    if not 1 <= n <= top:
        raise CliError(f"--threads must be between 1 and {top} (NUMBA_NUM_THREADS), got {n}")
    numba.set_num_threads(n)


def console() -> None:
    """Entry point of the ``orthoscope`` console script."""
    sys.exit(main())
