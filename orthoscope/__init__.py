"""orthoscope: lens design for image geometry — real chief rays to any image plane and Pestrecov's
characteristic and calibrated distortion, its variation with object distance (Fraser & Shortis),
compensation, and plots.

The shortest path::

    import orthoscope as osc
    lens = osc.load_lens("topogon-us2031792-fig1")        # bundled name or .toml/.zmx/.seq path
    p = osc.paraxial(lens)                                 # p.efl, p.bfl, pupils, m_e, ...
    rays = osc.chief_rays(lens, fields_deg=[0, 10, 20])    # named arrays, a status per ray
    d = osc.characteristic_distortion(lens, fields_deg=[0, 10, 20, 30, 40])
    cal = osc.calibrate(d, method="minimax")
    fig = osc.plot_distortion(d, cal)

Units: millimetres, wavelengths in nm, angles in degrees; light travels toward +z; signs follow
Pestrecov (1958) Fig. 1. The object plane is given as ``object_distance`` (mm from the first
vertex), ``object_s`` (signed, from H) or ``object_scale`` (N of "N×"); the image plane as
``s_prime`` (from H'), ``from_last_vertex`` or ``defocus`` (from the Gaussian plane) — the same
words as the command line's flags and the JSON keys (docs/design.md, "Vocabulary").

Names load on first use, so ``import orthoscope`` is cheap and the command line starts fast.
"""

from __future__ import annotations

import importlib as _importlib
from typing import TYPE_CHECKING

