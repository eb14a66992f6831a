#!/usr/bin/env python3
"""Writes a die-filling case for your own die from system/dieDict (docs/own-die.md).

    writeDieCase.py [-case DIR] [-coarseGrain L] [-summary]

Reads DIR/system/dieDict (the cavity as closed STL surfaces, the shoe, its motion, the
powder, the steps of the rig) and writes, in DIR:
  constant/triSurface/  cavity.stl (the cavity, placed: opening at z = 0, centred), table.stl
                        (the table with the opening cut out), dieWalls.stl (lowered with the
                        table), dieFloors.stl (the punches: they stay), opening.stl, airWalls.stl
                        (table + walls + floors: the air mesh's wall), shoe.stl (a box or STL shoe's
                        wall), shoeInside.stl (an STL shoe: its inside, the insertion region),
                        stamp.stl (with steps/stamp: the pre-compaction stamp's face)
  constant/demProperties.orig  the DEM: walls from those STL files, the shoe's motion, insertion
                        in the shoe, the timeline, output regions (the cavity, the region grid)
  system/blockMeshDict, snappyHexMeshDict, meshQualityDict, topoSetDict, createPatchDict
                        the air mesh from the same STL (blockMesh background + snappyHexMesh),
                        with air only
  system/controlDict.orig, 0.orig/  the air solver's time loop and fields, with air only
  constant/dieCase.json the derived figures (cavity volume, opening, timeline, regions) that
                        the post-processing reads
Errors name system/dieDict, the keyword and what was expected, and exit with status 2.
-coarseGrain L overrides powder/coarseGrain (the -quick setting of Allrun); -summary prints
the derived figures only (nothing written)."""
import json
import math
import os
import re
import shutil
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, positive, run_main  # noqa: E402
from diefillpost import foamdict, shoemotion  # noqa: E402
from diefillpost.cavity import LARGEST_DIE, SMALLEST_DIE, UNITS, Cavity, CavityError, table_triangles, write_stl  # noqa: E402
from diefillpost.shoe import Shoe, ShoeError  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAPER_CASE = os.path.join(REPO, "tutorials", "dieFilling")
F32_CLASSES = "( (0.355e-3 0.5e-3 5) (0.25e-3 0.355e-3 28) (0.18e-3 0.25e-3 49) (0.125e-3 0.18e-3 16) (0.09e-3 0.125e-3 2) )"
AIR_STEP = 1e-3              # s, the air's time step (system/controlDict)
DEM_STEP_PER_GRAIN = 6.25e-7  # s per unit of coarse grain: the paper case's rule (validation/README.md)
OPENING_SPEED = 0.05         # m/s, the die wall and table lowered (the quick paper case's)
SETTLE = 0.3                 # s after the last shoe motion before the opening, and after the opening
STAMP_SPEED = 0.01           # m/s, the pre-compaction stamp's default pressing speed
STAMP_APPROACH_SPEED = 0.2   # m/s, the stamp down to the table and back up
STAMP_HOLD = 0.2             # s, the stamp held at its depth (default)
STAMP_WEIGHT_SPEED = 0.02    # m/s, a stamp of given mass: lowered onto the powder no faster (default)
STAMP_WEIGHT_HOLD = 0.5      # s, a stamp of given mass: from the table until it is raised (default)


class DictError(ValueError):
    pass


class Reader:
    """Typed access to one sub-dictionary of dieDict; errors name the file and the keyword."""

    def __init__(self, d, path, where):
        self.d, self.path, self.where = d, path, where

    def fail(self, key, expected, got=None):
        got_text = "" if got is None else f", got {got!r}"
        raise DictError(f"{self.path}: {self.where}{'/' if self.where else ''}{key}: expected {expected}{got_text}")

    def has(self, key):
        return key in self.d

    def sub(self, key, required=True):
        v = self.d.get(key)
        if v is None and not required:
            return Reader({}, self.path, self.where + ("/" if self.where else "") + key)
        if not isinstance(v, dict):
            self.fail(key, "a sub-dictionary { ... }", v)
        return Reader(v, self.path, self.where + ("/" if self.where else "") + key)

    def number(self, key, default=None, low=None, low_open=False, high=None):
        v = self.d.get(key, default)
        if v is None:
            self.fail(key, "a number (missing)")
        if not isinstance(v, float) or not math.isfinite(v):
            self.fail(key, "a number", v)
        if low is not None and (v < low or (low_open and v == low)):
            self.fail(key, f"a number {'>' if low_open else '>='} {low:g}", v)
        if high is not None and v > high:
            self.fail(key, f"a number <= {high:g}", v)
        return v

    def word(self, key, choices, default=None):
        v = self.d.get(key, default)
        if v not in choices:
            self.fail(key, "one of " + ", ".join(choices), v)
        return v

    def switch(self, key, default):
        v = self.d.get(key, default)
        if v in (True, "yes", "on", "true"):
            return True
        if v in (False, "no", "off", "false"):
            return False
        self.fail(key, "yes or no", v)

    def vector(self, key, n, default=None):
        v = self.d.get(key, default)
        if not (isinstance(v, list) and len(v) == n and all(isinstance(x, float) and math.isfinite(x) for x in v)):
            self.fail(key, f"a list of {n} numbers, e.g. ({' '.join(['0'] * n)})", v)
        return np.array(v, float)

    def string_list(self, key):
        v = self.d.get(key)
        if isinstance(v, str):
            v = [v]
        if not (isinstance(v, list) and v and all(isinstance(x, str) for x in v)):
            self.fail(key, 'a list of file names, e.g. ("constant/geometry/part.stl")', v)
        return v

    def check_keys(self, allowed):
        for k in self.d:
            if k not in allowed:
                self.fail(k, "one of the keywords " + ", ".join(allowed) + " (unknown keyword)")


