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
import sys
from collections.abc import Sequence

EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

#: The subcommands, in the order ``orthoscope --help`` lists them (module names in this package).
COMMANDS: tuple[str, ...] = (
    "lenses",
    "paraxial",
    "trace",
    "distortion",
    "calibrate",
    "compensate",
    "variation",
    "coefficients",
    "optimize",
    "convert",
)


def _version() -> str:
    from .. import __version__

    return __version__


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="orthoscope",
        description=(
            "Lens distortion toolkit: paraxial data, real chief rays and Pestrecov's "
            "characteristic and calibrated distortion in Gaussian and non-Gaussian image planes. "
            "LENS is a path to a prescription file (.toml, .zmx, .seq) or the name of a bundled "
            "lens (see 'orthoscope lenses'). Distances in mm; light travels toward +z; signs "
            "follow Pestrecov (1958) Fig. 1."
        ),
        epilog="Run 'orthoscope COMMAND --help' for each command's options.",
    )
    p.add_argument("--version", action="version", version=f"orthoscope {_version()}")
    p.add_argument(
        "--threads",
        type=int,
        metavar="N",
        help="Numba threads for bulk traces (default: numba's setting, NUMBA_NUM_THREADS).",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 a run that did not succeed, 2 a
    usage or input error, 130 interrupted)."""
    from raytrace.errors import OrthoscopeError

    debug = os.environ.get("ORTHOSCOPE_DEBUG", "") not in ("", "0")
    command = "orthoscope"
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        command = f"orthoscope {args.command}"
        if args.threads is not None:
            _set_threads(args.threads)
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print(f"{command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except OrthoscopeError as e:
        if debug:
            raise
        print(f"{command}: error: {e}", file=sys.stderr)
        return EXIT_USAGE
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except Exception as e:  # never a traceback for a person
        if debug:
            raise
        print(
            f"{command}: internal error: {type(e).__name__}: {e} "
            f"(set ORTHOSCOPE_DEBUG=1 for a traceback and please report it)",
            file=sys.stderr,
        )
        return 1


def _silence_stdout() -> None:
    """After a closed pipe, point stdout at devnull so the interpreter's final flush is quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
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
