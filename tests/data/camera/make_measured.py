"""Make the synthetic "measured" calibrations of this folder (README.md says what they are).

    python tests/data/camera/make_measured.py [OUT_DIR]

There is no real measured calibration of a bundled lens, so these files stand in for one: the
prescription's prediction (the Cooke triplet 50 mm f/4 on a 24 x 16 mm, 3000 x 2000 px sensor,
focused on the object, OpenCV k1 k2 p1 p2 k3 fitted to its traced chief rays) is perturbed the
way a manufactured lens and its mounting differ from the design (PERTURBATION), and a calibration
of that perturbed camera is simulated: 800 image points spread over the sensor, observed with
Gaussian noise of NOISE_PX, and OpenCV's 5-term model fitted to them by least squares. The same
perturbation is used at every focus distance (one lens); the noise is seeded per file.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

LENS = "cooke-triplet-f4"
SENSOR = {"size": "24x16", "pixels": "3000x2000"}
FOCUS = {"1m": 1, "2m": 2, "5m": 5}  # focus = object distance; value = noise seed
#: how the "real" lens differs from the design (relative for fx, fy, k1, k2; absolute others)
PERTURBATION = {
    "focal_scale": 1.0035,
    "dcx_px": 6.3,
    "dcy_px": -4.1,
    "k1_scale": 1.08,
    "k2_scale": 0.93,
    "p1": 2.5e-5,
    "p2": -1.5e-5,
}
NOISE_PX = 0.08
N_POINTS = 800


def measured_camera(distance: str, seed: int):
    """(measured camera, predicted camera, real camera) for focus = object = ``distance``."""
    import orthoscope as osc
    from distortion.camera import Sensor, camera_model, fit_camera_model, project, unproject

    lens = osc.load_lens(LENS)
    sensor = Sensor.from_spec(**SENSOR)
    pred = camera_model(
        lens, sensor, "opencv", n_coefficients=5, focus=distance, object_distance=distance
    ).camera
    p = PERTURBATION
    real = pred.replace(
        fx=pred["fx"] * p["focal_scale"],
        fy=pred["fy"] * p["focal_scale"],
        cx=pred["cx"] + p["dcx_px"],
        cy=pred["cy"] + p["dcy_px"],
        k1=pred["k1"] * p["k1_scale"],
        k2=pred["k2"] * p["k2_scale"],
        p1=p["p1"],
        p2=p["p2"],
    )
    rng = np.random.default_rng(seed)
    uv = rng.uniform([0.0, 0.0], [sensor.width_px - 1.0, sensor.height_px - 1.0], (N_POINTS, 2))
    ideal = unproject(real, uv, pixels="opencv").points
    observed = project(real, ideal, pixels="opencv").points
    observed = observed + rng.normal(0.0, NOISE_PX, observed.shape)
    fit = fit_camera_model(
        ideal, observed, "opencv", width=sensor.width_px, height=sensor.height_px, free=5
    )
    return fit.camera, pred, real


def main(out: Path) -> int:
    from distortion.camera import write_calibration

    for d, seed in FOCUS.items():
        cam, _, _ = measured_camera(d, seed)
        path = write_calibration(cam, out / f"cooke-measured-{d}.yml", overwrite=True)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent))
