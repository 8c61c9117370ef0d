"""Fixtures shared by several test modules: the bundled lenses many of them trace.

A :class:`raytrace.Lens` is a frozen dataclass, and so are its surfaces, aperture, field and
materials (only its cached hash is set after construction; no test changes a fixture lens):
one instance serves the whole session. The library is imported inside the fixtures, so
collecting the tests imports nothing more than before."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

#: The numba kernels the suite uses, compiled (and cached) by the xdist controller before its
#: workers start: on a fresh clone each worker, and each command-line test's subprocess that
#: starts before a kernel is cached, compiled the same kernels again (the suite took 9m24s and
#: 10m14s on a clean clone, 7m01s with a warm cache, 2026-11-28). Two processes, one per set,
#: about 60 and 45 s cold on that machine; 2-3 s when the cache is warm.
_WARM = (
    "import numpy as np, orthoscope as osc; L = osc.load_lens('cooke-triplet-f4'); "
    "osc.characteristic_distortion(L, [0.0, 10.0, 20.0]); osc.ray_fan(L, 10.0)",
    "import orthoscope as osc; osc.distortion_grid(osc.load_lens('cooke-triplet-f4'), grid=5)",
)


def pytest_sessionstart(session):
    """Warm the numba cache once for a parallel run (``-n 2``, the README's test command).

    Only the xdist controller does it, and only with two or more workers; a failure is ignored
    (the tests then compile as before, and report any real problem themselves)."""
    config = session.config
    if hasattr(config, "workerinput") or not (getattr(config.option, "numprocesses", 0) or 0) > 1:
        return
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", code],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )  # fmt: skip
        for code in _WARM
    ]
    for p in procs:
        try:
            p.wait(timeout=600)
        except subprocess.TimeoutExpired:
            p.kill()


def _bundled(name: str):
    from raytrace.files.library import load_lens

    return load_lens(name)


@pytest.fixture(scope="session")
def cooke():
    """The bundled ``cooke-triplet-f4`` (50 mm f/4, half-field 20 deg)."""
    return _bundled("cooke-triplet-f4")


@pytest.fixture(scope="session")
def topogon():
    """The bundled ``topogon-like-pestrecov`` (half-field 45 deg)."""
    return _bundled("topogon-like-pestrecov")
