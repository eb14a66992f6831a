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
from argparse import ArgumentTypeError

import numpy as np

from _common import argument_parser, direction, finite, ordered, out_dir, positive, run_main
from diefillpost import geometry, output, plots, series, summary


def numbers(parser, option, name, values):
    """The numbers after a region's name, each checked as finite; a parser error names
    the option and the region."""
    try:
        return [finite(v) for v in values]
    except ArgumentTypeError as e:
        parser.error(f"argument {option} {name}: {e}")


def regions_from_options(parser, boxes, cylinders):
    """{name: region} from the -box and -cylinder options, checked: min below max,
    a non-zero axis, a radius above zero, a range low < high, names given once."""
    regions = {}
    for option, name, region in [("-box", b[0], b[1:]) for b in boxes] + [("-cylinder", c[0], c[1:]) for c in cylinders]:
        if name in regions or name == "time":
            parser.error(f"argument {option} {name}: the name " + ("is taken by the time column" if name == "time"
                                                                  else "is given to two regions"))
        v = numbers(parser, option, name, region)
        if option == "-box":
            for axis, lo, hi in zip("xyz", v[0:3], v[3:6]):
                if not lo < hi:
                    parser.error(f"argument -box {name}: min {axis} ({lo:g}) is not below max {axis} ({hi:g}); "
                                 "expected X0 Y0 Z0 (min) then X1 Y1 Z1 (max)")
            regions[name] = geometry.Box(v[0:3], v[3:6])
        else:
            direction(parser, f"-cylinder {name}", v[3:6])
            if not v[6] > 0:
                parser.error(f"argument -cylinder {name}: the radius ({v[6]:g}) is not above zero")
            ordered(parser, f"-cylinder {name}", v[7], v[8], what="axial limits Z0 Z1")
            regions[name] = geometry.Cylinder(v[0:3], v[3:6], v[6], v[7], v[8])
    return regions


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-box", nargs=7, action="append", default=[], metavar="V")
    ap.add_argument("-cylinder", nargs=10, action="append", default=[], metavar="V")
    ap.add_argument("-reference", type=positive, default=None, help="[kg] the mass of a full region")
    ap.add_argument("-name", default="regionMasses")
    a = ap.parse_args()
    regions = regions_from_options(ap, a.box, a.cylinder)
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
