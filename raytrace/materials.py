"""Optical materials: air, a fixed index, or an nd/vd model glass.

Wavelengths are in nanometres. The model glass follows the usual two-parameter convention:
``nd`` at the helium d line (587.5618 nm) and Abbe number ``vd = (nd - 1) / (nF - nC)`` with the
hydrogen F (486.1327 nm) and C (656.2725 nm) lines. Its dispersion is a two-term Cauchy law
``n(λ) = A + B / λ²`` fitted so that ``n(λd) = nd`` and ``n(λF) - n(λC) = (nd - 1) / vd`` exactly.
At the d line the index is exactly ``nd``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

LAMBDA_D = 587.5618
LAMBDA_F = 486.1327
LAMBDA_C = 656.2725


@dataclass(frozen=True)
class Material:
    """A homogeneous isotropic medium.

    ``kind`` is ``"air"`` (index 1 at every wavelength), ``"index"`` (a fixed, non-dispersive
    index ``nd``) or ``"model"`` (an nd/vd model glass, see the module docstring).
    """

    kind: str
    nd: float = 1.0
    vd: float = math.inf

    def __post_init__(self) -> None:
        if self.kind not in ("air", "index", "model"):
            raise ValueError(f"unknown material kind {self.kind!r}")
        if not (math.isfinite(self.nd) and self.nd > 0.0):
            raise ValueError(f"refractive index must be a positive finite number, got {self.nd}")
        if self.kind == "model" and not (math.isfinite(self.vd) and self.vd > 0.0):
            raise ValueError(f"Abbe number must be a positive finite number, got {self.vd}")

    @property
    def is_air(self) -> bool:
        return self.kind == "air"

    def index(self, wavelength_nm: float = LAMBDA_D) -> float:
        """Refractive index at ``wavelength_nm`` (nm)."""
        if self.kind == "air":
            return 1.0
        if self.kind == "index":
            return self.nd
        dn = (self.nd - 1.0) / self.vd  # nF - nC
        b = dn / (LAMBDA_F**-2 - LAMBDA_C**-2)
        return self.nd + b * (wavelength_nm**-2 - LAMBDA_D**-2)

    def describe(self) -> str:
        """Short text for listings: ``air``, ``n=1.5``, ``1.6201/60.4``."""
        if self.kind == "air":
            return "air"
        if self.kind == "index":
            return f"n={self.nd:g}"
        return f"{self.nd:g}/{self.vd:g}"


AIR = Material("air")


def model_glass(nd: float, vd: float) -> Material:
    """An nd/vd model glass."""
    return Material("model", float(nd), float(vd))


def fixed_index(n: float) -> Material:
    """A non-dispersive medium of index ``n``."""
    return Material("index", float(n))
