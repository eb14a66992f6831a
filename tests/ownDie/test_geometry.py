"""Checks of the own-die geometry route (tools/diefillpost/cavity.py, tools/writeDieStl.py,
tools/writeDieCase.py) against numbers known by construction.  One line per check,
'PASS: ...' or 'FAIL: ...'; the last line 'N passed, N failed'."""
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from diefillpost.cavity import Cavity, CavityError, read_stl, table_triangles, write_stl  # noqa: E402
from diefillpost.shoe import Shoe, ShoeError  # noqa: E402
import writeDieStl  # noqa: E402

PY = sys.executable
results = []


def check(name, ok, detail=""):
    results.append(bool(ok))
    print(("PASS: " if ok else "FAIL: ") + name + (f" ({detail})" if detail else ""), flush=True)


def polygon_area(n, r):
    return 0.5 * n * r * r * math.sin(2 * math.pi / n)


def table_area(t):
    return float(0.5 * np.abs(np.cross(t[:, 1, :2] - t[:, 0, :2], t[:, 2, :2] - t[:, 0, :2])).sum())


def run(args, cwd):
    p = subprocess.run([PY] + args, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return p.returncode, p.stdout


def main():
    tmp = tempfile.mkdtemp()
    n = 48
    ring = os.path.join(tmp, "ring.stl")
    write_stl(ring, "ring", [np.asarray(t, float) for t in writeDieStl.ring(20.0, 8.0, 15.0, n)])
    c = Cavity(ring, "mm")
    expected = (polygon_area(n, 20.0) - polygon_area(n, 8.0)) * 15.0 * 1e-9
    check("ring: volume = (outer polygon - core polygon) x depth", abs(c.volume - expected) < 1e-12 * 1e3,
          f"{c.volume * 1e9:.6f} vs {expected * 1e9:.6f} mm3")
    check("ring: opening area = annulus of the two polygons",
          abs(c.opening_area() - (polygon_area(n, 20.0) - polygon_area(n, 8.0)) * 1e-6) < 1e-12)
    check("ring: placed with its top at z = 0 and 15 mm deep",
          abs(c.bounds()[1][2]) < 1e-15 and abs(c.bounds()[0][2] + 0.015) < 1e-12)
    check("ring: 2 n opening faces, 2 n floor faces, 4 n wall faces (outer wall and core)",
          (c.is_opening.sum(), c.is_floor.sum(), c.is_wall.sum()) == (2 * n, 2 * n, 4 * n),
          f"{c.is_opening.sum()}, {c.is_floor.sum()}, {c.is_wall.sum()}")
    loops = c.opening_loops()
    check("ring: the opening's outline is two loops of n points", sorted(len(l) for l in loops) == [n, n])
    lo, hi = np.array([-0.05, -0.04]), np.array([0.06, 0.04])
    t = table_triangles(loops, lo, hi)
    want = 0.11 * 0.08 - c.opening_area()
    check("ring: table area = rectangle - annulus (the core's top kept as an island)",
          abs(table_area(t) - want) < 1e-12, f"{table_area(t) * 1e6:.6f} vs {want * 1e6:.6f} mm2")
    core = polygon_area(n, 8.0) * 1e-6
    check("ring: without the island the table would miss the core's top (negative control)",
          abs(table_area(t) - core - want) > 0.5 * core)
    # table + walls + floors: one watertight surface with the rectangle's border as its only edge
    allt = np.concatenate([t, c.triangles(c.is_wall), c.triangles(c.is_floor)])
    corners = allt.reshape(-1, 3)
    _, first, index = np.unique(np.round(corners / 1e-9).astype(np.int64), axis=0, return_index=True,
                                return_inverse=True)
    v, f = corners[first], index.reshape(-1, 3)
    # Edges used by one triangle only (the orientation of the table does not matter here)
    und = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(und, axis=0, return_counts=True)
    edges = uniq[counts == 1]
    on_border = np.all((np.isclose(v[edges][:, :, 0], lo[0]) | np.isclose(v[edges][:, :, 0], hi[0])
                        | np.isclose(v[edges][:, :, 1], lo[1]) | np.isclose(v[edges][:, :, 1], hi[1])))
    check("ring: table, walls and floors share their edges (open edges only on the table's border)",
          len(edges) > 0 and on_border, f"{len(edges)} open edges")

    two = os.path.join(tmp, "two.stl")
    write_stl(two, "two", [np.asarray(x, float) for x in writeDieStl.two_level(40.0, 30.0, 12.0, 10.0, 24.0)])
    c2 = Cavity(two, "mm")
    check("twoLevel: volume 40 x 30 x 12 + 10 x 30 x 12 mm3", abs(c2.volume - 18000e-9) < 1e-15,
          f"{c2.volume * 1e9:.6f}")
    floors = c2.triangles(c2.is_floor)
    levels = sorted(set(np.round(floors[:, :, 2].ravel() * 1e3, 9)))
    check("twoLevel: floors at -12 and -24 mm", levels == [-24.0, -12.0], str(levels))
    t2 = table_triangles(c2.opening_loops(), lo, hi)
    check("twoLevel: table area = rectangle - 40 x 30 mm", abs(table_area(t2) - (0.11 * 0.08 - 1.2e-3)) < 1e-12)

    # Bad cavities: an open surface, a flipped triangle, a wrong unit, no opening
    tris = writeDieStl.ring(20.0, 8.0, 15.0, n)
    open_stl = os.path.join(tmp, "open.stl")
    write_stl(open_stl, "open", [np.asarray(x, float) for x in tris[:-1]])
    try:
        Cavity(open_stl, "mm")
        check("an open STL is refused", False)
    except CavityError as e:
        check("an open STL is refused naming the file and an open edge",
              "open.stl" in str(e) and "not a closed surface" in str(e) and "edge from" in str(e), str(e)[:160])
    flipped = [np.asarray(x, float) for x in tris]
    flipped[5] = flipped[5][::-1]
    flip_stl = os.path.join(tmp, "flip.stl")
    write_stl(flip_stl, "flip", flipped)
    flipped_cavity = Cavity(flip_stl, "mm")
    check("a triangle facing the wrong way is turned outward: the same volume and split",
          abs(flipped_cavity.volume - c.volume) < 1e-15 and flipped_cavity.is_floor.sum() == c.is_floor.sum()
          and flipped_cavity.is_opening.sum() == c.is_opening.sum())
    try:
        Cavity(ring, "m")
        check("40 m wide (mm read as m) is refused", False)
    except CavityError as e:
        check("a die 40 m wide (mm read as m) is refused naming its size and the unit",
              "40 m across" in str(e) and "unit" in str(e), str(e)[:120])
    try:
        Cavity(ring, "um")
        check("a die 40 um wide is refused", False)
    except CavityError as e:
        check("a die 40 um wide is refused", "across" in str(e))
    # A cavity whose top is a cone's apex (no flat top) has no opening
    cone = []
    base = writeDieStl._circle(10.0, -10.0, 16)
    apex = np.array([0.0, 0.0, 0.0])
    for k in range(16):
        cone.append((apex, base[k], base[(k + 1) % 16]))
    cone += writeDieStl._fan(base, np.array([0.0, 0.0, -10.0]), False)
    cone_stl = os.path.join(tmp, "cone.stl")
    write_stl(cone_stl, "cone", [np.asarray(x, float) for x in cone])
    try:
        Cavity(cone_stl, "mm")
        check("a cavity without a flat top is refused", False)
    except CavityError as e:
        check("a cavity without a flat top (no opening) is refused", "top plane" in str(e), str(e)[:100])

    # writeDieCase: a case from a dieDict, and its errors
    case = os.path.join(tmp, "case")
    os.makedirs(os.path.join(case, "system"))
    os.makedirs(os.path.join(case, "constant"))
    write_stl(os.path.join(case, "constant", "ring.stl"), "ring",
              [np.asarray(x, float) for x in writeDieStl.ring(20.0, 8.0, 20.0, n)])
    good = """die { cavity ("constant/ring.stl"); unit mm; }
shoe { type box; size (50 50 30); start (-50 0); }
motion { type passes; start 0.5; speed 0.05; distance 100; passes 2; pause 0.2; }
powder { mass 0.04; coarseGrain 10; waterContent 0.05; }
steps { air yes; aeration yes; lowerDieWall yes; }
results { regionGrid (2 2); regions { near (-20 -20 0 20); } }
"""

    def write_dict(text):
        with open(os.path.join(case, "system", "dieDict"), "w") as f:
            f.write("FoamFile { version 2.0; format ascii; class dictionary; object dieDict; }\n" + text)

    write_dict(good)
    rc, out = run([os.path.join(ROOT, "tools", "writeDieCase.py"), "-case", case], tmp)
    check("writeDieCase writes the ring's case", rc == 0, out.strip()[-200:])
    summary = json.load(open(os.path.join(case, "constant", "dieCase.json")))
    tl = summary["timeline_s"]
    check("two passes of 100 mm at 0.05 m/s with a 0.2 s pause end at 0.5 + 2 + 0.2 + 2 = 4.7 s",
          abs(tl["shoeStops"] - 4.7) < 1e-12, str(tl))
    check("the opening starts 0.3 s after the shoe stops and takes 1.2 x 20 mm / 0.05 m/s",
          abs(tl["opening"] - 5.0) < 1e-12 and abs(tl["openingEnds"] - (5.0 + 0.024 / 0.05)) < 1e-12)
    dem = open(os.path.join(case, "constant", "demProperties.orig")).read()
    check("demProperties: the second pass comes back (velocity -0.05 along x)",
          "velocity (0.05 0 0)" in dem and "velocity (-0.05 0 0)" in dem)
    check("demProperties: the cavity and 2 x 2 + 1 regions are output regions",
          "cavity { type stl;" in dem and dem.count("grid_") == 4 and "near { type box;" in dem)
    check("demProperties: the time step divides the air's 1 ms step (coarse grain 10: 6.25e-6 s)",
          "timeStep    6.25e-06;" in dem)
    check("demProperties: the capillary model with 5 % water", "waterContent   0.05;" in dem)
    for name in ("snappyHexMeshDict", "blockMeshDict", "topoSetDict", "createPatchDict", "controlDict.orig"):
        check(f"system/{name} written", os.path.isfile(os.path.join(case, "system", name)))
    u = open(os.path.join(case, "0.orig", "U")).read()
    check("aeration: 2 cm/s under the shoe until just before it moves (0.45 s), then closed",
          "(0.45 (0 0 0.02))" in u and "(0.475 (0 0 0))" in u)

    # A measured motion table: a shoe that slows down; positions relative to the start
    with open(os.path.join(case, "constant", "shoeMotion.csv"), "w") as f:
        f.write("time,x,y\n0 0 0\n0.5 0 0\n1.5 60 0\n2.5 100 0\n")
    write_dict(good.replace("motion { type passes; start 0.5; speed 0.05; distance 100; passes 2; pause 0.2; }",
                            'motion { type table; file "constant/shoeMotion.csv"; }'))
    rc, out = run([os.path.join(ROOT, "tools", "writeDieCase.py"), "-case", case], tmp)
    dem = open(os.path.join(case, "constant", "demProperties.orig")).read()
    check("a motion table becomes translations: 60 mm/s then 40 mm/s",
          rc == 0 and "start 0.5; end 1.5; velocity (0.06 0 0)" in dem and "start 1.5; end 2.5; velocity (0.04 0 0)" in dem,
          out.strip()[-200:])

    # A shoe of any shape: the closed STL surface of its inside (diefillpost/shoe.py)
    octagon = os.path.join(tmp, "octagonShoe.stl")
    write_stl(octagon, "octagonShoe", [np.asarray(x, float) for x in writeDieStl.cylinder(25.0, 30.0, 8)])
    sh = Shoe.from_stl(octagon, 1e-3, (-0.045, 0.01))
    wall, inside = sh.wall_triangles(), sh.region_triangles()
    check("STL shoe (octagon R = 25 mm, 30 mm high): footprint area 2 sqrt(2) R^2, volume area x height",
          abs(sh.area - polygon_area(8, 0.025)) < 1e-12 and abs(sh.volume - polygon_area(8, 0.025) * 0.03) < 1e-12,
          f"{sh.area * 1e6:.6f} mm2, {sh.volume * 1e6:.6f} cm3")
    check("STL shoe: placed with its bottom on the table (z = 0) and its footprint's box centred on the start",
          abs(inside[:, :, 2].min()) < 1e-15 and abs(inside[:, :, 2].max() - 0.03) < 1e-12
          and np.allclose(0.5 * (inside[:, :, :2].reshape(-1, 2).min(0) + inside[:, :, :2].reshape(-1, 2).max(0)),
                          [-0.045, 0.01], atol=1e-12))
    check("STL shoe: the wall is the surface without its 8 bottom faces (open on the table), the lid kept",
          len(inside) - len(wall) == 8 and np.all(wall[:, :, 2].max(axis=1) > 1e-9))
    probe = np.array([[-0.045, 0.01], [-0.045 + 0.022, 0.01], [-0.045 + 0.0245, 0.01], [-0.045 + 0.0185, 0.0285],
                      [-0.045 + 0.016, 0.026]])
    check("STL shoe: the table under it is the octagon (a corner's tip and an edge's midpoint told apart)",
          list(sh.covers(probe)) == [True, True, True, False, True], str(sh.covers(probe)))
    corners, quads = writeDieStl._box((-0.02, -0.015, 0.0), (0.02, 0.015, 0.025))
    write_stl(os.path.join(tmp, "boxShoe.stl"), "boxShoe",
              [corners[[q[0], q[1 + k], q[2 + k]]] for q in quads for k in (0, 1)])
    boxed = Shoe.from_stl(os.path.join(tmp, "boxShoe.stl"), 1.0, (0.0, 0.0))
    box = Shoe.box((0.04, 0.03, 0.025), (0.0, 0.0))
    area = lambda t: float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum())
    sides = np.array([t for t in boxed.wall_triangles() if np.ptp(t[:, 2]) > 0])
    grid = np.linspace(-0.03, 0.03, 13)
    check("an STL box shoe is the box shoe: the same footprint, volume, table faces under it, side walls",
          np.allclose(boxed.half, box.half) and abs(boxed.volume - box.volume) < 1e-15
          and abs(boxed.area - box.area) < 1e-15
          and boxed.boxes_over(grid, grid, 0.001) == box.boxes_over(grid, grid, 0.001)
          and len(box.boxes_over(grid, grid, 0.001)) == 5
          and abs(area(sides) - area(box.wall_triangles())) < 1e-15
          and abs(area(boxed.wall_triangles()) - area(sides) - 0.04 * 0.03) < 1e-15,
          f"{len(box.boxes_over(grid, grid, 0.001))} rows under the box")
    with open(octagon) as f:
        lines = f.read().splitlines()
    open_shoe = os.path.join(tmp, "openShoe.stl")
    first = min(i for i, line in enumerate(lines) if line.strip().startswith("facet"))
    with open(open_shoe, "w") as f:
        f.write("\n".join(lines[:first] + lines[first + 7:]) + "\n")
    try:
        Shoe.from_stl(open_shoe, 1e-3, (0, 0))
        check("an open shoe STL is refused", False)
    except ShoeError as e:
        check("an open shoe STL is refused, naming the file and 'not a closed surface'",
              "openShoe.stl" in str(e) and "closed" in str(e), str(e)[:120])

    shutil.copy(octagon, os.path.join(case, "constant", "octagonShoe.stl"))
    shutil.copy(open_shoe, os.path.join(case, "constant", "openShoe.stl"))
    stl_shoe = good.replace("shoe { type box; size (50 50 30); start (-50 0); }",
                            'shoe { type stl; file "constant/octagonShoe.stl"; start (-50 0); }')
    write_dict(stl_shoe)
    rc, out = run([os.path.join(ROOT, "tools", "writeDieCase.py"), "-case", case], tmp)
    dem = open(os.path.join(case, "constant", "demProperties.orig")).read()
    topo = open(os.path.join(case, "system", "topoSetDict")).read()
    summary = json.load(open(os.path.join(case, "constant", "dieCase.json")))
    check("writeDieCase with an STL shoe: its wall (shoe.stl) moves, the powder is inserted in its inside "
          "(shoeInside.stl), aeration under its footprint (boxToFace boxes)",
          rc == 0 and 'type stl; file "constant/triSurface/shoe.stl"' in dem
          and 'region   { type stl; file "constant/triSurface/shoeInside.stl"; }' in dem
          and "source boxToFace; boxes (" in topo and summary["shoe"]["type"] == "stl"
          and abs(summary["shoe"]["footprintArea_m2"] - polygon_area(8, 0.025)) < 1e-12, out.strip()[-200:])

    # A pre-compaction stamp: the opening's shape parked above the shoe, down to the table,
    # pressed 4 mm in at 0.02 m/s, held 0.1 s, back up; the opening after it
    stamped = good.replace("lowerDieWall yes;", "lowerDieWall yes; stamp { depth 4; speed 0.02; hold 0.1; }")
    write_dict(stamped)
    rc, out = run([os.path.join(ROOT, "tools", "writeDieCase.py"), "-case", case], tmp)
    summary = json.load(open(os.path.join(case, "constant", "dieCase.json")))
    dem = open(os.path.join(case, "constant", "demProperties.orig")).read()
    face = read_stl(os.path.join(case, "constant", "triSurface", "stamp.stl"))
    st, tl = summary["steps"]["stamp"], summary["timeline_s"]
    check("stamp: its face is the opening (area) at 1.2 x the shoe's height (36 mm)",
          rc == 0 and abs(table_area(face) - summary["openingArea_m2"]) < 1e-12
          and np.allclose(face[:, :, 2], 0.036, atol=1e-15), out.strip()[-200:])
    segments = [tuple(float(v) for v in m) for m in re.findall(
        r"(?:down|press|up) +\{ type translate; start ([-\d.e]+); end ([-\d.e]+); velocity \(0 0 ([-\d.e]+)\); \}", dem)]
    height = np.cumsum([(e - s) * v for s, e, v in segments]) + 0.036 if len(segments) == 3 else []
    check("stamp: down to the table, 4 mm into the die at 0.02 m/s, back up to where it waited",
          len(segments) == 3 and np.allclose(height, [0.0, -0.004, 0.036], atol=1e-9)
          and abs(segments[1][2] + 0.02) < 1e-15, str(segments))
    check("stamp: after the shoe stops and the powder settles (0.3 s), held 0.1 s; the opening 0.3 s after it is up",
          abs(st["comesDown_s"] - (tl["shoeStops"] + 0.3)) < 1e-12 and abs(st["released_s"] - st["pressed_s"] - 0.1) < 1e-12
          and abs(tl["opening"] - (st["up_s"] + 0.3)) < 1e-12 and tl["filled"] == tl["opening"]
          and abs(segments[2][0] - st["released_s"]) < 1e-9, str(st))

    # A stamp of given weight: 0.5 kg lowered from the table at 0.02 m/s (a load: the DEM moves
    # it under the powder's force), raised 0.4 s after it reached the table, stopped at half the
    # cavity's depth (20 mm deep: 10 mm) at the latest, back on the table by then + 10 mm / 0.02 m/s
    weighted = good.replace("lowerDieWall yes;", "lowerDieWall yes; stamp { mass 0.5; speed 0.02; hold 0.4; }")
    write_dict(weighted)
    rc, out = run([os.path.join(ROOT, "tools", "writeDieCase.py"), "-case", case], tmp)
    summary = json.load(open(os.path.join(case, "constant", "dieCase.json")))
    dem = open(os.path.join(case, "constant", "demProperties.orig")).read()
    st, tl = summary["steps"]["stamp"], summary["timeline_s"]
    load = re.search(r"press +\{ type load; start ([-\d.e]+); raise ([-\d.e]+); direction \(0 0 -1\); "
                     r"mass ([-\d.e]+); speed ([-\d.e]+); stroke ([-\d.e]+); \}", dem)
    moves = [tuple(float(v) for v in m) for m in re.findall(
        r"(?:down|up) +\{ type translate; start ([-\d.e]+); end ([-\d.e]+); velocity \(0 0 ([-\d.e]+)\); \}", dem)]
    load = [float(v) for v in load.groups()] if load else []
    check("stamp of given mass: a load of 0.5 kg from the table, raised after 0.4 s, stopped at 10 mm, then back up",
          rc == 0 and len(load) == 5 and len(moves) == 2 and st["mass_kg"] == 0.5 and abs(st["stroke_m"] - 0.01) < 1e-15
          and abs(load[0] - st["onTable_s"]) < 1e-9 and abs(load[1] - load[0] - 0.4) < 1e-9 and load[2] == 0.5
          and load[3] == 0.02 and abs(load[4] - 0.01) < 1e-12 and abs(moves[0][1] - load[0]) < 1e-9
          and 0 < moves[1][0] - (load[1] + load[4] / load[3]) < 1e-5
          and abs((moves[0][1] - moves[0][0]) * moves[0][2] + 0.036) < 1e-9
          and abs((moves[1][1] - moves[1][0]) * moves[1][2] - 0.036) < 1e-9
          and abs(st["pressed_s"] - (st["onTable_s"] + 0.2)) < 1e-12 and abs(tl["opening"] - (st["up_s"] + 0.3)) < 1e-12,
          out.strip()[-200:] + " " + str(load) + " " + str(moves))

    bad = [
        ("a stamp with a depth and a mass", stamped.replace("depth 4;", "depth 4; mass 1;"), "steps/stamp/mass"),
        ("a stamp of no mass", weighted.replace("mass 0.5;", "mass 0;"), "steps/stamp/mass"),
        ("a stamp without its depth", good.replace("lowerDieWall yes;", "lowerDieWall yes; stamp yes;"), "steps/stamp"),
        ("a stamp deeper than half the cavity", stamped.replace("depth 4;", "depth 10;"), "steps/stamp/depth"),
        ("a stamp with an unknown keyword", stamped.replace("hold 0.1;", "hold 0.1; force 5;"), "steps/stamp/force"),
        ("a stamp where the shoe stops over the opening",
         stamped.replace("distance 100; passes 2;", "distance 50; passes 1;"), "steps/stamp"),
        ("a misspelt keyword", good.replace("passes 2;", "pases 2;"), "motion/pases"),
        ("an unknown shoe type", good.replace("type box;", "type sphere;"), "shoe/type"),
        ("a negative mass", good.replace("mass 0.04;", "mass -1;"), "powder/mass"),
        ("more powder than the shoe holds", good.replace("mass 0.04;", "mass 4;"), "powder/mass"),
        ("a shoe path that never crosses the die", good.replace("start (-50 0);", "start (-50 60);"), "motion"),
        ("a shoe that starts over the opening", good.replace("start (-50 0);", "start (0 0);"), "shoe/start"),
        ("a wrong unit", good.replace("unit mm;", "unit m;"), "across"),
        ("an STL that does not exist", good.replace("ring.stl", "rign.stl"), "die/cavity"),
        ("a shoe STL that does not exist", stl_shoe.replace("octagonShoe.stl", "octagon.stl"), "shoe/file"),
        ("an open shoe STL", stl_shoe.replace("octagonShoe.stl", "openShoe.stl"), "not a closed surface"),
        ("a shoe STL with a box's keyword", stl_shoe.replace("start (-50 0); }", "start (-50 0); size (1 1 1); }"),
         "shoe/size"),
    ]
    for what, text, key in bad:
        write_dict(text)
        before = open(os.path.join(case, "constant", "demProperties.orig")).read()
        rc, out = run([os.path.join(ROOT, "tools", "writeDieCase.py"), "-case", case], tmp)
        after = open(os.path.join(case, "constant", "demProperties.orig")).read()
        check(f"{what} is refused (exit 2) naming system/dieDict and {key}, nothing written",
              rc == 2 and "system/dieDict" in out and key in out and before == after, out.strip()[-160:])

    passed = sum(results)
    print(f"{passed} passed, {len(results) - passed} failed")
    return 0 if passed == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
