"""Units of the photogrammetric distortion parameters as the reports print them.

One table for the Brown–Conrady parameters in the Australis form (Fraser 1997: c, xp, yp, K1–K3,
P1, P2, b1, b2; :mod:`distortion.grid.brown`, the ``australis`` camera model) and the grid
decomposition's principal point x0, y0 and thin prism S1, S2 (:mod:`distortion.grid.decompose`).
"""

from __future__ import annotations

#: unit of each parameter (mm-based; "" for the dimensionless affinity terms b1, b2)
PARAMETER_UNITS: dict[str, str] = {
    "c": "mm",
    "x0": "mm",
    "y0": "mm",
    "xp": "mm",
    "yp": "mm",
    "K1": "mm^-2",
    "K2": "mm^-4",
    "K3": "mm^-6",
    "P1": "mm^-1",
    "P2": "mm^-1",
    "S1": "mm^-1",
    "S2": "mm^-1",
    "b1": "",
    "b2": "",
}
