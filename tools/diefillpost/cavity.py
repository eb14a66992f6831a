"""A die cavity from a closed STL surface: read, check, place, split into the walls a die
filling needs (docs/own-die.md).

The cavity is the volume the powder fills: a closed surface whose top faces lie in one
horizontal plane, the die's opening in the table.  Split by the outward normal n of each
face (outward: out of the cavity volume):
  opening  the top faces (n = +z, in the plane of the top): no wall, the powder falls through;
  floors   faces that hold the powder from below (n_z < -0.5: the lower punches, steps);
           they stay where they are when the die wall is lowered;
  walls    every other face (the die wall, cores, tapers); lowered with the table.
The table is the plane of the opening around it: a rectangle with the opening cut out,
triangulated by ear clipping on the opening's own boundary vertices, so that table and walls
share their edges (the air mesh needs one watertight surface; the DEM does not mind).
"""
import math
import os

import numpy as np

from .closedmesh import ClosedMesh, read_stl as _read_stl

UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "inch": 0.0254}
SMALLEST_DIE = 1e-3   # m: a cavity smaller than this, or larger than LARGEST_DIE, is a unit mistake
LARGEST_DIE = 1.0


class CavityError(ValueError):
    """Bad cavity input; the message names the file and what was expected."""


def read_stl(path):
    """Triangles (F, 3, 3) of an ASCII or binary STL file."""
    try:
        return _read_stl(path)
    except OSError as e:
        raise CavityError(f"{path}: cannot read the STL file ({e.strerror})")
    except ValueError as e:
        raise CavityError(str(e))


def write_stl(path, name, triangles):
    """ASCII STL of (F, 3, 3) triangles; the facet normals from the vertex order.  Written
    under a temporary name and renamed: a reader never sees half a file."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(f"solid {name}\n")
        for a, b, c in triangles:
            n = np.cross(b - a, c - a)
            length = np.linalg.norm(n)
            n = n / length if length > 0 else n
            f.write("  facet normal %.9g %.9g %.9g\n    outer loop\n" % tuple(n))
            for p in (a, b, c):
                f.write("      vertex %.12g %.12g %.12g\n" % tuple(p))
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")
    os.replace(tmp, path)


class Cavity:
    """A closed cavity surface in metres, its opening at z = 0.

    Cavity(paths, unit="m", place=True): reads the STL files (together one closed surface, or
    several disjoint closed surfaces), scales by the unit, and with place=True moves it so that
    its top lies at z = 0 and its opening's bounding box is centred on x = y = 0."""

    def __init__(self, paths, unit="m", place=True):
        if isinstance(paths, str):
            paths = [paths]
        if unit not in UNITS:
            raise CavityError(f"unit '{unit}': expected one of {', '.join(UNITS)}")
        self.paths = list(paths)
        names = ", ".join(self.paths)
        tris = np.concatenate([read_stl(p) for p in self.paths]) * UNITS[unit]
        if not np.all(np.isfinite(tris)):
            raise CavityError(f"{names}: a vertex is not a finite number")
        extent = tris.reshape(-1, 3).max(axis=0) - tris.reshape(-1, 3).min(axis=0)
        width = float(extent.max())
        if not SMALLEST_DIE <= width <= LARGEST_DIE:
            raise CavityError(
                f"{names}: with unit '{unit}' the cavity is {width:.6g} m across; expected {SMALLEST_DIE * 1e3:g} mm "
                f"to {LARGEST_DIE:g} m: check the unit (the STL's numbers are {width / UNITS[unit]:.6g} across)")
        self.tolerance = 1e-6 * width
        try:
            # welded, checked closed, turned outward (closedmesh.py)
            mesh = ClosedMesh(tris, names)
        except ValueError as e:
            raise CavityError(str(e) + ("" if unit == "m" else f" (coordinates in m; the file's are in {unit})"))
        self.vertices, self.faces, self.volume = mesh.vertices.copy(), mesh.faces, mesh.volume
        top = self.vertices[:, 2].max()
        if place:
            self.vertices = self.vertices - np.array([0.0, 0.0, top])
            top = 0.0
        self._split(top)
        if place:
            lo, hi = self.opening_bounds()
            self.vertices = self.vertices - np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.0])
        self.vertices[self.vertices[:, 2] > top - self.tolerance, 2] = top

    def normals(self):
        """The faces' outward unit normals."""
        v = self.vertices
        n = np.cross(v[self.faces[:, 1]] - v[self.faces[:, 0]], v[self.faces[:, 2]] - v[self.faces[:, 0]])
        return n / np.linalg.norm(n, axis=1)[:, None]

    def _split(self, top):
        n = self.normals()
        z = self.vertices[self.faces][:, :, 2]
        self.is_opening = (n[:, 2] > 1 - 1e-6) & np.all(np.abs(z - top) <= self.tolerance, axis=1)
        self.is_floor = (n[:, 2] < -0.5) & ~self.is_opening
        self.is_wall = ~self.is_opening & ~self.is_floor
        names = ", ".join(self.paths)
        if not self.is_opening.any():
            raise CavityError(f"{names}: no face of the cavity lies flat in its top plane, facing up: expected the "
                              f"die's opening as the top of the closed surface (the table's plane)")
        if not self.is_floor.any():
            raise CavityError(f"{names}: no face holds the powder from below (outward normal pointing down): "
                              f"expected a closed cavity with a bottom")

    def triangles(self, mask=None):
        f = self.faces if mask is None else self.faces[mask]
        return self.vertices[f]

    def opening_bounds(self):
        pts = self.vertices[self.faces[self.is_opening]].reshape(-1, 3)
        return pts.min(axis=0), pts.max(axis=0)

    def bounds(self):
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    def opening_area(self):
        t = self.triangles(self.is_opening)
        return float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum())

    def opening_loops(self):
        """The opening's boundary as closed loops of (x, y) points (vertex order along each loop)."""
        f = self.faces[self.is_opening]
        directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        pairs = {(int(a), int(b)) for a, b in directed}
        boundary = [(a, b) for a, b in pairs if (b, a) not in pairs]
        nxt = {}
        for a, b in boundary:
            if a in nxt:
                raise CavityError(f"{', '.join(self.paths)}: the opening's outline touches itself at a vertex "
                                  f"(two openings meeting at a point); expected openings apart")
            nxt[a] = b
        loops, seen = [], set()
        for start in sorted(nxt):
            if start in seen:
                continue
            loop, v = [], start
            while v not in seen:
                seen.add(v)
                loop.append(v)
                v = nxt[v]
            loops.append(self.vertices[loop][:, :2].copy())
        return loops


