"""Registration of the subcommands beyond lenses/paraxial/trace.

Each ``distortion/cli_*.py`` module defines ``register(subparsers)``, which adds its parser(s) and
sets ``func`` to a handler ``handler(args) -> int``. Handlers raise project errors
(``OrthoscopeError`` subclasses, e.g. ``distortion.cli.CliError``) for anything a person can get
wrong; ``distortion.cli.main`` prints them as one line and exits with status 2.
"""

from __future__ import annotations

import importlib

MODULES = ("cli_distortion", "cli_variation", "cli_convert", "cli_optimize")


def _registrars():
    out = []
    for name in MODULES:
        try:
            mod = importlib.import_module(f"distortion.{name}")
        except ModuleNotFoundError as e:
            if e.name == f"distortion.{name}":
                continue  # not written yet
            raise
        out.append(mod.register)
    return out


REGISTER = _registrars()
