"""2-D distortion of any lens (docs/design.md, "2-D distortion"): real chief rays over a grid of
fields in any image plane against Pestrecov's ideal image generalised to 2-D (:mod:`.field`), its
decomposition into radial, decentering and thin-prism parts about a named reference point
(:mod:`.decompose`), and Fraser's 10-parameter Brown–Conrady model fitted to it through the
camera-model package (:mod:`.brown`)."""

from .brown import (
    AFFINITY_WARNING_MM,
    BROWN_PARAMS,
    BrownConradyFit,
    fit_brown_conrady,
    fit_brown_conrady_points,
)
from .decompose import (
    CAMERA_CONSTANTS,
    PRINCIPAL_POINTS,
    GridDecomposition,
    LinearFit,
    UndeterminedFit,
    decentering_profile,
    decompose_distortion,
    solve_linear,
)
from .field import (
    MAX_GRID_FIELDS,
    REFERENCE_POINTS,
    DistortionGrid,
    RadialByAzimuth,
    distortion_grid,
    grid_from_fields,
    radial_by_azimuth,
)

__all__ = [
    "AFFINITY_WARNING_MM",
    "BROWN_PARAMS",
    "CAMERA_CONSTANTS",
    "MAX_GRID_FIELDS",
    "PRINCIPAL_POINTS",
    "REFERENCE_POINTS",
    "BrownConradyFit",
    "DistortionGrid",
    "GridDecomposition",
    "LinearFit",
    "RadialByAzimuth",
    "UndeterminedFit",
    "decentering_profile",
    "decompose_distortion",
    "distortion_grid",
    "fit_brown_conrady",
    "fit_brown_conrady_points",
    "grid_from_fields",
    "radial_by_azimuth",
    "solve_linear",
]
