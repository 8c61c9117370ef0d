"""Camera models: the bridge from lens design to camera calibration.

One module set for every target tool — OpenCV (standard and fisheye), COLMAP, Agisoft
Metashape and the Brown / Fraser (Australis) model of photogrammetry:

- :mod:`.conventions` — the image-coordinate conventions of each target, written once;
- :mod:`.sensor` — :class:`Sensor` (size, pixels, pitch, principal-point offset);
- :mod:`.models` — :class:`CameraModel`, the model formulas (forward, inverse, Jacobian);
- :mod:`.fit` — least-squares fits to correspondences and model-order selection;
- :mod:`.convert` — any model to any model (exact algebra or a refit with its residual);
- :mod:`.files` — OpenCV YAML/JSON, COLMAP cameras.txt, Metashape/PhotoScan XML, Australis text.

Everything works on point correspondences (ideal direction ↔ observed image point) and sensors;
a traced chief-ray grid is one such set of correspondences.
"""

from __future__ import annotations

from .convert import (
    Conversion,
    convert_camera_model,
    convert_exact,
    sensor_grid,
    smallest_exact,
)
from .files import (
    FORMATS,
    colmap_line,
    format_calibration,
    read_calibration,
    read_colmap_cameras,
    write_calibration,
)
from .fit import FAMILIES, CameraFit, ModelSelection, fit_camera_model, select_camera_model
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

__all__ = [
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
