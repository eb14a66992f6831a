#!/usr/bin/env python3
"""Write an axis-aligned box as an ASCII STL (12 triangles, outward normals).

    writeBoxStl.py OUT.stl XMIN YMIN ZMIN XMAX YMAX ZMAX [-name NAME]

Used by the inclined-plate tutorial for its finite steel plate (a mesh wall is
two-sided and has edges, unlike an infinite one-sided plane)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, finite, run_main  # noqa: E402
from diefillpost.output import open_replacing  # noqa: E402


def box_triangles(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c = np.array([[(hi if (k >> a) & 1 else lo)[a] for a in range(3)] for k in range(8)])
    # corner k has bit a set when coordinate a is at hi; faces as outward quads
    quads = [(4, 6, 2, 0), (3, 7, 5, 1), (1, 5, 4, 0), (6, 7, 3, 2), (2, 3, 1, 0), (5, 7, 6, 4)]
    tris = []
    for a, b, cc, d in quads:
        tris += [(c[a], c[b], c[cc]), (c[a], c[cc], c[d])]
    return tris


def write_stl(path, triangles, name="box"):
    with open_replacing(path) as f:
        f.write(f"solid {name}\n")
        for a, b, c in triangles:
            n = np.cross(b - a, c - a)
            n = n / np.linalg.norm(n)
            f.write(f"  facet normal {n[0]:.6g} {n[1]:.6g} {n[2]:.6g}\n    outer loop\n")
            for v in (a, b, c):
                f.write(f"      vertex {v[0]:.9g} {v[1]:.9g} {v[2]:.9g}\n")
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")


def main():
    p = argument_parser(__doc__)
    p.add_argument("out")
    p.add_argument("coords", type=finite, nargs=6, metavar="X")
    p.add_argument("-name", default="box")
    a = p.parse_args()
    lo, hi = a.coords[:3], a.coords[3:]
    if not all(h > l for l, h in zip(lo, hi)):
        p.error("expected XMAX > XMIN, YMAX > YMIN, ZMAX > ZMIN")
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    write_stl(a.out, box_triangles(lo, hi), a.name)


if __name__ == "__main__":
    run_main(main)
