"""Camera models: the bridge from lens design to camera calibration.

One module set for every target tool — OpenCV (standard and fisheye), COLMAP, Agisoft
Metashape and the Brown / Fraser (Australis) model of photogrammetry:

- :mod:`.conventions` — the image-coordinate conventions of each target, written once;
- :mod:`.sensor` — :class:`Sensor` (size, pixels, pitch, principal-point offset);
- :mod:`.models` — :class:`CameraModel`, the model formulas (forward, inverse, Jacobian);
- :mod:`.fit` — least-squares fits to correspondences and model-order selection;
- :mod:`.convert` — any model to any model (exact algebra or a refit with its residual);
- :mod:`.files` — OpenCV YAML/JSON, COLMAP cameras.txt, Metashape/PhotoScan XML, Australis text;
- :mod:`.setup` — :class:`CameraSetup` (sensor, focus setting, object plane; a TOML camera spec);
- :mod:`.traced` — from a prescription to a camera model: chief rays traced onto the sensor and the
  models fitted to them (:func:`camera_model`, :func:`opencv_coefficients`), and a measured
  calibration compared with the prediction (:func:`compare_calibration`);
- :mod:`.compare` — two models of one sensor compared (distortion map, radial profiles);
- :mod:`.distance` — models per object distance (traced, or from two calibrations by Brown's and
  Fraser & Shortis' formulas);
- :mod:`.maps` — ``cv2.remap`` maps and a picture of the distortion at true scale.

Everything works on point correspondences (ideal direction ↔ observed image point) and sensors;
a traced chief-ray grid is one such set of correspondences.
"""

from __future__ import annotations

from .compare import (
    CameraComparison,
    RadialProfile,
    compare_cameras,
    distortion_at,
    pinhole_part,
    radial_profile,
)
from .convert import (
    Conversion,
    convert_camera_model,
    convert_exact,
    sensor_grid,
    smallest_exact,
)
from .distance import ModelTable, calibrated_models_by_distance, traced_models_by_distance
from .files import (
    FORMATS,
    colmap_line,
    format_calibration,
    read_calibration,
    read_colmap_cameras,
    write_calibration,
)
from .fit import FAMILIES, CameraFit, ModelSelection, fit_camera_model, select_camera_model
from .maps import DistortionPicture, RemapMaps, distortion_picture, remap_maps
from .models import (
    FOLDED,
    INVALID,
    MODEL_NAMES,
    NOT_CONVERGED,
    OK,
    OPENCV_ORDERS,
    SINGULAR,
    STATUS_NAMES,
    CameraModel,
    MappedPoints,
    ModelSpec,
    NotRepresentable,
    camera_from_sensor,
    model_spec,
    pinhole_camera,
    project,
    project_jacobian,
    unproject,
)
from .sensor import Sensor
from .setup import CameraGeometry, CameraSetup, read_camera_setup
from .traced import (
    CameraPoints,
    Residual,
    TracedCamera,
    camera_model,
    camera_residual,
    compare_calibration,
    fit_correspondences,
    fit_points,
    opencv_coefficients,
    prediction_like,
    trace_camera_points,
)

__all__ = [
    "CameraComparison",
    "CameraGeometry",
    "CameraPoints",
    "CameraSetup",
    "DistortionPicture",
    "ModelTable",
    "RadialProfile",
    "RemapMaps",
    "Residual",
    "TracedCamera",
    "calibrated_models_by_distance",
    "camera_model",
    "camera_residual",
    "compare_calibration",
    "compare_cameras",
    "distortion_at",
    "distortion_picture",
    "fit_correspondences",
    "fit_points",
    "opencv_coefficients",
    "pinhole_part",
    "prediction_like",
    "radial_profile",
    "read_camera_setup",
    "remap_maps",
    "trace_camera_points",
    "traced_models_by_distance",
    "FAMILIES",
    "FOLDED",
    "FORMATS",
    "INVALID",
    "MODEL_NAMES",
    "NOT_CONVERGED",
    "OK",
    "OPENCV_ORDERS",
    "SINGULAR",
    "STATUS_NAMES",
    "CameraFit",
    "CameraModel",
    "Conversion",
    "MappedPoints",
    "ModelSelection",
    "ModelSpec",
    "NotRepresentable",
    "Sensor",
    "camera_from_sensor",
    "colmap_line",
    "convert_camera_model",
    "convert_exact",
    "fit_camera_model",
    "format_calibration",
    "model_spec",
    "pinhole_camera",
    "project",
    "project_jacobian",
    "read_calibration",
    "read_colmap_cameras",
    "select_camera_model",
    "sensor_grid",
    "smallest_exact",
    "unproject",
    "write_calibration",
]
