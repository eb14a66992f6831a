#!/usr/bin/env python3
"""Results of the die-filling case (paper section 5): bed profile, angles, masses, fill ratio.

    dieFilling.py -case DIR [-openingStart T] [-runTime S]

Reads dem/ (HDF5 series, summary.csv) and constant/demProperties (die radius and height
from the 'dieWall' cylinder, the opening time from its motion) and writes to
postProcessing/:
  profile.csv / profile.png  bed surface in the plane of shoe motion (|y| < R/4) after
                             the opening, with the two fitted lines:
                             - central angle: fit over x in [-R/2, R/2] (the paper's 'central
                               region', 33.8 deg measured, 32.9 deg simulated);
                             - right-border angle: the bed's right edge (outermost particle
                               per height band, |y| < R/4) fitted against height between 20 %
                               and 80 % of the bed's height there; 90 deg = vertical
                               (paper: about 90 deg);
  fillRatio.png              mass in the die / mass poured, vs time;
  sideView_filled.png, sideView_final.png   the bed from the side (like the paper's Fig. 5b);
  results.json / results.csv.
Heights are measured from the die base (z = -H)."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import out_dir  # noqa: E402
from diefillpost import foamdict, plots, profile, results, series, summary  # noqa: E402


def profile_plot(path, x, h, fits, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(x * 1e3, h * 1e3, "o-", ms=3, label="surface profile")
    for f, colour in zip(fits, ("r", "m")):
        xs = np.linspace(*f["window"], 20)
        ax.plot(xs * 1e3, (f["intercept"] + f["slope"] * xs) * 1e3, colour + "-", lw=2,
                label=f"fit {f['angle']:.1f} deg on [{f['window'][0]*1e3:.1f}, {f['window'][1]*1e3:.1f}] mm")
    ax.set_xlabel("x along the shoe motion [mm]")
    ax.set_ylabel("height above die base [mm]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def die_geometry(case):
    d = foamdict.read_case(case)
    wall = d["walls"]["dieWall"]
    radius = float(wall["radius"])
    z0, z1 = (float(v) for v in wall["range"])
    opening = None
    motion = wall.get("motion", {})
    for seg in motion.values():
        if isinstance(seg, dict):
            start = float(seg["start"])
            opening = start if opening is None else min(opening, start)
    return radius, z1 - z0, z0, opening


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-case", default=".")
    ap.add_argument("-openingStart", type=float, default=None)
    ap.add_argument("-runTime", type=float, default=None, help="wall time of the run [s], for the summary")
    a = ap.parse_args()
    case = a.case
    radius, height, base_z, opening = die_geometry(case)
    if a.openingStart is not None:
        opening = a.openingStart
    if opening is None:
        sys.exit("dieFilling.py: no opening time: give -openingStart or a motion of the 'dieWall'")
    out = out_dir(case)

    s = summary.read(case)
    t = s["time"]
    frames = series.list_frames(case)
    # The mass poured: every particle inserted, i.e. the largest particle mass seen in
    # the fields plus what was lost before (particles are never added after the fill).
    poured = max(float(np.sum(series.read_frame(p).mass)) for _, p in frames[: min(len(frames), 12)])
    before = t <= opening + 1e-9
    mass_die_filled = float(s["mass_die"][before][-1])
    mass_base_final = float(s["mass_base"][-1])
    lost_total = float(s["lostMass"][-1])
    lost_before_opening = float(s["lostMass"][before][-1])
    lost_at_opening = lost_total - lost_before_opening
    fill = summary.fill_ratio(s["mass_die"], poured)

    final = series.read_frame(frames[-1][1])
    filled = series.read_frame(min(frames, key=lambda e: abs(e[0] - opening))[1])
    pos = final.position.copy()
    pos[:, 2] -= base_z
    bin_width = 1.5 * float(np.mean(2 * final.radius))
    x, h = profile.line_profile(pos, final.radius, (0, 0, 0), (1, 0, 0), (0, 0, 1), bin_width,
                                extent=(-1.3 * radius, 1.3 * radius), band=radius / 4)
    centre = profile.fit_line(x, h, (-radius / 2, radius / 2))
    # The right border stands close to vertical: measured from the bed's edge position vs
    # height, which a height profile cannot resolve.
    right = None
    try:
        right = profile.edge_angle(pos, final.radius, (0, 0, 0), (1, 0, 0), (0, 0, 1), band=radius / 4,
                                   bin_height=bin_width)
    except ValueError as e:
        print("dieFilling.py: right border:", e)

    with open(os.path.join(out, "profile.csv"), "w") as f:
        f.write("x_mm,height_mm\n")
        for xi, hi in zip(x, h):
            f.write(f"{xi * 1e3:.4f},{'' if not np.isfinite(hi) else f'{hi * 1e3:.4f}'}\n")
    profile_plot(os.path.join(out, "profile.png"), x, h, [centre],
                 f"bed profile after opening (plane of shoe motion): centre {centre['angle']:.1f} deg"
                 + (f", right border {right['angle']:.1f} deg" if right else ""))
    plots.curve(os.path.join(out, "fillRatio.png"), t, [fill], ["mass in die / mass poured"], "time [s]",
                "fill ratio [-]", title="die fill ratio", vlines=[(opening, "die opening starts")])
    plots.side_view(os.path.join(out, "sideView_filled.png"), filled, title=f"filled die, t = {filled.time:.2f} s")
    plots.side_view(os.path.join(out, "sideView_final.png"), final, title=f"after opening, t = {final.time:.2f} s")

    res = {
        "centralAngle": {"value": round(centre["angle"], 2), "unit": "deg",
                         "description": f"fit over x in [{-radius / 2 * 1e3:.1f}, {radius / 2 * 1e3:.1f}] mm "
                                        "(paper: 33.8 measured, 32.9 simulated)"},
        "rightBorderAngle": {"value": round(right["angle"], 2) if right else None, "unit": "deg",
                             "description": ("edge position vs height fitted over heights [%.1f, %.1f] mm "
                                             "above the base" % tuple(w * 1e3 for w in right["window"])
                                             if right else "no edge found") + " (paper: about 90)"},
        "massPoured": {"value": poured, "unit": "kg"},
        "massInDieFilled": {"value": mass_die_filled, "unit": "kg", "description": f"at t = {opening} s"},
        "fillRatioFilled": {"value": mass_die_filled / poured, "unit": "-"},
        "massOnBaseFinal": {"value": mass_base_final, "unit": "kg"},
        "massLostAtOpening": {"value": lost_at_opening, "unit": "kg"},
        "fractionLostAtOpening": {"value": lost_at_opening / mass_die_filled if mass_die_filled > 0 else None,
                                  "unit": "-", "description": "of the mass in the die (paper: 0.10 simulated, 0.02 measured)"},
        "openingStart": {"value": opening, "unit": "s"},
    }
    if a.runTime is not None:
        res["runTime"] = {"value": a.runTime, "unit": "s", "description": "wall time of demRun"}
    results.write(case, res)
    print("dieFilling: central angle %.1f deg, right border %s deg, fill ratio %.3f, lost at opening %.1f %%"
          % (centre["angle"], f"{right['angle']:.1f}" if right else "n/a", mass_die_filled / poured,
             100 * lost_at_opening / max(mass_die_filled, 1e-30)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
