"""Render the plot gallery: ``python docs/gallery/make_gallery.py`` (from the repository root or
anywhere; about 5 s after the kernels are compiled). Writes the PNG files next to this script,
replacing the old ones.

Pestrecov 1958 Figs. 2, 3, 4 and 6 (from his Table I and from traced lenses), Fraser & Shortis
1992 Figs. 2 and 7 style (a traced S65-like lens), lens layouts of the bundled lenses, and the
two-panel figure a newcomer composes in three lines.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt

import orthoscope as osc
from distortion.tablefile import read_distortion_table
from distortion.variation import Conjugate, trace_variation
from orthoscope.plots.common import offscreen_figures
from orthoscope.plots.variation import plot_g, plot_profiles

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
DPI = 100
TABLE1_FIELDS = [0, 10, 20, 25, 30, 35, 37.5, 40, 42.5, 45]  # Pestrecov 1958, Table I
LAYOUTS = (
    "cooke-triplet-f4",
    "tessar-fr1066698",
    "topogon-like-pestrecov",
    "super-angulon-de975637",
    "wide-field-ektar-us2518719",
    "twinplex-like-55-525",
)


def save(fig, name: str) -> None:
    osc.save_figure(fig, HERE / name, overwrite=True, dpi=DPI)
    print(HERE.relative_to(ROOT) / name)


def main() -> None:
    with offscreen_figures():
        # Pestrecov's Table I as printed: markers joined by a monotone spline (no invented data)
        table = read_distortion_table(
            ROOT / "tests" / "data" / "pestrecov_table1.csv", 153.706, name="154 mm f/6.3 Topogon"
        )
        cal = osc.calibrate(table, "two-point", at=(37.5, 45))
        save(osc.plot_characteristic(table), "fig2_table1.png")
        save(osc.plot_calibrated(cal), "fig3_table2.png")
        save(osc.plot_rotation(cal), "fig4_rotation.png")

        # the traced Topogon-like lens: dense curves through the traced fields
        topogon = osc.load_lens("topogon-like-pestrecov")
        d = osc.characteristic_distortion(topogon, TABLE1_FIELDS)
        save(osc.plot_distortion(d), "fig2_traced.png")
        save(
            osc.plot_distortion(d, osc.calibrate(d, "two-point", at=(37.5, 45))), "fig3_traced.png"
        )

        # Fig. 6: the Twinplex-like projector objective in four image planes
        twinplex = osc.load_lens("twinplex-like-55-525")
        sp_gauss = osc.paraxial(twinplex).s_prime_gauss
        planes = osc.characteristic_distortion(
            twinplex,
            [0, 10, 15, 20, 25, 30, 35, 40, 45],
            s_prime=[425.0, 525.0, sp_gauss, 625.0],
        )
        save(osc.plot_distortion(planes), "fig6_traced.png")

        # Fraser & Shortis: the Super-Angulon scaled to 65 mm, focused at 12x
        sa = osc.load_lens("super-angulon-de975637")
        sa = sa.scaled(65.0 / osc.paraxial(sa, math.inf).efl)
        tv = trace_variation(
            sa,
            Conjugate.scale(12),
            [Conjugate.scale(n) for n in (8, 16, 20)],
            max_field_deg=0.9 * sa.field.value,
        )
        save(plot_profiles(tv.analysis), "fs_profiles_s65.png")
        save(plot_g(tv.analysis), "fs_g_s65.png")

        for name in LAYOUTS:
            save(osc.plot_layout(osc.load_lens(name)), f"layout_{name}.png")

    # the newcomer's composed figure (three lines after `import orthoscope as osc`)
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.6), layout="constrained")
    osc.plot_distortion(d, ax=a)
    osc.plot_layout(topogon, ax=b)
    save(fig, "composed_two_panel.png")
    plt.close(fig)


if __name__ == "__main__":
    main()
