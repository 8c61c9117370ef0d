"""Fixtures shared by several test modules: the bundled lenses many of them trace.

A :class:`raytrace.Lens` is a frozen dataclass, and so are its surfaces, aperture, field and
materials (only its cached hash is set after construction; no test changes a fixture lens):
one instance serves the whole session. The library is imported inside the fixtures, so
collecting the tests imports nothing more than before."""

from __future__ import annotations

import pytest


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