#: public name -> module that defines it
_API: dict[str, str] = {
    # lenses and files
    "Lens": "raytrace.lens",
    "Surface": "raytrace.lens",
    "Aperture": "raytrace.lens",
    "Field": "raytrace.lens",
    "Material": "raytrace.materials",
    "model_glass": "raytrace.materials",
    "fixed_index": "raytrace.materials",
    "load_lens": "raytrace.files.library",
    "list_lenses": "raytrace.files.library",
    "save_lens": "raytrace.files",
    "convert": "raytrace.files",
    # paraxial optics and the vocabulary of planes
    "paraxial": "raytrace.paraxial",
    "ParaxialResult": "raytrace.paraxial",
    "ImagePlane": "raytrace.paraxial",
    "pestrecov_constants": "raytrace.paraxial",
    # real rays
    "chief_rays": "raytrace.trace",
    "ChiefRays": "raytrace.trace",
    "ChromaticChiefRays": "raytrace.trace",
    "trace_rays": "raytrace.trace",
    "RayBatch": "raytrace.trace",
    "chief_rays_2d": "raytrace.trace",
    "ChiefRays2D": "raytrace.trace",
    "ray_fan": "raytrace.trace",
    "RayFan": "raytrace.trace",
    "spot_diagram": "raytrace.trace",
    "SpotDiagram": "raytrace.trace",
    # distortion (Pestrecov 1958)
    "characteristic_distortion": "distortion.characteristic",
    "CharacteristicDistortion": "distortion.characteristic",
    "ChromaticDistortion": "distortion.characteristic",
    # colour
    "lateral_colour": "distortion.colour",
    "LateralColour": "distortion.colour",
    "focal_shift": "distortion.colour",
    "FocalShift": "distortion.colour",
    "lookup_glass": "raytrace.glass",
    "search_glass": "raytrace.glass",
    "calibrate": "distortion.calibration",
    "CalibrationResult": "distortion.calibration",
    "compensate": "distortion.compensation",
    "CompensationResult": "distortion.compensation",
    "DistortionCurve": "distortion.curve",
    "make_curve": "distortion.curve",
    "read_distortion_table": "distortion.tablefile",
    # named definitions (F-tan(theta), F-theta, fisheye) and pupils / telecentricity
    "projection_distortion": "distortion.definitions",
    "ProjectionDistortion": "distortion.definitions",
    "pupil_analysis": "distortion.telecentricity",
    "PupilAnalysis": "distortion.telecentricity",
    # 2-D distortion, decentering, Brown-Conrady
    "distortion_grid": "distortion.grid",
    "DistortionGrid": "distortion.grid",
    "radial_by_azimuth": "distortion.grid",
    "decompose_distortion": "distortion.grid",
    "GridDecomposition": "distortion.grid",
    "fit_brown_conrady": "distortion.grid",
    "BrownConradyFit": "distortion.grid",
    # rectangular-sensor metrics (TV distortion, keystone, straightness) and the certificate
    "sensor_metrics": "distortion.sensor_metrics",
    "SensorMetrics": "distortion.sensor_metrics",
    "calibration_certificate": "distortion.certificate",
    "CalibrationCertificate": "distortion.certificate",
    # variation with object distance (Fraser & Shortis 1992) and coefficients
    "trace_variation": "distortion.variation",
    "analyze_variation": "distortion.variation",
    "analyze_csv": "distortion.variation",
    "read_profiles_csv": "distortion.variation",
    "Conjugate": "distortion.variation",
    # focus positions / configurations that change thicknesses (Brown's model tested on them)
    "read_configured": "raytrace.files.configurations",
    "read_configurations": "raytrace.files.configurations",
    "apply_configuration": "raytrace.files.configurations",
    "write_lens_with_configurations": "raytrace.files.configurations",
    "Configuration": "raytrace.files.configurations",
    "Configurations": "raytrace.files.configurations",
    "focus_study": "distortion.variation.focus",
    "FocusStudy": "distortion.variation.focus",
    "solve_focus": "distortion.variation.focus",
    "focus_configurations": "distortion.variation.focus",
    "unit_focus_configurations": "distortion.variation.focus",
    "fit_radial": "distortion.coefficients",
    "opencv_model": "distortion.coefficients",
    # camera models (OpenCV, COLMAP, Metashape, Australis) and sensors
    "Sensor": "distortion.camera",
    "CameraModel": "distortion.camera",
    "CameraFit": "distortion.camera",
    "camera_from_sensor": "distortion.camera",
    "fit_camera_model": "distortion.camera",
    "select_camera_model": "distortion.camera",
    "convert_camera_model": "distortion.camera",
    "read_calibration": "distortion.camera",
    "write_calibration": "distortion.camera",
    # camera models from a prescription, and back
    "CameraSetup": "distortion.camera",
    "read_camera_setup": "distortion.camera",
    "camera_model": "distortion.camera",
    "opencv_coefficients": "distortion.camera",
    "TracedCamera": "distortion.camera",
    "trace_camera_points": "distortion.camera",
    "compare_calibration": "distortion.camera",
    "compare_cameras": "distortion.camera",
    "CameraComparison": "distortion.camera",
    "traced_models_by_distance": "distortion.camera",
    "calibrated_models_by_distance": "distortion.camera",
    "ModelTable": "distortion.camera",
    "remap_maps": "distortion.camera",
    "distortion_picture": "distortion.camera",
    # design
    "read_spec": "raytrace.optimize",
    "optimize": "raytrace.optimize",
    "global_optimize": "raytrace.optimize",
    "split_element": "raytrace.elements",
    "insert_element": "raytrace.elements",
    "split_design": "raytrace.optimize",
    "insert_design": "raytrace.optimize",
    "element_power": "raytrace.paraxial",
    # tolerancing (docs/tolerance.md)
    "read_tolerance_spec": "raytrace.tolerance",
    "ToleranceSpec": "raytrace.tolerance",
    "SensitivityResult": "distortion.tolerance",
    "MonteCarloResult": "distortion.tolerance",
    "ToleranceOutputs": "distortion.tolerance",
    "tolerance_sensitivity": "distortion.tolerance",
    "tolerance_monte_carlo": "distortion.tolerance",
    # plots (matplotlib loads with the first of these)
    "plot_distortion": "orthoscope.plots.distortion",
    "plot_characteristic": "orthoscope.plots.distortion",
    "plot_calibrated": "orthoscope.plots.distortion",
    "plot_planes": "orthoscope.plots.distortion",
    "plot_rotation": "orthoscope.plots.distortion",
    "plot_layout": "orthoscope.plots.layout",
    "plot_focal_shift": "orthoscope.plots.colour",
    "plot_lateral_colour": "orthoscope.plots.colour",
    "plot_distortion_by_wavelength": "orthoscope.plots.colour",
    "plot_profiles": "orthoscope.plots.variation",
    "plot_g": "orthoscope.plots.variation",
    "plot_ray_fan": "orthoscope.plots.rays",
    "plot_grid_distortion": "orthoscope.plots.grid",
    "plot_distortion_vectors": "orthoscope.plots.grid",
    "plot_radial_by_azimuth": "orthoscope.plots.grid",
    "plot_certificate": "orthoscope.plots.certificate",
    "plot_spot": "orthoscope.plots.rays",
    "plot_camera_residuals": "orthoscope.plots.camera",
    "plot_distortion_picture": "orthoscope.plots.camera",
    "plot_calibration_comparison": "orthoscope.plots.camera",
    "plot_radial_comparison": "orthoscope.plots.camera",
    "plot_difference_map": "orthoscope.plots.camera",
    "save_figure": "orthoscope.plots.save",
    "plot_glass_map": "orthoscope.plots.glassmap",
    "plot_pupils": "orthoscope.plots.telecentricity",
    "plot_chief_ray_angle": "orthoscope.plots.telecentricity",
    "plot_distortion_slope": "orthoscope.plots.telecentricity",
    "plot_entrance_pupil": "orthoscope.plots.telecentricity",
    "plot_tolerance": "orthoscope.plots.tolerance",
    "plot_envelope": "orthoscope.plots.tolerance",
    "plot_sensitivity": "orthoscope.plots.tolerance",
    # errors
    "OrthoscopeError": "raytrace.errors",
    "PrescriptionError": "raytrace.errors",
    "LensError": "raytrace.errors",
    "TraceError": "raytrace.errors",
    "OutputError": "raytrace.errors",
    "FieldNotTracedError": "raytrace.trace.fans",
    "DataError": "distortion.errors",
    "CalibrationError": "distortion.errors",
}

