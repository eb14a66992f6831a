#!/usr/bin/env python3
"""Surface profile of the particle bed at one output time, along a line or around an axis.

    bedProfile.py -case DIR [-time T] -line OX OY OZ DX DY DZ [-band W] [-binWidth B] [-window A B] [-name N]
    bedProfile.py -case DIR [-time T] -axis PX PY PZ AX AY AZ [-sectors N] [-binWidth B] [-window A B] [-name N]

Heights are the highest particle top (centre height + radius) per bin (see
docs/post-processing.md).  With -window (mm, along the line / from the axis) a line is
fitted and its angle reported; -window auto takes the pile flank (80 %-20 % of the peak).
Writes postProcessing/<N>.csv and <N>.png (N default 'bedProfile')."""
import csv
import os
from argparse import ArgumentTypeError

import numpy as np

from _common import argument_parser, direction, finite, frame_at, ordered, out_dir, positive, positive_int, run_main
from diefillpost import output, plots, profile


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-time", type=finite, default=None)
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("-line", type=finite, nargs=6, metavar="V")
    g.add_argument("-axis", type=finite, nargs=6, metavar="V")
    ap.add_argument("-up", type=finite, nargs=3, default=(0, 0, 1))
    ap.add_argument("-band", type=positive, default=None, help="half-width of the band around the line [m]")
    ap.add_argument("-sectors", type=positive_int, default=8)
    ap.add_argument("-binWidth", type=positive, default=None, help="[m] (default 1.5 mean diameters)")
    ap.add_argument("-window", nargs=2, default=None, help="fit window in mm, or 'auto auto'")
    ap.add_argument("-name", default="bedProfile")
    a = ap.parse_args()
    if a.line:
        along = direction(ap, "-line", a.line[3:])
        direction(ap, "-up", a.up, along, "-line")
    else:
        direction(ap, "-axis", a.axis[3:])
    window = None
    if a.window and a.window != ["auto", "auto"]:
        try:
            window = [finite(v) * 1e-3 for v in a.window]
        except ArgumentTypeError:
            ap.error(f"argument -window: expected two numbers (mm) or 'auto auto', got '{' '.join(a.window)}'")
        ordered(ap, "-window", *window, what="positions")
    f = frame_at(a.case, a.time)
    bw = a.binWidth if a.binWidth is not None else 1.5 * float(np.mean(2 * f.radius))
    if a.line:
        try:
            x, h = profile.line_profile(f.position, f.radius, a.line[:3], a.line[3:], a.up, bw, band=a.band)
        except ValueError as e:
            if a.band is None:
                raise
            raise ValueError(f"argument -band: {e} given by -line (widen -band, or move -line onto the bed)") from e
    else:
        x, h, _ = profile.radial_profile(f.position, f.radius, a.axis[:3], a.axis[3:], bw, sectors=a.sectors)
    fit = None
    if a.window:
        win = window or profile.flank_window(x, h)
        fit = profile.fit_line(x, h, win)
        print(f"angle {fit['angle']:.2f} deg over [{win[0]*1e3:.1f}, {win[1]*1e3:.1f}] mm ({fit['points']} bins)")
    d = out_dir(a.case)
    with output.open_replacing(os.path.join(d, a.name + ".csv"), newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["position_m", "height_m"])
        for xi, hi in zip(x, h):
            w.writerow([f"{xi:.6g}", "" if not np.isfinite(hi) else f"{hi:.6g}"])
    plots.profile_with_fit(os.path.join(d, a.name + ".png"), x, h, fit, title=f"t = {f.time:.3f} s")
    print(f"wrote {os.path.join(d, a.name)}.csv/.png")


if __name__ == "__main__":
    run_main(main)
