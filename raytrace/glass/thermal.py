"""Temperature dependence of the refractive index: the Schott dn/dT model (TIE-19).

Schott TIE-19 ("Temperature coefficient of the refractive index", Schott technical
information, 2016, eqs. 2 and 3) gives the change of the *absolute* index from the reference
temperature T0 (20 °C) to T, ΔT = T − T0, λ in µm:

    Δn_abs(λ, T) = (n²(λ, T0) − 1)/(2 n(λ, T0)) ·
                   [D0 ΔT + D1 ΔT² + D2 ΔT³ + (E0 ΔT + E1 ΔT²)/(λ² − S λ_TK²)]

    dn_abs/dT(λ, T) = (n²(λ, T0) − 1)/(2 n(λ, T0)) ·
                      [D0 + 2 D1 ΔT + 3 D2 ΔT² + (E0 + 2 E1 ΔT)/(λ² − S λ_TK²)]

with the six constants D0, D1, D2, E0, E1, λ_TK of the catalog. S is the sign of λ_TK (1 for
Schott's positive values; Zemax's AGF convention, which lets Hoya's negative λ_TK through
unchanged). n is the absolute index at T0.

:func:`index_at` is the whole procedure a lens program applies when a lens file asks for
another temperature or pressure (Zemax ``ENVD``): relative index at the catalog conditions →
absolute → Schott Δn_abs → relative to the air at (T, P). Wavelengths are given in the air of
the system (T, P) and rescaled to the catalog's air before the dispersion formula is evaluated,
as Zemax and optiland do.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .air import air_index


def _factor(n_abs, lam_um, delta_t, dndt: Sequence[float], derivative: bool):
    d0, d1, d2, e0, e1, ltk = dndt
    denom = lam_um**2 - np.sign(ltk) * ltk**2
    pre = (n_abs**2 - 1.0) / (2.0 * n_abs)
    if derivative:
        return pre * (d0 + 2 * d1 * delta_t + 3 * d2 * delta_t**2 + (e0 + 2 * e1 * delta_t) / denom)
    return pre * (
        d0 * delta_t + d1 * delta_t**2 + d2 * delta_t**3 + (e0 * delta_t + e1 * delta_t**2) / denom
    )


def delta_n_absolute(n_abs_ref, wavelength_um, delta_t, dndt: Sequence[float]):
    """Δn_abs (TIE-19 eq. 3) for an absolute index ``n_abs_ref`` at T0 and ΔT = T − T0 (K);
    ``dndt`` = (D0, D1, D2, E0, E1, λ_TK) with λ_TK in µm."""
    return _factor(
        np.asarray(n_abs_ref, float), np.asarray(wavelength_um, float), delta_t, dndt, False
    )


def dn_dt_absolute(n_abs_ref, wavelength_um, delta_t, dndt: Sequence[float]):
    """dn_abs/dT (1/K, TIE-19 eq. 2) at ΔT = T − T0."""
    return _factor(
        np.asarray(n_abs_ref, float), np.asarray(wavelength_um, float), delta_t, dndt, True
    )


def index_at(
    material,
    wavelength_nm,
    temperature_c: float,
    pressure_atm: float = 1.0,
    *,
    rescale_wavelength: bool = True,
):
    """Index of a catalog ``material`` relative to the air at ``temperature_c`` (°C) and
    ``pressure_atm`` (atm), at ``wavelength_nm`` (nm, in that air).

    At the material's own reference conditions this equals ``material.index(wavelength_nm)``.
    A material without dn/dT constants (``material.dndt`` empty) gets only the air change
    (its absolute index is held fixed), which is what Zemax does for such glasses.

    ``rescale_wavelength=False`` evaluates the formula at the same numerical wavelength at every
    temperature — the definition behind Schott's printed *relative* temperature coefficients
    (the rescaling changes n by dn/dλ · λ Δn_air, about 1e-7/K for dense flints in the blue).

    Raises ``ValueError`` for a material that is not a catalog material.
    """
    if material.kind != "catalog":
        raise ValueError(f"{material.describe()}: temperature data need a catalog material")
    t0, p0 = material.temperature_c, material.pressure_atm
    lam_um = np.asarray(wavelength_nm, float) / 1000.0
    # wavelength in the catalog's air
    lam_ref_um = lam_um
    if rescale_wavelength:
        lam_ref_um = (
            lam_um * air_index(lam_um, temperature_c, pressure_atm) / air_index(lam_um, t0, p0)
        )
    n_ref = np.asarray(material.index(lam_ref_um * 1000.0), float)  # relative at (t0, p0)
    n_abs = n_ref * air_index(lam_ref_um, t0, p0)
    if material.dndt:
        n_abs = n_abs + delta_n_absolute(n_abs, lam_ref_um, temperature_c - t0, material.dndt)
    n = n_abs / air_index(lam_um, temperature_c, pressure_atm)
    return float(n) if np.ndim(n) == 0 else n