__all__ = sorted([*_API, "__version__"])


def _version() -> str:
    """The installed distribution's version (read on first use: importlib.metadata is slow)."""
    try:
        from importlib.metadata import PackageNotFoundError, version
    except ImportError:  # pragma: no cover
        return "0+unknown"
    try:
        return version("orthoscope")
    except PackageNotFoundError:
        return "0+unknown"


def __getattr__(name: str) -> object:
    if name == "__version__":
        v = _version()
        globals()["__version__"] = v
        return v
    mod = _API.get(name)
    if mod is None:
        raise AttributeError(f"module 'orthoscope' has no attribute {name!r}")
    value = getattr(_importlib.import_module(mod), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public API (:data:`__all__`), the module's dunder names and its subpackages that are
    loaded (``plots``, ``report``, ``cli``): not the helpers of this file (``TYPE_CHECKING``,
    ``annotations``, ...)."""
    import types

    names = {n for n in globals() if n.startswith("__") and n.endswith("__")}
    names |= {n for n, v in globals().items() if isinstance(v, types.ModuleType) and n[0] != "_"}
    return sorted(names | set(__all__))


if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load lazily
    from distortion.calibration import CalibrationResult, calibrate
    from distortion.camera import (
        CameraComparison,
        CameraFit,
        CameraModel,
        CameraSetup,
        ModelTable,
        Sensor,
        TracedCamera,
        calibrated_models_by_distance,
        camera_from_sensor,
        camera_model,
        compare_calibration,
        compare_cameras,
        convert_camera_model,
        distortion_picture,
        fit_camera_model,
        opencv_coefficients,
        read_calibration,
        read_camera_setup,
        remap_maps,
        select_camera_model,
        trace_camera_points,
        traced_models_by_distance,
        write_calibration,
    )
    from distortion.certificate import CalibrationCertificate, calibration_certificate
    from distortion.characteristic import (
        CharacteristicDistortion,
        ChromaticDistortion,
        characteristic_distortion,
    )
    from distortion.coefficients import fit_radial, opencv_model
    from distortion.colour import FocalShift, LateralColour, focal_shift, lateral_colour
    from distortion.compensation import CompensationResult, compensate
    from distortion.curve import DistortionCurve, make_curve
    from distortion.definitions import ProjectionDistortion, projection_distortion
    from distortion.errors import CalibrationError, DataError
    from distortion.grid import (
        BrownConradyFit,
        DistortionGrid,
        GridDecomposition,
        decompose_distortion,
        distortion_grid,
        fit_brown_conrady,
        radial_by_azimuth,
    )
    from distortion.sensor_metrics import SensorMetrics, sensor_metrics
    from distortion.tablefile import read_distortion_table
    from distortion.telecentricity import PupilAnalysis, pupil_analysis
    from distortion.tolerance import (
        MonteCarloResult,
        SensitivityResult,
        ToleranceOutputs,
        tolerance_monte_carlo,
        tolerance_sensitivity,
    )
    from distortion.variation import (
        Conjugate,
        analyze_csv,
        analyze_variation,
        read_profiles_csv,
        trace_variation,
    )
    from distortion.variation.focus import (
        FocusStudy,
        focus_configurations,
        focus_study,
        solve_focus,
        unit_focus_configurations,
    )
    from raytrace.errors import (
        LensError,
        OrthoscopeError,
        OutputError,
        PrescriptionError,
        TraceError,
    )
    from raytrace.files import convert, save_lens
    from raytrace.files.configurations import (
        Configuration,
        Configurations,
        apply_configuration,
        read_configurations,
        read_configured,
        write_lens_with_configurations,
    )
    from raytrace.files.library import list_lenses, load_lens
    from raytrace.glass import lookup_glass, search_glass
    from raytrace.lens import Aperture, Field, Lens, Surface
    from raytrace.materials import Material, fixed_index, model_glass
    from raytrace.optimize import global_optimize, optimize, read_spec
    from raytrace.paraxial import ImagePlane, ParaxialResult, paraxial, pestrecov_constants
    from raytrace.tolerance import ToleranceSpec, read_tolerance_spec
    from raytrace.trace import (
        ChiefRays,
        ChiefRays2D,
        ChromaticChiefRays,
        RayBatch,
        RayFan,
        SpotDiagram,
        chief_rays,
        chief_rays_2d,
        ray_fan,
        spot_diagram,
        trace_rays,
    )
    from raytrace.trace.fans import FieldNotTracedError

    from .plots.camera import (
        plot_calibration_comparison,
        plot_camera_residuals,
        plot_difference_map,
        plot_distortion_picture,
        plot_radial_comparison,
    )
    from .plots.certificate import plot_certificate
    from .plots.colour import (
        plot_distortion_by_wavelength,
        plot_focal_shift,
        plot_lateral_colour,
    )
    from .plots.distortion import (
        plot_calibrated,
        plot_characteristic,
        plot_distortion,
        plot_planes,
        plot_rotation,
    )
    from .plots.glassmap import plot_glass_map
    from .plots.grid import plot_distortion_vectors, plot_grid_distortion, plot_radial_by_azimuth
    from .plots.layout import plot_layout
    from .plots.rays import plot_ray_fan, plot_spot
    from .plots.save import save_figure
    from .plots.telecentricity import (
        plot_chief_ray_angle,
        plot_distortion_slope,
        plot_entrance_pupil,
        plot_pupils,
    )
    from .plots.tolerance import plot_envelope, plot_sensitivity, plot_tolerance
    from .plots.variation import plot_g, plot_profiles
