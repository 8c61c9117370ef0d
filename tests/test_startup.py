"""Start-up of the command line (docs/design.md, "Performance"): a command imports only what it
needs, the parser of one command parses as the full parser does, and a cached kernel loads
without numba's registries and gives the same numbers as the compiled one."""

from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

from orthoscope.cli import COMMANDS, build_parser, command_of, signed_values

ROOT = Path(__file__).resolve().parents[1]


def _subparsers(parser: argparse.ArgumentParser) -> dict:
    return next(a for a in parser._actions if isinstance(a.choices, dict)).choices


def test_command_of_names_the_command_only_when_plain():
    assert command_of(["distortion", "x", "--fields", "0,10"]) == "distortion"
    assert command_of(["--threads", "2", "--allow-large", "trace", "x"]) == "trace"
    assert command_of(signed_values(["--threads", "-1", "paraxial", "x"])) == "paraxial"
    # help first, an abbreviated option, a command another module registers, no command
    for argv in (["-h", "paraxial"], ["--thr", "2", "paraxial"], ["spot", "x"], [], ["bogus"]):
        assert command_of(argv) is None, argv


@pytest.mark.parametrize("name", COMMANDS)
def test_one_command_parser_parses_as_the_full_parser(name):
    full = build_parser()
    one = build_parser(name)
    assert name in _subparsers(one)
    assert _subparsers(one)[name].format_help() == _subparsers(full)[name].format_help()
    assert one.format_usage() == full.format_usage()
    mod = importlib.import_module(f"orthoscope.cli.{name}")
    for argv in getattr(mod, "SAMPLES", []):
        if argv[0] != name:
            continue
        argv = [a.format(data="d", specs="s", tmp="t") for a in argv]
        assert vars(one.parse_args(argv)) == vars(full.parse_args(argv)), argv


PROBE = r"""
import io, json, sys
from contextlib import redirect_stdout
from orthoscope.cli import main
with redirect_stdout(io.StringIO()) as out:
    rc = main(sys.argv[1:])
mods = ("numba", "numba.np.arraymath", "scipy", "scipy.linalg", "matplotlib")
print("PROBE", json.dumps({"rc": rc, "out": out.getvalue(),
                           "imported": [m for m in mods if m in sys.modules]}))
"""


def _probe(*argv: str) -> dict:
    r = subprocess.run(
        [sys.executable, "-c", PROBE, *argv], cwd=ROOT, capture_output=True, text=True
    )
    assert "PROBE" in r.stdout, r.stderr[-2000:]
    return json.loads(r.stdout.split("PROBE", 1)[1])


def test_paraxial_imports_no_numba_scipy_or_matplotlib():
    p = _probe("paraxial", "cooke-triplet-f4")
    assert p["rc"] == 0 and "EFL" in p["out"]
    assert p["imported"] == []


def test_distortion_loads_its_kernel_without_registries_scipy_linalg_or_matplotlib():
    _probe("distortion", "cooke-triplet-f4", "--fields", "0,10,20")  # fills the cache if cold
    p = _probe("distortion", "cooke-triplet-f4", "--fields", "0,10,20")
    assert p["rc"] == 0
    assert "numba" in p["imported"]
    assert not {"numba.np.arraymath", "scipy.linalg", "matplotlib"} & set(p["imported"])


CHILD = r"""
import sys
import numpy as np
import raytrace.kernels.jit as jit
if sys.argv[1] == "numba":  # numba's own cached load (cache=True), same cache files
    jit._KERNEL_CACHE = None
from raytrace.files.library import load_lens
from raytrace.kernels import aim
from raytrace.trace import chief_rays
cr = chief_rays(load_lens("topogon-us2031792-fig1"), np.linspace(0.0, 30.0, 7))
s = aim.aim_chief.stats
print("RESULT", repr(cr.heights_at(cr.z_last[0] + 51.9415).tolist()),
      sum(s.cache_hits.values()), "numba.np.arraymath" in sys.modules)
"""


def _child(how: str) -> tuple[str, int, bool]:
    r = subprocess.run([sys.executable, "-c", CHILD, how], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    heights, hits, registries = r.stdout.split("RESULT", 1)[1].rsplit(maxsplit=2)
    return heights, int(hits), registries == "True"


def test_cached_kernel_loads_light_and_gives_numbas_numbers():
    """The same cached aim_chief loaded numba's way (which imports every registry first) and the
    light way (which does not): the chief-ray heights are the same to the last bit (the same
    machine code)."""
    from raytrace.kernels import jit

    if jit._KERNEL_CACHE is None:
        pytest.skip(f"the light load is not used with this numba version ({jit.numba.__version__})")
    numbas = _child("numba")  # compiles (and fills the cache) if it is cold
    light = _child("light")
    assert numbas[2]  # numba's load refreshed its registries
    assert light[1:] == (1, False)  # loaded from the cache, no registries imported
    assert light[0] == numbas[0]


def test_light_load_refreshes_for_symbols_it_does_not_register(monkeypatch):
    """Object code that names numba's hash secret (registered by importing
    numba.cpython.hashing), or a library not cached as object code, gets numba's full refresh."""
    from numba.core import compiler

    from raytrace.kernels import jit

    if jit._KERNEL_CACHE is None:
        pytest.skip(f"the light load is not used with this numba version ({jit.numba.__version__})")
    monkeypatch.setattr(
        compiler.CompileResult, "_rebuild", classmethod(lambda cls, ctx, *payload: "rebuilt")
    )

    class Context:
        refreshed = 0

        def refresh(self):
            self.refreshed += 1

    impl = jit._KERNEL_CACHE._impl_class.__new__(jit._KERNEL_CACHE._impl_class)
    for library, refresh in (
        (("f", "object", (b"\x00call _numba_hashsecret_siphash_k0\x00", b"")), 1),
        (("f", "object", (b"\x00NRT_MemInfo_call\x00", b"")), 0),
        (("f", "bitcode", b"BC"), 1),
    ):
        ctx = Context()
        assert impl.rebuild(ctx, (library, None)) == "rebuilt"
        assert ctx.refreshed == refresh, library


def test_numba_imports_arraymath_without_the_blas_probe_on_the_command_line():
    """The command line answers numba's BLAS probe "absent" (its kernels use no BLAS) whenever
    numba imports numba.np.arraymath, without importing it itself; SciPy imports normally."""
    code = (
        "import sys\n"
        "from orthoscope.cli import _numba_without_blas_probe\n"
        "_numba_without_blas_probe()\n"
        "assert 'numba.np.arraymath' not in sys.modules\n"
        "import numba.np.arraymath as a\n"
        "print('RESULT', a._HAVE_BLAS, 'scipy.linalg' in sys.modules)\n"
        "import scipy.linalg.cython_blas\n"
    )
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.split("RESULT", 1)[1].split() == ["False", "False"]
