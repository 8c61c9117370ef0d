"""``orthoscope camera``: from a prescription to the camera models of OpenCV, COLMAP, Metashape and
Australis, and back (:mod:`distortion.camera`).

Four actions, chosen by the first word:

- ``orthoscope camera LENS ...`` — real chief rays traced onto a sensor, a model fitted to them
  (``--model``), written as a calibration file (``-o``), a table of models per object distance
  (``--object-distances``), a picture of the distortion (``--picture``) and ``cv2.remap`` maps
  (``--maps``);
- ``orthoscope camera compare LENS CALIBRATION`` — a measured calibration against the
  prescription's prediction at the same focus and object distance;
- ``orthoscope camera convert CALIBRATION --model TARGET`` — any model to any model over the
  sensor, with the residual;
- ``orthoscope camera variation CAL1 CAL2 --calibrated-at S1,S2 ...`` — models per object
  distance from two measured calibrations (Brown; Fraser & Shortis 1992).

The modules, each importing only those above it: values.py (the flags' values), setup.py (the
sensor and the camera setup from the flags), files.py (calibration files in and the format of
``-o``), output.py (files and stdout), forms.py (the forms, the flags each reads and their help
texts), actions.py (the four actions, :func:`~.actions.cmd_camera`), parser.py (the form-aware
parser, the help pages, :func:`~.parser.register`). This module holds the per-command test
samples and re-exports the names other modules use.
"""

from __future__ import annotations

from .files import BUNDLED_CALIBRATIONS
from .forms import ACTIONS, FORMS, form_flags
from .parser import action_parser, register

__all__ = [
    "ACTIONS",
    "BUNDLED_CALIBRATIONS",
    "FORMS",
    "OUTPUTS",
    "SAMPLES",
    "action_parser",
    "form_flags",
    "register",
]

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    ["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "1200x800", "--grid", "9x7",
     "-o", "{tmp}/cooke.yml"],
    ["camera", "topogon-like-pestrecov", "--sensor", "200x200", "--pixels", "2000x2000",
     "--model", "fisheye", "--grid", "9x9", "--json"],
    ["camera", "compare", "cooke-triplet-f4", "{data}/camera/cooke-measured-2m.yml",
     "--sensor", "24x16", "--focus", "2m", "--object-distance", "2m", "--grid", "9x7"],
    ["camera", "convert", "{data}/camera/cooke-measured-2m.yml", "--model", "metashape",
     "-o", "{tmp}/cooke.xml"],
    ["camera", "variation", "{data}/camera/cooke-measured-1m.yml",
     "{data}/camera/cooke-measured-5m.yml", "--calibrated-at", "1m,5m", "--focal-length", "50",
     "--focus", "2m", "--object-distances", "1m,2m,5m", "--sensor", "24x16"],
    ["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "1200x800", "--grid", "9x7",
     "--focus", "2m", "--object-distances", "1m,2m,inf", "--csv"],
]  # fmt: skip
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("-o", ".yml"), ("--plot", ".png")]