def raw_block(text, name):
    """The text of a top-level 'name { ... }' block of the dictionary (comments kept), or None."""
    m = re.search(r"(?m)^\s*" + re.escape(name) + r"\s*\{", text)
    if not m:
        return None
    depth, i = 0, m.end() - 1
    while i < len(text):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return text[m.start():i + 1].strip()
        i += 1
    return None


def shoe_path(motion, start_xy, scale, path):
    """The shoe's motion as translate segments [(t0, t1, (vx, vy))] and its positions at the
    segment ends; from passes (speed, distance, passes, pause) or a table (time, x, y)."""
    kind = motion.word("type", ["passes", "table"])
    if kind == "passes":
        motion.check_keys(["type", "start", "speed", "distance", "passes", "pause"])
        t = motion.number("start", 0.5, low=0.0)
        speed = motion.number("speed", low=0.0, low_open=True, high=5.0)
        distance = motion.number("distance", low=0.0, low_open=True) * scale
        passes = motion.number("passes", 1.0, low=1.0)
        if passes != int(passes):
            motion.fail("passes", "a whole number >= 1", passes)
        pause = motion.number("pause", 0.0, low=0.0)
        segments = []
        for k in range(int(passes)):
            direction = 1.0 if k % 2 == 0 else -1.0
            segments.append((t, t + distance / speed, (direction * speed, 0.0)))
            t += distance / speed + pause
        points = [(0.0, start_xy[0], start_xy[1])]
        x = start_xy[0]
        for (t0, t1, (vx, _)) in segments:
            x += vx * (t1 - t0)
            points += [(t0, points[-1][1], start_xy[1]), (t1, x, start_xy[1])]
        return segments, points
    motion.check_keys(["type", "file", "points"])
    key = "file" if motion.has("file") else "points"
    try:
        if motion.has("file"):
            name = motion.d["file"]
            rows = shoemotion.read_table(os.path.join(os.path.dirname(os.path.dirname(path)), name))
        else:
            rows = motion.d.get("points")
            if not (isinstance(rows, list) and all(isinstance(r, list) and len(r) in (2, 3)
                                                   and all(isinstance(v, float) for v in r) for r in rows)):
                motion.fail("points", "a list ((t x y) ...) of numbers, or a file", rows)
        segments, points = shoemotion.segments(rows, start_xy, scale, "the table")
    except DictError:
        raise
    except OSError as e:
        motion.fail(key, "a readable table of time [s], x, y", f"{motion.d.get('file')} ({e.strerror})")
    except ValueError as e:
        motion.fail(key, str(e))
    return segments, points


def fmt(v):
    return "(" + " ".join("%.9g" % x for x in v) + ")"


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-coarseGrain", type=positive)
    ap.add_argument("-summary", action="store_true")
    a = ap.parse_args()
    case = os.path.abspath(a.case)
    path = os.path.join(case, "system", "dieDict")
    rel = os.path.relpath(path, os.getcwd()) if path.startswith(os.getcwd()) else path
    if not os.path.isfile(path):
        print(f"writeDieCase: no {rel}: expected the die's description there (docs/own-die.md)", file=sys.stderr)
        return 2
    try:
        return write_case(case, path, rel, a)
    except (DictError, CavityError) as e:
        print(f"writeDieCase: {e}", file=sys.stderr)
        return 2