# ---- the table: a rectangle with the opening cut out, by ear clipping -------------------------

def _area2(p):
    x, y = p[:, 0], p[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _inside_loop(point, loop):
    """Even-odd test of a point against a closed polygon."""
    x, y = point
    xs, ys = loop[:, 0], loop[:, 1]
    xn, yn = np.roll(xs, -1), np.roll(ys, -1)
    crosses = (ys > y) != (yn > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = xs + (y - ys) * (xn - xs) / (yn - ys)
    return bool(np.count_nonzero(crosses & (xi > x)) % 2)


def _bridge(outer, hole):
    """Splices a hole (clockwise) into the outer polygon (counter-clockwise) through a
    mutually visible pair of vertices (Eberly, 'Triangulation by ear clipping', 2002)."""
    m_index = int(np.argmax(hole[:, 0]))
    m = hole[m_index]
    best, best_x = None, math.inf
    n = len(outer)
    for i in range(n):
        a, b = outer[i], outer[(i + 1) % n]
        if (a[1] - m[1]) * (b[1] - m[1]) > 0 or a[1] == b[1]:
            continue
        x = a[0] + (m[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        if m[0] <= x < best_x:
            best_x, best = x, i
    if best is None:
        raise CavityError("the opening reaches beyond the table (no table edge to the right of it)")
    a, b = outer[best], outer[(best + 1) % n]
    p_index = best if a[0] > b[0] else (best + 1) % n
    i_point = np.array([best_x, m[1]])
    if not np.allclose(outer[p_index], i_point):
        # A reflex vertex inside the triangle (M, I, P) may hide P: take the one closest in angle to the ray.
        p = outer[p_index]
        tri = (m, i_point, p) if _cross(m, i_point, p) > 0 else (m, p, i_point)
        best_angle = None
        for k in range(n):
            q = outer[k]
            if _cross(outer[k - 1], q, outer[(k + 1) % n]) >= 0 or k == p_index:   # convex, or P itself
                continue
            if all(_cross(tri[j], tri[(j + 1) % 3], q) >= 0 for j in range(3)):
                angle = abs(math.atan2(q[1] - m[1], q[0] - m[0]))
                if best_angle is None or angle < best_angle:
                    best_angle, p_index = angle, k
    hole_walk = np.concatenate([hole[m_index:], hole[:m_index + 1]])
    return np.concatenate([outer[:p_index + 1], hole_walk, outer[p_index:p_index + 1], outer[p_index + 1:]])


def _ear_clip(poly):
    """Triangles (index triples into poly) of a simple counter-clockwise polygon (bridged
    holes allowed: repeated points)."""
    idx = list(range(len(poly)))
    tris = []
    guard = 0
    while len(idx) > 3:
        n = len(idx)
        clipped = False
        for k in range(n):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % n]
            a, b, c = poly[i0], poly[i1], poly[i2]
            if _cross(a, b, c) <= 0:
                continue
            ok = True
            for j in idx:
                if j in (i0, i1, i2):
                    continue
                q = poly[j]
                if np.array_equal(q, a) or np.array_equal(q, b) or np.array_equal(q, c):
                    continue
                if _cross(a, b, q) >= 0 and _cross(b, c, q) >= 0 and _cross(c, a, q) >= 0:
                    ok = False
                    break
            if ok:
                tris.append((i0, i1, i2))
                del idx[k]
                clipped = True
                break
        if not clipped:
            # Only collinear runs left (zero-area ears): drop a middle point of one.
            for k in range(n):
                if _cross(poly[idx[k - 1]], poly[idx[k]], poly[idx[(k + 1) % n]]) == 0:
                    del idx[k]
                    clipped = True
                    break
        guard += 1
        if not clipped or guard > 4 * len(poly) ** 2:
            raise CavityError("the table around the opening could not be triangulated (an outline that "
                              "crosses itself?)")
    tris.append(tuple(idx))
    return tris


def polygon_with_holes(outer, holes):
    """Triangles (T, 3, 2) covering the polygon `outer` minus the `holes` (loops of (x, y))."""
    outer = outer if _area2(outer) > 0 else outer[::-1]
    holes = [h if _area2(h) < 0 else h[::-1] for h in holes]
    poly = outer.copy()
    for h in sorted(holes, key=lambda h: -h[:, 0].max()):
        poly = _bridge(poly, h)
    return np.array([[poly[i] for i in t] for t in _ear_clip(poly)])


def _outline(lo, hi, nx, ny):
    """The box [lo, hi]'s outline, counter-clockwise, through the nodes of an nx x ny grid."""
    xs, ys = np.linspace(lo[0], hi[0], nx + 1), np.linspace(lo[1], hi[1], ny + 1)
    return np.array([[x, ys[0]] for x in xs[:-1]] + [[xs[-1], y] for y in ys[:-1]]
                    + [[x, ys[-1]] for x in xs[:0:-1]] + [[xs[0], y] for y in ys[:0:-1]])


def table_triangles(loops, lower, upper, z=0.0, spacing=None):
    """The table (T, 3, 3): the rectangle [lower, upper] in x, y minus the opening, whose
    outline is `loops`; islands of the table inside the opening (the top of a core) included.

    Triangles of bounded size: a wall's triangles are found by their bounding boxes, and a
    triangle as large as the table is a candidate for every particle on it (the ring example
    spent 80 % of its DEM time in that search with a plain ear clipping of the rectangle).
    So the rectangle is a grid of squares about `spacing` wide (default: a quarter of the
    opening's smaller width), two triangles each, except a frame of grid cells around the
    opening, which is ear-clipped with the opening cut out, through the grid's nodes on its
    border (the squares and the frame share their edges)."""
    pts = np.concatenate(loops)
    olo, ohi = pts.min(axis=0), pts.max(axis=0)
    if spacing is None:
        spacing = 0.25 * float(np.min(ohi - olo))
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    nx = max(1, int(math.ceil((upper[0] - lower[0]) / spacing)))
    ny = max(1, int(math.ceil((upper[1] - lower[1]) / spacing)))
    xs, ys = np.linspace(lower[0], upper[0], nx + 1), np.linspace(lower[1], upper[1], ny + 1)
    # The frame: the grid cells that the opening's box, one cell wider on each side, touches.
    i0 = max(0, int(np.searchsorted(xs, olo[0], "right")) - 2)
    i1 = min(nx, int(np.searchsorted(xs, ohi[0], "left")) + 1)
    j0 = max(0, int(np.searchsorted(ys, olo[1], "right")) - 2)
    j1 = min(ny, int(np.searchsorted(ys, ohi[1], "left")) + 1)
    for loop in loops:
        if not (np.all(loop[:, 0] > lower[0]) and np.all(loop[:, 0] < upper[0])
                and np.all(loop[:, 1] > lower[1]) and np.all(loop[:, 1] < upper[1])):
            raise CavityError("the die's opening reaches the edge of the table: expected a table larger than the "
                              "opening on every side")
    squares = []
    for i in range(nx):
        for j in range(ny):
            if i0 <= i < i1 and j0 <= j < j1:
                continue
            a, b = np.array([xs[i], ys[j]]), np.array([xs[i + 1], ys[j]])
            c, d = np.array([xs[i + 1], ys[j + 1]]), np.array([xs[i], ys[j + 1]])
            squares += [(a, b, c), (a, c, d)]
    frame = _outline(np.array([xs[i0], ys[j0]]), np.array([xs[i1], ys[j1]]), i1 - i0, j1 - j0)
    rect = frame
    depth = [sum(_inside_loop(loop[0], other) for j, other in enumerate(loops) if j != i)
             for i, loop in enumerate(loops)]
    # Even depth: an outline of the opening (a hole of the table or of an island); odd: an island's edge.
    pieces = [polygon_with_holes(rect, [l for l, d in zip(loops, depth) if d == 0])]
    for loop, d in zip(loops, depth):
        if d % 2 == 1:
            inner = [l for l, dd in zip(loops, depth) if dd == d + 1 and _inside_loop(l[0], loop)]
            pieces.append(polygon_with_holes(loop, inner))
    if squares:
        pieces.append(np.array(squares))
    flat = np.concatenate(pieces)
    return np.concatenate([flat, np.full(flat.shape[:2] + (1,), z)], axis=2)
