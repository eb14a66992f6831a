#!/usr/bin/env python3
"""Mass of particles in named regions vs time, and the fill ratio.

    regionMasses.py -case DIR [-box NAME X0 Y0 Z0 X1 Y1 Z1]... [-cylinder NAME PX PY PZ AX AY AZ R Z0 Z1]...
                    [-reference M] [-name N]

Regions given on the command line are evaluated on every HDF5 output (particle
centre inside, as demLib's output/regions); the mass_<region> columns of
dem/summary.csv are added as they are.  With -reference M (kg) the fill ratio
mass/M is written too (e.g. M = the mass that fills the die).  Writes
postProcessing/<N>.csv and <N>.png (N default 'regionMasses')."""
import csv
import os

import numpy as np

from _common import argument_parser, out_dir, run_main
from diefillpost import geometry, output, plots, series, summary


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-box", nargs=7, action="append", default=[], metavar="V")
    ap.add_argument("-cylinder", nargs=10, action="append", default=[], metavar="V")
    ap.add_argument("-reference", type=float, default=None)
    ap.add_argument("-name", default="regionMasses")
    a = ap.parse_args()
    regions = {b[0]: geometry.Box([float(v) for v in b[1:4]], [float(v) for v in b[4:7]]) for b in a.box}
    for c in a.cylinder:
        v = [float(x) for x in c[1:]]
        regions[c[0]] = geometry.Cylinder(v[0:3], v[3:6], v[6], v[7], v[8])
    columns = {}
    if regions:
        times, masses = [], {k: [] for k in regions}
        for f in series.frames(a.case):
            times.append(f.time)
            for k, r in regions.items():
                masses[k].append(geometry.mass_in_region(f, r))
        columns = {"time": np.array(times), **{k: np.array(v) for k, v in masses.items()}}
    else:
        s = summary.read(a.case)
        columns = {"time": s["time"], **{k[5:]: v for k, v in s.items() if k.startswith("mass_")}}
    names = [k for k in columns if k != "time"]
    if not names:
        ap.error("no region: give -box/-cylinder, or define output/regions in demProperties")
    ratios = [summary.fill_ratio(columns[k], a.reference) for k in names] if a.reference else []
    d = out_dir(a.case)
    with output.open_replacing(os.path.join(d, a.name + ".csv"), newline="") as fh:
        w = csv.writer(fh)
        head = ["time"] + [f"mass_{k}" for k in names] + [f"fillRatio_{k}" for k in names if a.reference]
        w.writerow(head)
        for i, t in enumerate(columns["time"]):
            row = [t] + [columns[k][i] for k in names] + [r[i] for r in ratios]
            w.writerow([f"{v:.6g}" for v in row])
    ys = ratios if a.reference else [columns[k] * 1e3 for k in names]
    plots.curve(os.path.join(d, a.name + ".png"), columns["time"], ys, names, "time [s]",
                "fill ratio [-]" if a.reference else "mass [g]")
    print(f"wrote {os.path.join(d, a.name)}.csv/.png")


if __name__ == "__main__":
    run_main(main)
