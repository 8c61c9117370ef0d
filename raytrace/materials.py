"""Optical materials: air, a fixed index, an nd/vd model glass, or a catalog material.

Wavelengths are in nanometres. ``index(λ)`` accepts a scalar (returns a float) or a numpy array
(returns an array of its shape).

Catalog materials (``kind="catalog"``) carry their vendor's dispersion formula and coefficients
(:mod:`raytrace.glass.formulas`), valid wavelength range, index basis and reference conditions.
``index(λ)`` is the index **relative to air at the material's reference conditions** (the vendor
catalogs: 20 °C, 1 atm) — the basis lens programs trace in. Data given as absolute (vacuum)
indices are divided by the air index (:func:`raytrace.glass.air.air_index`) at the material's
reference temperature and pressure. Other temperatures and pressures:
:func:`raytrace.glass.thermal.index_at`. A wavelength outside the valid range gives an
:class:`OutOfRangeWarning` (``strict=True``, or ``warnings.simplefilter("error",
OutOfRangeWarning)``, turns it into an error).

Model glasses (``kind="model"``) are fictitious glasses given by ``nd`` (helium d line,
587.5618 nm) and Abbe number ``vd = (nd − 1)/(nF − nC)`` (hydrogen F 486.1327 nm, C 656.2725 nm).
``model`` names the dispersion law:

``"cauchy2"`` (default, orthoscope's own)
    ``n(λ) = A + B/λ²`` with ``n(λd) = nd`` and ``n(λF) − n(λC) = (nd − 1)/vd`` exactly.
``"buchdahl-rayoptics"``
    the quadratic Buchdahl model ray-optics/opticalglass use for a glass given by nd/vd
    (``opticalglass.buchdahl.Buchdahl2``, opticalglass 1.1.1): ``n = nd + ν1 ω + ν2 ω²``,
    ``ω = Δλ/(1 + 2.5 Δλ)``, ``Δλ = λ − λd`` (µm), ``ν1 = b + m ν2`` on the line
    ``b = −0.064667, m = −1.604048`` fitted to catalog glasses, and
    ``ν2 = ((nd − 1)/vd − b δω)/(m δω − δω²)`` with ``δω = ωF − ωC``, ``δω² = ωF² − ωC²`` —
    reproduced as opticalglass publishes it, which does not make ``nF − nC`` exactly
    ``(nd − 1)/vd`` (the Abbe number comes out ~2 % high: 61.7 for 1.62/60.3).
``"buchdahl-optiland"``
    optiland's ``AbbeMaterial(model="buchdahl")`` (``BuchdahlDModel``, optiland 0.6.3), the
    model optiland uses for a Zemax model glass: ``n = nd + ν1 ω + ν2 ω² + ν3 ω³`` with the same
    ω and ν1..ν3 regressions in 1/vd, 1/vd², nd, nd², nd/vd (coefficients below).

A model glass is validated against real glasses over :data:`MODEL_RANGE_NM` (365–1014 nm, the i
to t lines); evaluated outside it, it gives an
:class:`OutOfRangeWarning` (``strict=True``: :class:`OutOfRangeError`) as a catalog glass does
outside its data: the index is an extrapolation of the model (see :data:`MODEL_RANGE_NM` for how
far off it is there).

Zemax's MODEL glass and CODE V's fictitious glass use their vendors' own dispersion laws; no
published definition of either was available to this project, so neither is implemented (the
two Buchdahl models are what two open tools do, named as such).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np

from .errors import TraceError
from .units import real_number

LAMBDA_D = 587.5618
LAMBDA_F = 486.1327
LAMBDA_C = 656.2725

MODELS = ("cauchy2", "buchdahl-rayoptics", "buchdahl-optiland")
KINDS = ("air", "index", "model", "catalog")
BASES = ("relative", "absolute")

#: Wavelengths (nm) over which an nd/vd model glass is validated against real glasses: Schott's
#: i to t lines (365.01–1013.98 nm), the span the catalogs tabulate. Outside it
#: :meth:`Material.index` warns that the index is an extrapolation of the model. Measured on
#: the shipped catalogs (tests/test_input_guards.py checks it): each current Schott and Ohara
#: glass (276 with nd/vd) against the ``cauchy2`` model of its own catalog nd/vd, at the
#: wavelengths its data cover. Inside the span the typical error is what it is in the blue end
#: of the visible: median |Δn| over the glasses ≤ 1.13e-3 and 95th percentile ≤ 7.3e-3, against
#: worst values of 1.07e-3 and 7.29e-3 over 400–700 nm (both at 405 nm). Beyond it the error
#: grows: median 1.8e-3 at 1200 nm, 4.1e-3 at 1500 nm, 1.4e-2 at 2300 nm; 2.5e-3 at 300 nm.
MODEL_RANGE_NM: tuple[float, float] = (365.01, 1013.98)


#: The d-line indices (nd) a fixed index or a model glass may have: 1 (vacuum, air) to 4.1.
#: Germanium, ~4.0 in the infrared (and opaque in the visible), has the highest index of any
#: optical material; in the visible and near IR the highest-index catalog glasses stay near 2.2
#: (Sumita K-PSFn215 2.154; ZnSe ~2.6, silicon ~3.5 in the IR). 1 exactly is legal for a fixed
#: index (air, dummy surfaces) and for a model glass (no dispersion: (nd − 1)/vd = 0; the native
#: reader has always taken nd >= 1, and tests/test_prescription.py draws model glasses from
#: nd = 1). A value outside is a slip (an Abbe number given for nd, 0.5 for 1.5), refused where
#: it is built.
INDEX_RANGE = (1.0, 4.1)
#: The Abbe numbers (vd) a model glass may have: above 0, at most 120. The largest of real
#: optical materials lie near 100 (the shipped catalogs, :mod:`raytrace.glass.catalog`: MgF2
#: 106.2 in Misc, Sumita K-FIR100UV 101.0; CaF2 ~95); 120 leaves margin.
ABBE_RANGE = (0.0, 120.0)


class OutOfRangeWarning(UserWarning):
    """A catalog material was evaluated outside the wavelength range its data are valid for, or
    a model glass outside :data:`MODEL_RANGE_NM`."""


class OutOfRangeError(TraceError):
    """A catalog material or model glass was evaluated outside its valid range with strict
    checking on (or where its formula gives no index)."""


@dataclass(frozen=True)
class Material:
    """A homogeneous isotropic medium (frozen and hashable).

    kind:
        ``"air"`` (index 1), ``"index"`` (a fixed index ``nd``), ``"model"`` (nd/vd model glass,
        dispersion law ``model``) or ``"catalog"`` (a vendor formula; see the module docstring).
    nd, vd:
        d-line index and Abbe number (for a catalog material: the catalog's values, for
        information and searching).
    model:
        model-glass dispersion law, one of :data:`MODELS` (``kind="model"`` only).
    name, catalog:
        the material's name as its vendor spells it and the catalog (``kind="catalog"``).
    formula, coefficients:
        dispersion formula id (:data:`raytrace.glass.formulas.FORMULAS`) and its coefficients.
    wavelength_range_nm:
        (min, max) wavelength in nm where the data are valid (catalog materials; a model glass
        is valid over :data:`MODEL_RANGE_NM`: :attr:`valid_range_nm`).
    basis, temperature_c, pressure_atm:
        ``"relative"`` (to air at ``temperature_c`` °C and ``pressure_atm`` atm) or
        ``"absolute"`` (vacuum) index data, and the reference conditions of the data.
    dndt:
        Schott dn/dT constants (D0, D1, D2, E0, E1, λ_TK[µm]) or ``()``.
    """

    kind: str
    nd: float = 1.0
    vd: float = math.inf
    model: str = ""
    name: str = ""
    catalog: str = ""
    formula: int | str = 0
    coefficients: tuple[float, ...] = ()
    wavelength_range_nm: tuple[float, float] = (0.0, math.inf)
    basis: str = "relative"
    temperature_c: float = 20.0
    pressure_atm: float = 1.0
    dndt: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown material kind {self.kind!r}")
        if self.kind != "catalog":
            nd = real_number(self.nd, "nd", "a refractive index such as 1.5168", error=ValueError)
            object.__setattr__(self, "nd", nd)
            if not (math.isfinite(nd) and nd > 0.0):
                raise ValueError(f"refractive index must be a positive finite number, got {nd}")
        if self.kind in ("index", "model"):
            self._check_range()
        if self.kind == "model":
            if self.model == "":
                object.__setattr__(self, "model", "cauchy2")
            if self.model not in MODELS:
                raise ValueError(
                    f"unknown model-glass law {self.model!r} (use {', '.join(MODELS)})"
                )
        if self.kind == "catalog":
            if self.basis not in BASES:
                raise ValueError(
                    f"index basis must be 'relative' or 'absolute', got {self.basis!r}"
                )
            if not self.coefficients:
                raise ValueError(f"catalog material {self.name!r} has no dispersion coefficients")

    def _check_range(self) -> None:
        """Refuse an nd outside :data:`INDEX_RANGE` and, for a model glass, a vd outside
        :data:`ABBE_RANGE`: ValueError naming the value and the fix."""
        (lo, hi), (vlo, vhi) = INDEX_RANGE, ABBE_RANGE
        nd, model = self.nd, self.kind == "model"
        what = "model glass" if model else "fixed index"
        if model:
            vd = real_number(self.vd, "vd", "an Abbe number such as 64.17", error=ValueError)
            object.__setattr__(self, "vd", vd)
            if not (math.isfinite(vd) and vd > 0.0):
                raise ValueError(f"Abbe number must be a positive finite number, got {vd}")
        swapped = model and lo < self.vd <= hi and vlo < nd <= vhi
        hint = f"; nd and vd swapped? give nd {self.vd:g}, vd {nd:g}" if swapped else ""
        if not lo <= nd <= hi:
            side = f"below {lo:g}" if nd < lo else f"above {hi:g}"
            raise ValueError(
                f"{what} nd={nd:g} is {side}: a refractive index (d line) is {lo:g} (air) to "
                f"{hi:g} (germanium, ~4.0 in the infrared, has the highest); give e.g. 1.5168"
                f"{hint}"
            )
        if model and not vlo < self.vd <= vhi:
            raise ValueError(
                f"{what} vd={self.vd:g} is above {vhi:g}: an Abbe number is above {vlo:g} and at "
                f"most {vhi:g} (MgF2, 106, is among the highest); give e.g. 64.17{hint}"
            )

    @property
    def is_air(self) -> bool:
        return self.kind == "air"

    @property
    def valid_range_nm(self) -> tuple[float, float]:
        """(min, max) wavelength in nm where the index is data, not an extrapolation: a catalog
        material's data range, :data:`MODEL_RANGE_NM` for a model glass, (0, inf) for air and a
        fixed index."""
        if self.kind == "model":
            return MODEL_RANGE_NM
        return self.wavelength_range_nm

    def in_range(self, wavelength_nm) -> bool:
        """True when every wavelength (nm) lies in the material's valid range
        (:attr:`valid_range_nm`)."""
        lo, hi = self.valid_range_nm
        w = np.asarray(wavelength_nm, dtype=float)
        return bool(np.all((w >= lo) & (w <= hi)))

    def check_range(self, wavelength_nm, *, strict: bool = False) -> None:
        """Warn (:class:`OutOfRangeWarning`) or, with ``strict``, raise
        :class:`OutOfRangeError` when a wavelength lies outside the valid range (catalog
        materials and model glasses)."""
        if self.kind not in ("catalog", "model") or self.in_range(wavelength_nm):
            return
        lo, hi = self.valid_range_nm
        w = np.atleast_1d(np.asarray(wavelength_nm, dtype=float))
        what = (
            f"model glass {self.describe()}"
            if self.kind == "model"
            else f"glass {self.name} ({self.catalog})"
        )
        nonsense = w[~(np.isfinite(w) & (w > 0.0))]
        if nonsense.size:  # no wavelength at all (it failed with an IndexError or ValueError)
            raise OutOfRangeError(
                f"{what} evaluated at {nonsense[0]:g} nm: a wavelength is a positive finite "
                "number of nm"
            )
        bad = w[(w < lo) | (w > hi)]
        u = np.unique(bad)  # every wavelength outside, ascending (the first six)
        at = ", ".join(f"{b:g}" for b in u[:6]) + (f" (+{u.size - 6} more)" if u.size > 6 else "")
        if self.kind == "model":
            msg = (
                f"{what} evaluated at {at} nm, outside the range {lo:g}–{hi:g} nm its nd/vd "
                "model is validated over (Schott's i to t lines): the index is an extrapolation "
                f"of the model; use a catalog glass with data there (search_glass({self.nd:g}, "
                f"{self.vd:g}) lists the nearest)"
            )
            fitted = "defined from nd/vd"
        else:
            msg = (
                f"{what} evaluated at {at} nm, outside its data range {lo:g}–{hi:g} nm: "
                "the index is extrapolated"
            )
            fitted = f"fitted over {lo:g}–{hi:g} nm"
        for b in bad:  # beyond a pole of the formula the numbers are no index at all
            edge = lo if b < lo else hi
            if not _formula_holds(self, float(b)):
                raise OutOfRangeError(
                    f"{what} has no index at {b:g} nm: its dispersion formula, {fitted}, breaks "
                    f"down (a pole or n < 1) between {edge:g} and {b:g} nm; use a material with "
                    "data there"
                )
        if strict:
            raise OutOfRangeError(msg + "; use wavelengths inside the range or another material")
        warnings.warn(msg, OutOfRangeWarning, stacklevel=3)

    def index(self, wavelength_nm=LAMBDA_D, *, strict: bool = False):
        """Refractive index at ``wavelength_nm`` (nm; scalar or array).

        For a catalog material: relative to air at the material's reference conditions (see the
        module docstring). Outside the valid range (:attr:`valid_range_nm`: a catalog
        material's data range, :data:`MODEL_RANGE_NM` for a model glass) a warning, or with
        ``strict`` an :class:`OutOfRangeError`.
        """
        scalar = np.ndim(wavelength_nm) == 0
        if self.kind == "air" or self.kind == "index":
            v = 1.0 if self.kind == "air" else self.nd
            return v if scalar else np.full(np.shape(wavelength_nm), v)
        self.check_range(wavelength_nm, strict=strict)
        n = _raw_index(self, np.asarray(wavelength_nm, dtype=float))
        return float(n) if scalar else n

    def describe(self) -> str:
        """Short text for listings: ``air``, ``n=1.5``, ``1.6201/60.4``, ``N-BK7 (Schott)``."""
        if self.kind == "air":
            return "air"
        if self.kind == "index":
            return f"n={self.nd:g}"
        if self.kind == "catalog":
            return f"{self.name} ({self.catalog})"
        law = "" if self.model == "cauchy2" else f" [{self.model}]"
        return f"{self.nd:g}/{self.vd:g}{law}"


@functools.lru_cache(maxsize=1024)
def _formula_holds(m: Material, wavelength_nm: float) -> bool:
    """Whether the dispersion formula of ``m`` stays an index (finite, ≥ 1) all the way from
    the nearest end of its valid range to ``wavelength_nm`` (no pole crossed): 257 points."""
    lo, hi = m.valid_range_nm
    path = np.geomspace(lo if wavelength_nm < lo else hi, wavelength_nm, 257)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        n = _raw_index(m, path)
    return bool(np.all(np.isfinite(n)) and np.all(n >= 1.0))


def _raw_index(m: Material, wavelength_nm: np.ndarray) -> np.ndarray:
    """The index of a model or catalog material by its law or formula, no range check."""
    if m.kind == "model":
        return _MODEL_LAWS[m.model](m.nd, m.vd, wavelength_nm)
    return _catalog_index(m, wavelength_nm)


def _catalog_index(m: Material, wavelength_nm: np.ndarray) -> np.ndarray:
    # deferred import: raytrace.glass imports this module
    from .glass.air import air_index
    from .glass.formulas import evaluate

    lam_um = wavelength_nm / 1000.0
    n = evaluate(m.formula, m.coefficients, lam_um)
    if m.basis == "absolute":
        n = n / air_index(lam_um, m.temperature_c, m.pressure_atm)
    return n


# --------------------------------------------------------------------------- model-glass laws


def _cauchy2(nd: float, vd: float, lam_nm: np.ndarray) -> np.ndarray:
    dn = (nd - 1.0) / vd  # nF - nC
    b = dn / (LAMBDA_F**-2 - LAMBDA_C**-2)
    return nd + b * (lam_nm**-2 - LAMBDA_D**-2)


def _omega(lam_nm, alpha: float = 2.5):
    d = (np.asarray(lam_nm, dtype=float) - LAMBDA_D) / 1000.0
    return d / (1.0 + alpha * d)


def _buchdahl_rayoptics(nd: float, vd: float, lam_nm: np.ndarray) -> np.ndarray:
    # opticalglass 1.1.1, buchdahl.Buchdahl2: the (ν1, ν2) line b, m
    b, m = -0.064667, -1.604048
    om_f, om_c = _omega(LAMBDA_F), _omega(LAMBDA_C)
    d_om, d_om2 = om_f - om_c, om_f**2 - om_c**2
    v2 = ((nd - 1.0) / vd - b * d_om) / (m * d_om - d_om2)
    v1 = b + m * v2
    om = _omega(lam_nm)
    return nd + v1 * om + v2 * om**2


def _buchdahl_optiland(nd: float, vd: float, lam_nm: np.ndarray) -> np.ndarray:
    # optiland 0.6.3, materials/abbe.py, BuchdahlDModel (reference 0.5875618 µm, alpha 2.5)
    iv, iv2, n2, nv = 1.0 / vd, 1.0 / vd**2, nd * nd, nd / vd
    v1 = 0.004160 + 4.462559 * iv + 2.326660 * iv2 + 0.002330 * nd - 0.003697 * n2 - 4.697604 * nv
    v2 = 0.066434 - 7.636396 * iv + 12.597434 * iv2 - 0.037014 * n2 + 5.551013 * nv
    v3 = -0.032218 + 2.230357 * iv - 103.318994 * iv2 - 0.009654 * n2 + 1.934983 * nv
    om = _omega(lam_nm)
    return nd + v1 * om + v2 * om**2 + v3 * om**3


_MODEL_LAWS = {
    "cauchy2": _cauchy2,
    "buchdahl-rayoptics": _buchdahl_rayoptics,
    "buchdahl-optiland": _buchdahl_optiland,
}

AIR = Material("air")


def model_glass(nd: float, vd: float, model: str = "cauchy2") -> Material:
    """An nd/vd model glass with dispersion law ``model`` (see :data:`MODELS`).

    Parameters
    ----------
    nd : float
        Refractive index at the d line (587.56 nm): 1 to 4.1 (:data:`INDEX_RANGE`).
    vd : float
        Abbe number (nd − 1)/(nF − nC): above 0, at most 120 (:data:`ABBE_RANGE`).
    model : str
        The dispersion law, one of :data:`MODELS`: ``"cauchy2"`` (default; ``""`` means it),
        ``"buchdahl-rayoptics"``, ``"buchdahl-optiland"``.

    Returns
    -------
    Material
        ``kind="model"``.

    Raises
    ------
    ValueError
        nd or vd not a number or outside its range, an unknown ``model``.
    """
    return Material("model", nd, vd, model=model)


def fixed_index(n: float) -> Material:
    """A non-dispersive medium of index ``n``.

    Parameters
    ----------
    n : float
        The refractive index at every wavelength: 1 (air) to 4.1 (:data:`INDEX_RANGE`).

    Returns
    -------
    Material
        ``kind="index"``.

    Raises
    ------
    ValueError
        An index that is not a number or outside :data:`INDEX_RANGE`.
    """
    return Material("index", n)
