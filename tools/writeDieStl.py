#!/usr/bin/env python3
"""Closed STL surfaces of simple die cavities (the examples of docs/own-die.md), top at z = 0.

    writeDieStl.py cylinder OUT.stl -radius R -depth H [-segments N] [-unit mm]
    writeDieStl.py ring OUT.stl -radius R -innerRadius RI -depth H [-segments N] [-unit mm]
    writeDieStl.py twoLevel OUT.stl -size LX LY -depth H -deepSize DX -deepDepth HD [-unit mm]

cylinder  a round die of radius R and depth H (the paper's die: R = 50 mm, H = 100 mm);
ring      the same with a core of radius RI on the axis (a bush, a thin ring);
twoLevel  a rectangular cavity LX x LY, H deep, with a deeper level: the strip x in
          [LX/2 - DX, LX/2] (the side the shoe reaches last) goes down to HD;
the numbers in the given -unit (default mm), written in that unit (give the same unit in
system/dieDict).  Faces outward, one solid."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, positive, run_main  # noqa: E402
from diefillpost.cavity import UNITS, write_stl  # noqa: E402


def _circle(radius, z, segments):
    a = 2 * np.pi * np.arange(segments) / segments
    return np.stack([radius * np.cos(a), radius * np.sin(a), np.full(segments, z)], axis=1)


def _quads_between(upper, lower, outward):
    """The band between two loops (same count); faces point away from the axis when outward."""
    tris = []
    n = len(upper)
    for k in range(n):
        a, b, c, d = upper[k], upper[(k + 1) % n], lower[(k + 1) % n], lower[k]
        if outward:
            tris += [(a, d, c), (a, c, b)]
        else:
            tris += [(a, b, c), (a, c, d)]
    return tris


def _fan(loop, centre, up):
    n = len(loop)
    return [(centre, loop[k], loop[(k + 1) % n]) if up else (centre, loop[(k + 1) % n], loop[k]) for k in range(n)]


def cylinder(radius, depth, segments):
    top, bottom = _circle(radius, 0.0, segments), _circle(radius, -depth, segments)
    return (_fan(top, np.array([0, 0, 0.0]), True) + _fan(bottom, np.array([0, 0, -depth]), False)
            + _quads_between(top, bottom, True))


def ring(radius, inner, depth, segments):
    ot, ob = _circle(radius, 0.0, segments), _circle(radius, -depth, segments)
    it, ib = _circle(inner, 0.0, segments), _circle(inner, -depth, segments)
    tris = _quads_between(ot, ob, True) + _quads_between(it, ib, False)
    n = segments
    for k in range(n):   # annular caps: top facing up, bottom facing down
        tris += [(it[k], ot[k], ot[(k + 1) % n]), (it[k], ot[(k + 1) % n], it[(k + 1) % n])]
        tris += [(ib[k], ob[(k + 1) % n], ob[k]), (ib[k], ib[(k + 1) % n], ob[(k + 1) % n])]
    return tris


def _box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c = np.array([[(hi if (k >> a) & 1 else lo)[a] for a in range(3)] for k in range(8)])
    quads = [(4, 6, 2, 0), (3, 7, 5, 1), (1, 5, 4, 0), (6, 7, 3, 2), (2, 3, 1, 0), (5, 7, 6, 4)]
    return c, quads


def two_level(lx, ly, depth, deep_width, deep_depth):
    """A box LX x LY x H whose strip x > LX/2 - DX continues down to HD, as one closed surface:
    the outline in the x-z plane is an L-shape, extruded along y."""
    x0, x1, xs = -lx / 2, lx / 2, lx / 2 - deep_width
    y0, y1 = -ly / 2, ly / 2
    # The L-shaped profile (counter-clockwise seen from -y, i.e. in the x-z plane with y towards the viewer).
    prof = np.array([[x0, 0.0], [x0, -depth], [xs, -depth], [xs, -deep_depth], [x1, -deep_depth], [x1, 0.0]])
    tris = []
    n = len(prof)
    for k in range(n):   # the side faces, extruded along y
        a, b = prof[k], prof[(k + 1) % n]
        p = [np.array([a[0], y0, a[1]]), np.array([b[0], y0, b[1]]), np.array([b[0], y1, b[1]]),
             np.array([a[0], y1, a[1]])]
        tris += [(p[0], p[2], p[1]), (p[0], p[3], p[2])]   # outward (the profile runs counter-clockwise in x-z)
    # The two L-shaped ends (y = y0 facing -y, y = y1 facing +y), as two rectangles each.
    for y, sign in ((y0, -1), (y1, 1)):
        for (ax, az), (bx, bz) in (((x0, -depth), (xs, 0.0)), ((xs, -deep_depth), (x1, 0.0))):
            q = [np.array([ax, y, az]), np.array([bx, y, az]), np.array([bx, y, bz]), np.array([ax, y, bz])]
            t = [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
            if sign > 0:
                t = [(a, c, b) for a, b, c in t]
            tris += t
    # The end faces share the vertical edge x = xs between -depth and 0 with each other only:
    # split the side faces at the matching vertices (the bottom edge of the upper level at xs, -depth).
    return _make_conforming(tris)


def _make_conforming(tris):
    """Splits triangle edges at any vertex that lies inside them (T-junctions), so that the
    surface is closed edge-to-edge."""
    tris = [tuple(np.asarray(p, float) for p in t) for t in tris]
    verts = np.unique(np.round(np.array([p for t in tris for p in t]), 12), axis=0)
    changed = True
    while changed:
        changed = False
        out = []
        for t in tris:
            split = None
            for e in range(3):
                a, b = t[e], t[(e + 1) % 3]
                ab = b - a
                L2 = ab.dot(ab)
                for v in verts:
                    s = (v - a).dot(ab) / L2
                    if 1e-9 < s < 1 - 1e-9 and np.linalg.norm(a + s * ab - v) < 1e-12 * (1 + np.sqrt(L2)):
                        split = (e, v)
                        break
                if split:
                    break
            if split:
                e, v = split
                a, b, c = t[e], t[(e + 1) % 3], t[(e + 2) % 3]
                out += [(a, v, c), (v, b, c)]
                changed = True
            else:
                out.append(t)
        tris = out
    return tris


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("shape", choices=["cylinder", "ring", "twoLevel"])
    ap.add_argument("out")
    ap.add_argument("-radius", type=positive)
    ap.add_argument("-innerRadius", type=positive)
    ap.add_argument("-depth", type=positive)
    ap.add_argument("-size", type=positive, nargs=2, metavar=("LX", "LY"))
    ap.add_argument("-deepSize", type=positive)
    ap.add_argument("-deepDepth", type=positive)
    ap.add_argument("-segments", type=int, default=96)
    ap.add_argument("-unit", default="mm", choices=sorted(UNITS))
    a = ap.parse_args()

    def need(*names):
        for n in names:
            if getattr(a, n) is None:
                ap.error(f"{a.shape} needs -{n}")
    if a.segments < 8:
        ap.error(f"-segments: expected 8 or more, got {a.segments}")
    need("depth")
    if a.shape == "cylinder":
        need("radius")
        tris = cylinder(a.radius, a.depth, a.segments)
    elif a.shape == "ring":
        need("radius", "innerRadius")
        if not a.innerRadius < a.radius:
            ap.error(f"-innerRadius {a.innerRadius} must be smaller than -radius {a.radius}")
        tris = ring(a.radius, a.innerRadius, a.depth, a.segments)
    else:
        need("size", "deepSize", "deepDepth")
        if not a.deepSize < a.size[0]:
            ap.error(f"-deepSize {a.deepSize} must be smaller than the cavity's length {a.size[0]}")
        if not a.deepDepth > a.depth:
            ap.error(f"-deepDepth {a.deepDepth} must be larger than -depth {a.depth}")
        tris = two_level(a.size[0], a.size[1], a.depth, a.deepSize, a.deepDepth)
    write_stl(a.out, a.shape, [np.asarray(t, float) for t in tris])
    print(f"writeDieStl: {a.shape}, {len(tris)} triangles ({a.unit}) -> {a.out}")
    return 0


if __name__ == "__main__":
    run_main(main)
