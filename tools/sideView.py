#!/usr/bin/env python3
"""Side picture of the particle bed at one output time: circles of the true radius
projected on a vertical plane, coloured by height, speed or angular velocity.

    sideView.py -case DIR [-time T] [-color height|speed|omega] [-horizontal X Y Z] [-name N]

Writes postProcessing/<N>.png (N default 'sideView_<time>')."""
import os

from _common import argument_parser, direction, finite, frame_at, out_dir, run_main
from diefillpost import plots


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-time", type=finite, default=None)
    ap.add_argument("-color", choices=("height", "speed", "omega"), default="height")
    ap.add_argument("-horizontal", type=finite, nargs=3, default=(1, 0, 0))
    ap.add_argument("-up", type=finite, nargs=3, default=(0, 0, 1))
    ap.add_argument("-name", default=None)
    a = ap.parse_args()
    direction(ap, "-horizontal", a.horizontal, direction(ap, "-up", a.up), "-up")
    f = frame_at(a.case, a.time)
    path = os.path.join(out_dir(a.case), (a.name or f"sideView_{f.time:.4f}") + ".png")
    plots.side_view(path, f, a.horizontal, a.up, color_by=a.color)
    print(f"wrote {path}")


if __name__ == "__main__":
    run_main(main)
