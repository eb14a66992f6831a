#!/usr/bin/env python3
"""Post-processing of the repose-angle calibration case (no ParaView needed).

    reposeAngle.py -case DIR [-tube WALL] [-binWidth B] [-sectors N] [-heights LOW HIGH]
                   [-window RA RB] [-runTime S]

The angle of repose of the final pile: the surface profile h(r) is the highest
particle top (z + radius) per radial bin of width B around the tube's axis, in
each of N azimuthal sectors, averaged over the sectors.  A straight line is fitted
to h(r) over the flank window: from the first radius beyond the peak where h falls
below HIGH x peak height to the last radius where h is still above LOW x peak
height (defaults 0.8 and 0.2: the rounded top and the toe are left out), or over
[RA, RB] (mm) when -window is given.  The angle is atan|slope|; the same fit in
each sector gives the spread.  Writes postProcessing/{profile.csv, reposeProfile.png,
sideView.png, results.json, results.csv}."""
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from diefillpost import foamdict, geometry, output, plots, profile, results, series, summary  # noqa: E402
from _common import argument_parser, finite, non_negative, ordered, positive, positive_int, run_main  # noqa: E402

PAPER_ANGLE = 28.0


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-tube", default="tube", help="name of the lifted cylinder wall (gives the axis)")
    ap.add_argument("-binWidth", type=positive, default=None, help="radial bin [m] (default: 1.5 mean diameters)")
    ap.add_argument("-sectors", type=positive_int, default=8)
    ap.add_argument("-heights", type=finite, nargs=2, default=(0.2, 0.8), metavar=("LOW", "HIGH"))
    ap.add_argument("-window", type=finite, nargs=2, default=None, metavar=("RA", "RB"), help="fit window [mm]")
    ap.add_argument("-runTime", type=non_negative, default=None, help="demRun wall time [s] to record")
    a = ap.parse_args()
    if not 0 <= a.heights[0] < a.heights[1] <= 1:
        ap.error(f"argument -heights: expected fractions of the peak height 0 <= LOW < HIGH <= 1, "
                 f"got {a.heights[0]:g} {a.heights[1]:g}")
    if a.window:
        ordered(ap, "-window", *a.window, what="radii")
    case = a.case
    props = foamdict.read_case(case)
    tube = props["walls"][a.tube]
    axis_point, axis = np.asarray(tube["axisPoint"], float), geometry.unit(tube["axis"])
    f = series.last_frame(case)
    if f.count == 0:
        sys.exit("reposeAngle.py: the last output holds no particles")
    bw = a.binWidth if a.binWidth is not None else 1.5 * float(np.mean(2 * f.radius))
    r, h, n = profile.radial_profile(f.position, f.radius, axis_point, axis, bw, sectors=a.sectors)
    window = tuple(np.asarray(a.window) * 1e-3) if a.window else profile.flank_window(r, h, *a.heights)
    fit = profile.fit_line(r, h, window)
    # the same fit sector by sector: the spread around the axis
    sector_angles = profile.sector_angles(f.position, f.radius, axis_point, axis, bw, window, a.sectors)
    removed_at = float(tube.get("removeAt", np.inf))
    s = summary.read(case)
    setting = open(os.path.join(case, "constant", "setting")).read().strip() \
        if os.path.exists(os.path.join(case, "constant", "setting")) else "unknown"
    rolling = props["contactModel"]["rolling"]

    out = os.path.join(case, "postProcessing")
    os.makedirs(out, exist_ok=True)
    with output.open_replacing(os.path.join(out, "profile.csv"), newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["radius_m", "height_m", "sectorsWithParticles"])
        for ri, hi, ni in zip(r, h, n):
            w.writerow([f"{ri:.6g}", "" if not np.isfinite(hi) else f"{hi:.6g}", int(ni)])
    plots.profile_with_fit(os.path.join(out, "reposeProfile.png"), r, h, fit,
                           title=f"repose angle {fit['angle']:.1f}° ({setting}, rolling {rolling}; paper 28°)",
                           xlabel="distance from the axis [mm]")
    plots.side_view(os.path.join(out, "sideView.png"), f, (1, 0, 0), (0, 0, 1), color_by="height",
                    title=f"final pile, t = {f.time:.3f} s, {f.count} particles")
    peak = float(np.nanmax(h))
    res = {
        "setting": setting,
        "rollingModel": rolling,
        "reposeAngle": {"value": fit["angle"], "unit": "deg", "description": "fit of the sector-averaged surface profile h(r) (paper: 28)"},
        "fitWindow": {"value": [w * 1e3 for w in fit["window"]], "unit": "mm", "description": f"radii fitted ({a.heights[0]:g}-{a.heights[1]:g} of peak height unless -window)"},
        "fitRms": {"value": fit["rms"] * 1e3, "unit": "mm"},
        "sectorAngleMean": {"value": float(np.mean(sector_angles)) if sector_angles else None, "unit": "deg"},
        "sectorAngleStd": {"value": float(np.std(sector_angles)) if sector_angles else None, "unit": "deg"},
        "binWidth": {"value": bw * 1e3, "unit": "mm"},
        "pileHeight": {"value": peak * 1e3, "unit": "mm"},
        "particles": {"value": int(f.count), "unit": "-"},
        "mass": {"value": f.total_mass * 1e3, "unit": "g"},
        "time": {"value": f.time, "unit": "s"},
        "tubeRemoved": {"value": bool(f.time >= removed_at), "unit": "-", "description": f"the tube is removed at t = {removed_at} s"},
        "lostCount": {"value": int(s["lostCount"][-1]), "unit": "-"},
        "finalKineticEnergy": {"value": float(s["kineticEnergy"][-1]), "unit": "J"},
        "demRunWallTime": {"value": a.runTime, "unit": "s"},
        "paperReposeAngle": {"value": PAPER_ANGLE, "unit": "deg"},
    }
    jp, _ = results.write(case, res)
    if f.time < removed_at:
        print(f"    warning: the last output (t = {f.time:.3f} s) is before the tube is removed ({removed_at} s)")
    print(f"    repose angle ({setting}, rolling {rolling}): {fit['angle']:.1f} deg (paper 28 deg), "
          f"fit over r = {fit['window'][0]*1e3:.1f}-{fit['window'][1]*1e3:.1f} mm, "
          + (f"sectors {np.mean(sector_angles):.1f} +- {np.std(sector_angles):.1f} deg" if sector_angles
             else "no sector alone holds enough of the flank for a fit")
          + f"; pile height {peak*1e3:.1f} mm, "
          f"{f.count} particles, {f.total_mass*1e3:.2f} g")
    print(f"    results: {jp}")


if __name__ == "__main__":
    run_main(main)