def write_case(case, path, rel, a):
    text = open(path).read()
    try:
        root = Reader(foamdict.read(path), rel, "")
    except Exception as e:   # the dictionary's syntax
        raise DictError(f"{rel}: cannot be read ({e})")
    root.check_keys(["die", "shoe", "motion", "powder", "steps", "results", "materials", "interactions",
                     "contactModel"])
    die = root.sub("die")
    die.check_keys(["cavity", "unit"])
    unit = die.word("unit", list(UNITS), "m")
    scale = UNITS[unit]
    files = [f if os.path.isabs(f) else os.path.join(case, f) for f in die.string_list("cavity")]
    for f, given in zip(files, die.string_list("cavity")):
        if not os.path.isfile(f):
            die.fail("cavity", "STL files that exist (relative to the case)", given)
    try:
        cavity = Cavity(files, unit)
    except CavityError as e:
        raise DictError(f"{rel}: die/cavity: {e}")
    lo, hi = cavity.bounds()
    olo, ohi = cavity.opening_bounds()
    depth = -lo[2]

    shoe_dict = root.sub("shoe")
    shoe_type = shoe_dict.word("type", ["box", "cylinder", "stl"])
    start = shoe_dict.vector("start", 2) * scale
    if shoe_type == "box":
        shoe_dict.check_keys(["type", "size", "start"])
        size = shoe_dict.vector("size", 3) * scale
        if np.any(size <= 0):
            shoe_dict.fail("size", "three lengths > 0", list(size / scale))
        shoe = Shoe.box(size, start)
    elif shoe_type == "cylinder":
        shoe_dict.check_keys(["type", "radius", "height", "start"])
        radius = shoe_dict.number("radius", low=0.0, low_open=True) * scale
        height = shoe_dict.number("height", low=0.0, low_open=True) * scale
        shoe = Shoe.cylinder(radius, height, start)
    else:
        shoe_dict.check_keys(["type", "file", "start"])
        given = shoe_dict.d.get("file")
        if not isinstance(given, str):
            shoe_dict.fail("file", 'the STL file of the shoe\'s inside, e.g. "constant/shoe.stl"', given)
        shoe_file = given if os.path.isabs(given) else os.path.join(case, given)
        if not os.path.isfile(shoe_file):
            shoe_dict.fail("file", "an STL file that exists (relative to the case)", given)
        try:
            shoe = Shoe.from_stl(shoe_file, scale, start, given)
        except ShoeError as e:
            raise DictError(f"{rel}: shoe/file: {e}")
        if not SMALLEST_DIE <= float(max(2 * shoe.half.max(), shoe.height)) <= LARGEST_DIE:
            shoe_dict.fail("file", f"a shoe {SMALLEST_DIE * 1e3:g} mm to {LARGEST_DIE:g} m across in unit {unit} "
                                   f"(it is {2 * shoe.half.max():.6g} x {shoe.height:.6g} m)", given)
    half, height = shoe.half, shoe.height
    segments, points = shoe_path(root.sub("motion"), start, scale, path)
    path_xy = np.array([[p[1], p[2]] for p in points])
    # The shoe must pass over the opening: its footprint overlaps the opening's box at some time
    crosses = False
    for (p, q) in zip(path_xy, path_xy[1:]):
        for s in np.linspace(0, 1, 200):
            c = p + s * (q - p)
            if np.all(c - half < ohi[:2]) and np.all(c + half > olo[:2]):
                crosses = True
                break
    if not crosses:
        root.sub("motion").fail("type", "a shoe path that passes over the die's opening (the shoe never covers "
                                        f"x {olo[0] / scale:.4g}..{ohi[0] / scale:.4g}, y {olo[1] / scale:.4g}.."
                                        f"{ohi[1] / scale:.4g} {unit})")
    start_inside = np.all(start - half < ohi[:2]) and np.all(start + half > olo[:2])
    if start_inside:
        shoe_dict.fail("start", "a start position where the shoe stands on the table beside the opening (it is "
                                "filled there)", list(start / scale))
    margin = 0.25 * max(half)
    table_lo = np.minimum(path_xy.min(axis=0) - half, olo[:2]) - margin
    table_hi = np.maximum(path_xy.max(axis=0) + half, ohi[:2]) + margin

    powder = root.sub("powder")
    powder.check_keys(["mass", "coarseGrain", "waterContent", "seed", "sizeDistribution", "material"])
    mass = powder.number("mass", low=0.0, low_open=True)
    grain = a.coarseGrain or powder.number("coarseGrain", 5.0, low=1.0)
    water = powder.number("waterContent", 0.0, low=0.0, high=0.3)
    seed = powder.number("seed", 1.0, low=0.0)
    steps = root.sub("steps", required=False)
    steps.check_keys(["air", "aeration", "lowerDieWall", "stamp"])
    air = steps.switch("air", True)
    aeration = steps.switch("aeration", False)
    lower = steps.switch("lowerDieWall", True)
    stamp = None
    if isinstance(steps.d.get("stamp"), dict):
        press = steps.sub("stamp")
        press.check_keys(["depth", "mass", "speed", "hold"])
        given = [k for k in ("depth", "mass") if k in press.d]
        if not given:
            press.fail("depth", f"depth D (the stamp pressed D {unit} below the table) or mass M (a stamp of "
                                "M kg resting on the powder under its weight)")
        if len(given) == 2:
            press.fail("mass", "either depth (driven to a depth) or mass (resting under its weight), not both",
                       "both")
        if given == ["depth"]:
            stamp = {"depth": press.number("depth", low=0.0, low_open=True) * scale,
                     "speed": press.number("speed", STAMP_SPEED, low=0.0, low_open=True, high=STAMP_APPROACH_SPEED),
                     "hold": press.number("hold", STAMP_HOLD, low=0.0)}
            if stamp["depth"] >= 0.5 * depth:
                press.fail("depth", f"a depth below the table (in {unit}) less than half the cavity's "
                                    f"{depth / scale:.4g} {unit}", stamp["depth"] / scale)
        else:
            # Lowered by a hoist onto the powder, resting under its weight, stopped at half the
            # cavity's depth at the latest (docs/walls.md, "A wall under load").
            stamp = {"mass": press.number("mass", low=0.0, low_open=True, high=1000.0),
                     "speed": press.number("speed", STAMP_WEIGHT_SPEED, low=0.0, low_open=True,
                                           high=STAMP_APPROACH_SPEED),
                     "hold": press.number("hold", STAMP_WEIGHT_HOLD, low=0.0, low_open=True),
                     "stroke": 0.5 * depth}
    elif steps.switch("stamp", False):
        steps.fail("stamp", "no, or stamp { depth D; speed V; hold T; }: how far below the table the stamp "
                            f"presses (D, in {unit}), at V m/s (default {STAMP_SPEED:g}), held T s (default "
                            f"{STAMP_HOLD:g}); or stamp {{ mass M; speed V; hold T; }}: a stamp of M kg lowered "
                            f"at V m/s (default {STAMP_WEIGHT_SPEED:g}) onto the powder, raised T s (default "
                            f"{STAMP_WEIGHT_HOLD:g}) after it reached the table", "yes")
    end_xy = path_xy[-1]
    if stamp and np.all(end_xy - half < ohi[:2]) and np.all(end_xy + half > olo[:2]):
        steps.fail("stamp", "no stamp, or a shoe path that ends beside the opening: the stamp comes down over "
                            f"the opening, where the shoe stops (its centre at x {end_xy[0] / scale:.4g}, "
                            f"y {end_xy[1] / scale:.4g} {unit})", "a stamp")
    if aeration and not air:
        steps.fail("aeration", "no when air is no (aeration blows air through the powder)")
    results = root.sub("results", required=False)
    results.check_keys(["regionGrid", "regions"])
    grid = results.vector("regionGrid", 2, [3.0, 3.0])
    if np.any(grid < 1) or np.any(grid != np.round(grid)):
        results.fail("regionGrid", "two whole numbers >= 1", list(grid))
    named = {}
    if results.has("regions"):
        regs = results.sub("regions")
        for name, box in regs.d.items():
            if not re.match(r"^[A-Za-z][A-Za-z0-9_]*$", name):
                regs.fail(name, "a region name of letters, digits and _")
            v = regs.vector(name, 4)
            if not (v[2] > v[0] and v[3] > v[1]):
                regs.fail(name, "(x0 y0 x1 y1) with x1 > x0 and y1 > y0", list(v))
            named[name] = v * scale

    # The shoe's powder: fill height at a loose packing 0.55 must fit in the shoe
    bulk = 2650.0 * 0.55
    if mass / bulk > 0.9 * shoe.volume:
        powder.fail("mass", f"at most {0.9 * shoe.volume * bulk:.4g} kg: {mass:g} kg at a packing of 0.55 fills "
                            f"{mass / bulk / shoe.volume * 100:.3g} % of the shoe's {shoe.volume * 1e6:.4g} cm3 "
                            f"({mass / (bulk * shoe.area) * 1e3:.3g} mm high in a shoe of {height * 1e3:.3g} mm)",
                    mass)
    # Timeline
    fill_end = 0.5 * segments[0][0] if segments[0][0] > 0 else 0.0
    pass_end = segments[-1][1]
    open_start = pass_end + SETTLE
    if stamp:
        # The stamp waits above the shoe, comes down to the table, presses to its depth, is
        # held there and goes back up; the die counts as filled SETTLE after that.
        stamp["park"] = 1.2 * height
        stamp["down"] = open_start
        stamp["onTable"] = stamp["down"] + stamp["park"] / STAMP_APPROACH_SPEED
        if "mass" in stamp:
            # From the table it hangs on the hoist (at most `speed`) until the powder carries
            # it; raised `hold` after it reached the table, back there within stroke / speed.
            # Its figures are taken over the hold's second half, when it rests.
            stamp["pressed"] = stamp["onTable"] + 0.5 * stamp["hold"]
            stamp["released"] = stamp["onTable"] + stamp["hold"]
            # (1 us later: clear of the load's end after the times are rounded to 9 digits)
            stamp["back"] = stamp["released"] + stamp["stroke"] / stamp["speed"] + 1e-6
            stamp["up"] = stamp["back"] + stamp["park"] / STAMP_APPROACH_SPEED
        else:
            stamp["pressed"] = stamp["onTable"] + stamp["depth"] / stamp["speed"]
            stamp["released"] = stamp["pressed"] + stamp["hold"]
            stamp["up"] = stamp["released"] + (stamp["park"] + stamp["depth"]) / STAMP_APPROACH_SPEED
        open_start = stamp["up"] + SETTLE
    open_end = open_start + 1.2 * depth / OPENING_SPEED
    end_time = (open_end if lower else open_start) + SETTLE
    wave = max(0.02, min(0.2, 0.5 * max(segments[0][0], 0.1) / 3))
    step = DEM_STEP_PER_GRAIN * grain
    if air:
        step = AIR_STEP / math.ceil(AIR_STEP / step * (1 - 1e-12))
    summary = {
        "dieDict": rel, "unit": unit, "cavityFiles": die.string_list("cavity"),
        "cavityVolume_m3": cavity.volume, "cavityDepth_m": depth,
        "cavityBounds_m": [list(map(float, lo)), list(map(float, hi))],
        "openingBounds_m": [list(map(float, olo[:2])), list(map(float, ohi[:2]))],
        "openingArea_m2": cavity.opening_area(), "tableBounds_m": [list(map(float, table_lo)), list(map(float, table_hi))],
        "shoe": {"type": shoe_type, "halfSize_m": list(map(float, half)), "height_m": float(height),
                 "start_m": list(map(float, start)), "footprintArea_m2": shoe.area, "volume_m3": shoe.volume},
        "shoePath": [{"time_s": p[0], "x_m": p[1], "y_m": p[2]} for p in points],
        "timeline_s": {"shoeFilled": fill_end, "shoeMoves": segments[0][0], "shoeStops": pass_end,
                       "filled": open_start, "opening": open_start if lower else None,
                       "openingEnds": open_end if lower else None, "end": end_time},
        "powder": {"mass_kg": mass, "coarseGrain": grain, "waterContent": water, "seed": int(seed)},
        "steps": {"air": air, "aeration": aeration, "lowerDieWall": lower,
                  "stamp": None if not stamp else {
                      **({"mass_kg": stamp["mass"], "stroke_m": stamp["stroke"], "backOnTable_s": stamp["back"]}
                         if "mass" in stamp else {"depth_m": stamp["depth"]}),
                      "speed_m_s": stamp["speed"], "hold_s": stamp["hold"],
                      "parkedAt_m": stamp["park"], "comesDown_s": stamp["down"], "onTable_s": stamp["onTable"],
                      "pressed_s": stamp["pressed"], "released_s": stamp["released"], "up_s": stamp["up"]}},
        "timeStep_s": step, "regionGrid": [int(grid[0]), int(grid[1])],
        "regions_m": {k: list(map(float, v)) for k, v in named.items()},
    }
    if a.summary:
        print(json.dumps(summary, indent=1))
        return 0

    tri_dir = os.path.join(case, "constant", "triSurface")
    os.makedirs(tri_dir, exist_ok=True)
    table = table_triangles(cavity.opening_loops(), table_lo, table_hi)
    write_stl(os.path.join(tri_dir, "cavity.stl"), "cavity", cavity.triangles())
    write_stl(os.path.join(tri_dir, "opening.stl"), "opening", cavity.triangles(cavity.is_opening))
    write_stl(os.path.join(tri_dir, "table.stl"), "table", table)
    write_stl(os.path.join(tri_dir, "dieWalls.stl"), "dieWalls", cavity.triangles(cavity.is_wall))
    write_stl(os.path.join(tri_dir, "dieFloors.stl"), "dieFloors", cavity.triangles(cavity.is_floor))
    write_stl(os.path.join(tri_dir, "airWalls.stl"), "walls",
              np.concatenate([table, cavity.triangles(cavity.is_wall), cavity.triangles(cavity.is_floor)]))
    if stamp:
        # The stamp's face: the opening itself, waiting above the shoe (its reference position)
        face = cavity.triangles(cavity.is_opening).copy()
        face[:, :, 2] += stamp["park"]
        write_stl(os.path.join(tri_dir, "stamp.stl"), "stamp", face)
    shoe_wall_triangles, shoe_inside = shoe.wall_triangles(), shoe.region_triangles()
    if shoe_wall_triangles is not None:
        write_stl(os.path.join(tri_dir, "shoe.stl"), "shoe", shoe_wall_triangles)
    if shoe_inside is not None:
        write_stl(os.path.join(tri_dir, "shoeInside.stl"), "shoeInside", shoe_inside)

    # ---- constant/demProperties ----
    motion_lines = shoemotion.motion_block(segments)
    opening = (f"motion {{ open {{ type translate; start {open_start:.9g}; end {open_end:.9g}; "
               f"velocity (0 0 {-OPENING_SPEED:g}); }} }}" if lower else "")
    if shoe_type != "cylinder":
        shoe_wall = "type stl; file \"constant/triSurface/shoe.stl\"; material steel;   // at its start position"
    else:
        shoe_wall = (f"type cylinder; material steel; side inside;\n        axisPoint {fmt([start[0], start[1], 0.0])};"
                     f" axis (0 0 1); radius {half[0]:.9g}; range (0 {height:.9g});")
    inset = 0.01 * min(half)
    if shoe_type == "box":
        region = (f"type box; min {fmt([start[0] - half[0] + inset, start[1] - half[1] + inset, 0.0005 * height])}; "
                  f"max {fmt([start[0] + half[0] - inset, start[1] + half[1] - inset, 0.98 * height])};")
    elif shoe_type == "stl":
        region = "type stl; file \"constant/triSurface/shoeInside.stl\";"
    else:
        region = (f"type cylinder; axisPoint {fmt([start[0], start[1], 0.0])}; axis (0 0 1); radius "
                  f"{half[0] - inset:.9g}; range ({0.0005 * height:.9g} {0.98 * height:.9g});")
    domain_lo = [table_lo[0], table_lo[1], lo[2] - 0.2 * depth - 0.01]
    domain_hi = [table_hi[0], table_hi[1], 1.5 * height]
    materials = raw_block(text, "materials") or (
        "materials\n{\n    sand  { youngsModulus 5e6;  poissonRatio 0.3; density 2650; }\n"
        "    steel { youngsModulus 7e10; poissonRatio 0.3; density 7800; }\n}")
    interactions = raw_block(text, "interactions") or (
        "// Paper Table 2\ninteractions\n{\n    sand-sand   { restitution 0.10; friction 0.70; rollingFriction 0.50; }\n"
        "    sand-steel  { restitution 0.15; friction 0.61; rollingFriction 0.50; }\n"
        "    steel-steel { restitution 0.50; friction 0.50; rollingFriction 0.0; }\n}")
    contact = raw_block(text, "contactModel") or "contactModel { normal hertz; tangential history; rolling cdt; }"
    sizes = raw_block(text.split("powder", 1)[1] if "powder" in text else "", "sizeDistribution") or \
        f"sizeDistribution {{ classes {F32_CLASSES}; }}"
    material = powder.d.get("material", "sand")
    cohesion = ("" if water == 0 else
                f"cohesion\n{{\n    model          capillary;\n    waterContent   {water:g};\n"
                f"    surfaceTension 0.072;\n    contactAngle   0;\n}}\n")
    regions = ["        cavity { type stl; file \"constant/triSurface/cavity.stl\"; }"]
    nx, ny = int(grid[0]), int(grid[1])
    for i in range(nx):
        for j in range(ny):
            x0 = olo[0] + (ohi[0] - olo[0]) * i / nx
            x1 = olo[0] + (ohi[0] - olo[0]) * (i + 1) / nx
            y0 = olo[1] + (ohi[1] - olo[1]) * j / ny
            y1 = olo[1] + (ohi[1] - olo[1]) * (j + 1) / ny
            regions.append(f"        grid_{i}_{j} {{ type box; min {fmt([x0, y0, lo[2] - 1e-6])}; "
                           f"max {fmt([x1, y1, 0.0])}; }}")
    for name, v in named.items():
        regions.append(f"        {name} {{ type box; min {fmt([v[0], v[1], lo[2] - 1e-6])}; max {fmt([v[2], v[3], 0.0])}; }}")
    regions_text = "\n".join(regions)
    stamp_wall = ""
    if stamp:
        a_, v_ = STAMP_APPROACH_SPEED, stamp["speed"]
        if "mass" in stamp:
            press_text = (f"            press {{ type load; start {stamp['onTable']:.9g}; raise {stamp['released']:.9g}; "
                          f"direction (0 0 -1); mass {stamp['mass']:.9g}; speed {v_:g}; "
                          f"stroke {stamp['stroke']:.9g}; }}\n")
            up_start = stamp["back"]
        else:
            press_text = (f"            press {{ type translate; start {stamp['onTable']:.9g}; end {stamp['pressed']:.9g}; "
                          f"velocity (0 0 {-v_:g}); }}\n")
            up_start = stamp["released"]
        stamp_wall = (
            "    // The pre-compaction stamp: the opening's shape, parked above the shoe\n"
            "    stamp\n    {\n        type stl; file \"constant/triSurface/stamp.stl\"; material steel;\n"
            "        motion\n        {\n"
            f"            down  {{ type translate; start {stamp['down']:.9g}; end {stamp['onTable']:.9g}; "
            f"velocity (0 0 {-a_:g}); }}\n"
            + press_text +
            f"            up    {{ type translate; start {up_start:.9g}; end {stamp['up']:.9g}; "
            f"velocity (0 0 {a_:g}); }}\n"
            "        }\n    }\n")
    dem = f"""FoamFile {{ version 2.0; format ascii; class dictionary; object demProperties; }}
// Written by writeDieCase.py from {rel}; edit that file and run ./Allrun again.
// Timeline: shoe filled by {fill_end:.4g} s; shoe moves {segments[0][0]:.4g}-{pass_end:.4g} s;
// {"stamp down " + f"{stamp['down']:.4g} s, " + (f"{stamp['mass']:.4g} kg resting on the powder {stamp['onTable']:.4g}-{stamp['released']:.4g} s" if "mass" in stamp else f"pressed {stamp['depth'] * 1e3:.4g} mm {stamp['onTable']:.4g}-{stamp['pressed']:.4g} s") + f", up by {stamp['up']:.4g} s; " if stamp else ""}{"die wall and table lowered " + f"{open_start:.4g}-{open_end:.4g} s; " if lower else ""}end {end_time:.4g} s.

simulation
{{
    timeStep    {step:.9g};
    endTime     {end_time:.9g};
    gravity     (0 0 -9.81);
    domain      {{ min {fmt(domain_lo)}; max {fmt(domain_hi)}; }}
}}

{contact}

coarseGrain {{ factor {grain:g}; }}

{cohesion}
{materials}

{interactions}

walls
{{
    table     {{ type stl; file "constant/triSurface/table.stl"; material steel; {opening} }}
    dieWalls  {{ type stl; file "constant/triSurface/dieWalls.stl"; material steel; {opening} }}
    dieFloors {{ type stl; file "constant/triSurface/dieFloors.stl"; material steel; }}
{stamp_wall}    shoe
    {{
        {shoe_wall}
        motion
        {{
{motion_lines}
        }}
    }}
}}

insertion
{{
    powder
    {{
        material {material};
        mass     {mass:g};
        region   {{ {region} }}
        {sizes}
        seed         {int(seed)};
        waveInterval {wave:.4g};
    }}
}}

output
{{
    fieldInterval   {max(0.05, round(end_time / 40, 2)):g};
    logInterval     0.02;
    restartInterval 0.5;
    regions
    {{
{regions_text}
    }}
}}
"""
    os.makedirs(os.path.join(case, "constant"), exist_ok=True)
    # Allrun's source of constant/demProperties (tutorial_prepare copies it; a user's edit of the
    # copy is caught by its guard)
    with open(os.path.join(case, "constant", "demProperties.orig"), "w") as f:
        f.write(dem)
    with open(os.path.join(case, "constant", "dieCase.json"), "w") as f:
        json.dump(summary, f, indent=1)
    if air:
        write_air(case, cavity, table_lo, table_hi, lo, shoe, aeration, segments, end_time, grain)
    print(f"writeDieCase: {rel}: cavity {cavity.volume * 1e6:.4g} cm3, {depth * 1e3:.4g} mm deep, opening "
          f"{(ohi[0] - olo[0]) * 1e3:.4g} x {(ohi[1] - olo[1]) * 1e3:.4g} mm; shoe {shoe_type}, {len(segments)} "
          f"motion segment(s) {segments[0][0]:.4g}-{pass_end:.4g} s; {mass * 1e3:g} g at coarse grain {grain:g}; "
          f"end {end_time:.4g} s; {'air' if air else 'vacuum'}")
    return 0


