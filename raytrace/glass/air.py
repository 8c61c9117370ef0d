"""Refractive index of air, and relative ↔ absolute refractive index.

Glass catalogs give indices *relative* to air at the catalog's reference conditions (Schott and
the Japanese and Chinese vendors: 20 °C, 1 atm); some crystal and polymer data are *absolute*
(relative to vacuum). ``n_absolute = n_relative · n_air(λ, T, P)``.

The air index is the formula Schott uses in TIE-19 ("Temperature coefficient of the refractive
index", Schott technical information, 2016, section 3) and Zemax/OpticStudio in its thermal
analysis ("the index of air", glass catalog chapter) — Edlén's 1953 dispersion of standard air
(B. Edlén, J. Opt. Soc. Am. 43, 339 (1953), 15 °C, 101 325 Pa), scaled to the temperature T (°C)
and relative pressure P (atm):

    n_ref − 1 = [6432.8 + 2949810 λ²/(146 λ² − 1) + 25540 λ²/(41 λ² − 1)] · 10⁻⁸
    n_air(λ, T, P) = 1 + (n_ref − 1) · P / (1 + 3.4785·10⁻³ (T − 15))

λ in µm. (Edlén writes the two terms as 2949810/(146 − σ²) and 25540/(41 − σ²) with σ = 1/λ;
the λ² forms above are the same.)
"""

from __future__ import annotations

import numpy as np

#: Reference conditions of the vendor catalogs (Schott, Ohara, Hoya, CDGM, Hikari, Sumita).
CATALOG_TEMPERATURE_C = 20.0
CATALOG_PRESSURE_ATM = 1.0


def air_index(wavelength_um, temperature_c: float = 15.0, pressure_atm: float = 1.0):
    """Refractive index of dry air at ``wavelength_um`` (µm), ``temperature_c`` (°C) and
    ``pressure_atm`` (atm, 1 atm = 101 325 Pa); see the module docstring for the formula.

    Scalar in, float out; array in, array out.
    """
    lam2 = np.asarray(wavelength_um, dtype=float) ** 2
    n_ref_1 = (
        6432.8 + 2949810.0 * lam2 / (146.0 * lam2 - 1.0) + 25540.0 * lam2 / (41.0 * lam2 - 1.0)
    ) * 1e-8
    n = 1.0 + n_ref_1 * pressure_atm / (1.0 + 3.4785e-3 * (temperature_c - 15.0))
    return float(n) if np.ndim(n) == 0 else n


def relative_to_absolute(
    n_relative,
    wavelength_um,
    temperature_c: float = CATALOG_TEMPERATURE_C,
    pressure_atm: float = CATALOG_PRESSURE_ATM,
):
    """Absolute (vacuum) index from an index relative to air at (T, P)."""
    return n_relative * air_index(wavelength_um, temperature_c, pressure_atm)


def absolute_to_relative(
    n_absolute,
    wavelength_um,
    temperature_c: float = CATALOG_TEMPERATURE_C,
    pressure_atm: float = CATALOG_PRESSURE_ATM,
):
    """Index relative to air at (T, P) from an absolute (vacuum) index."""
    return n_absolute / air_index(wavelength_um, temperature_c, pressure_atm)