def write_air(case, cavity, table_lo, table_hi, lo, shoe, aeration, segments, end_time, grain):
    system = os.path.join(case, "system")
    start, half, height, shoe_type = shoe.start, shoe.half, shoe.height, shoe.kind
    # Air cells: three of the largest parcels across, or 8 across the opening's smaller side where
    # that is finer, but never smaller than a parcel (unresolved coupling: a cell holds parcels).
    olo, ohi = cavity.opening_bounds()
    parcel = 0.5e-3 * grain
    cell = max(min(3 * parcel, min(ohi[:2] - olo[:2]) / 8), parcel)
    top = 1.25 * height
    n_below = max(2, math.ceil(-lo[2] / cell) + 1)
    n_above = max(4, math.ceil(top / cell))
    z_lo = -n_below * cell
    # The background box inside the table by a fraction of a cell: the table cuts through it
    box_lo = table_lo + 0.3 * cell
    box_hi = table_hi - 0.3 * cell
    nx, ny = max(4, math.ceil((box_hi[0] - box_lo[0]) / cell)), max(4, math.ceil((box_hi[1] - box_lo[1]) / cell))
    v = lambda x, y, z: f"({x:.9g} {y:.9g} {z:.9g})"
    z_top = n_above * cell
    verts = []
    for z in (z_lo, 0.0, z_top):
        verts += [v(box_lo[0], box_lo[1], z), v(box_hi[0], box_lo[1], z), v(box_hi[0], box_hi[1], z),
                  v(box_lo[0], box_hi[1], z)]
    header = "FoamFile {{ version 2.0; format ascii; class dictionary; object {}; }}\n// Written by writeDieCase.py\n\n"
    with open(os.path.join(system, "blockMeshDict"), "w") as f:
        f.write(header.format("blockMeshDict"))
        f.write("scale 1;\nvertices\n(\n    " + "\n    ".join(verts) + "\n);\n")
        f.write(f"blocks\n(\n    hex (0 1 2 3 4 5 6 7) ({nx} {ny} {n_below}) simpleGrading (1 1 1)\n"
                f"    hex (4 5 6 7 8 9 10 11) ({nx} {ny} {n_above}) simpleGrading (1 1 1)\n);\n")
        f.write("boundary\n(\n    atmosphere\n    {\n        type patch;\n        faces\n        (\n"
                "            (8 11 10 9) (4 8 9 5) (5 9 10 6) (6 10 11 7) (7 11 8 4)\n"
                "            (0 3 2 1) (0 1 5 4) (1 2 6 5) (2 3 7 6) (3 0 4 7)\n        );\n    }\n);\n")
    # A point in the air above the table, away from the shoe's start
    inside = [0.5 * (box_lo[0] + box_hi[0]) + 0.123 * cell, 0.5 * (box_lo[1] + box_hi[1]) + 0.137 * cell,
              0.5 * z_top + 0.149 * cell]
    with open(os.path.join(system, "snappyHexMeshDict"), "w") as f:
        f.write(header.format("snappyHexMeshDict"))
        f.write(f"""// Castellated only: a cell of the background mesh is kept whole or removed (the air sees the
// cavity in cells of the air mesh; the DEM's walls are the STL itself).  Cells snapped to the
// surface came out distorted next to the opening's rim, where the air solver's balance of
// pressure and gravity failed (32 m/s in the first millisecond of the ring example).
castellatedMesh true;
snap            false;
addLayers       false;
geometry
{{
    airWalls.stl {{ type triSurfaceMesh; name walls; }}
}}
castellatedMeshControls
{{
    maxLocalCells 2000000;
    maxGlobalCells 8000000;
    minRefinementCells 0;
    maxLoadUnbalance 0.10;
    nCellsBetweenLevels 2;
    features ();
    refinementSurfaces {{ walls {{ level (0 0); patchInfo {{ type wall; }} }} }}
    resolveFeatureAngle 30;
    refinementRegions {{ }}
    locationInMesh {v(*inside)};
    allowFreeStandingZoneFaces true;
}}
snapControls
{{
    nSmoothPatch 3;
    tolerance 2.0;
    nSolveIter 50;
    nRelaxIter 5;
    nFeatureSnapIter 10;
    implicitFeatureSnap true;
    explicitFeatureSnap false;
    multiRegionFeatureSnap false;
}}
addLayersControls {{ layers {{ }} relativeSizes true; expansionRatio 1.0; finalLayerThickness 0.3; minThickness 0.1;
    nGrow 0; featureAngle 60; nRelaxIter 3; nSmoothSurfaceNormals 1; nSmoothNormals 3; nSmoothThickness 10;
    maxFaceThicknessRatio 0.5; maxThicknessToMedialRatio 0.3; minMedialAxisAngle 90; nBufferCellsNoExtrude 0;
    nLayerIter 50; }}
meshQualityControls {{ #include "meshQualityDict" }}
mergeTolerance 1e-6;
""")
    with open(os.path.join(system, "meshQualityDict"), "w") as f:
        f.write(header.format("meshQualityDict"))
        f.write("maxNonOrtho 65;\nmaxBoundarySkewness 20;\nmaxInternalSkewness 4;\nmaxConcave 80;\n"
                "minVol 1e-13;\nminTetQuality 1e-15;\nminArea -1;\nminTwist 0.02;\nminDeterminant 0.001;\n"
                "minFaceWeight 0.05;\nminVolRatio 0.01;\nminTriangleTwist -1;\nnSmoothScale 4;\n"
                "errorReduction 0.75;\nrelaxed { maxNonOrtho 75; }\n")
    # dieTop: the faces across the opening (air leaving the die); aeration: the table under the shoe's start
    r = 0.98 * min(half)
    if shoe_type == "box":
        under = (f"source boxToFace; box {v(start[0] - half[0] + 0.25 * cell, start[1] - half[1] + 0.25 * cell, -0.5 * cell)} "
                 f"{v(start[0] + half[0] - 0.25 * cell, start[1] + half[1] - 0.25 * cell, 0.5 * cell)};")
    elif shoe_type == "stl":
        # The table's faces under the shoe, row by row of the background mesh (boxToFace tests face centres)
        xs = box_lo[0] + (np.arange(nx) + 0.5) * (box_hi[0] - box_lo[0]) / nx
        ys = box_lo[1] + (np.arange(ny) + 0.5) * (box_hi[1] - box_lo[1]) / ny
        boxes = shoe.boxes_over(xs, ys, 0.25 * cell)
        under = "source boxToFace; boxes (" + " ".join(
            f"{v(a[0], a[1], -0.5 * cell)} {v(b[0], b[1], 0.5 * cell)}" for a, b in boxes) + ");"
    else:
        under = (f"source cylinderToFace; p1 {v(start[0], start[1], -0.5 * cell)}; p2 {v(start[0], start[1], 0.5 * cell)}; "
                 f"radius {r - 0.75 * cell:.9g};")
    with open(os.path.join(system, "topoSetDict"), "w") as f:
        f.write(header.format("topoSetDict"))
        f.write(f"""actions
(
    {{ name dieTop; type faceZoneSet; action new; source searchableSurfaceToFaceZone;
      surfaceType triSurfaceMesh; surfaceName opening.stl; }}
    {{ name aeration; type faceSet; action new; source patchToFace; patch walls; }}
    {{ name aeration; type faceSet; action subset; {under} }}
);
""")
    with open(os.path.join(system, "createPatchDict"), "w") as f:
        f.write(header.format("createPatchDict"))
        f.write("pointSync false;\npatches\n(\n    { name aeration; patchInfo { type patch; } "
                "constructFrom set; set aeration; }\n);\n")
    # controlDict
    src = open(os.path.join(PAPER_CASE, "system", "controlDict")).read()
    src = re.sub(r"(?m)^endTime\s+[^;]*;.*$", f"endTime         {end_time:.9g};", src)
    src = src.replace("// The air of the die-filling case;", "// Written by writeDieCase.py: the air of your die's case;")
    with open(os.path.join(system, "controlDict.orig"), "w") as f:
        f.write(src)
    for name in ("fvSchemes", "fvSolution"):
        shutil.copyfile(os.path.join(PAPER_CASE, "system", name), os.path.join(system, name))
    for name in ("couplingProperties", "transportProperties", "turbulenceProperties"):
        shutil.copyfile(os.path.join(PAPER_CASE, "constant", name), os.path.join(case, "constant", name))
    orig = os.path.join(case, "0.orig")
    os.makedirs(orig, exist_ok=True)
    for name in ("U", "p", "alpha.air"):
        shutil.copyfile(os.path.join(PAPER_CASE, "0.orig", name), os.path.join(orig, name))
    # Aeration through the plate under the shoe until just before it moves, or closed
    u = open(os.path.join(orig, "U")).read()
    t_close = segments[0][0]
    table_text = (f"table ( (0 (0 0 0.02)) ({0.9 * t_close:.6g} (0 0 0.02)) ({0.95 * t_close:.6g} (0 0 0)) "
                  f"(1000 (0 0 0)) )" if aeration else "table ( (0 (0 0 0)) (1000 (0 0 0)) )")
    u = re.sub(r"(?m)^(\s*uniformValue\s+)table.*$", lambda m: m.group(1) + table_text + ";", u)
    with open(os.path.join(orig, "U"), "w") as f:
        f.write(u)


if __name__ == "__main__":
    run_main(main)
