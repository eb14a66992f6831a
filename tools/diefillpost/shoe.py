"""The feed shoe of a die filling (docs/own-die.md): a box, a cylinder, or a shoe of any shape
given as the closed STL surface of its inside (the space the powder fills), standing on the
table (z = 0) with the centre of its footprint's bounding box at a start position.

What a case needs from it: the footprint (bounding-box half sizes, area), the height and the
volume, the DEM wall (box: its four sides; STL: the surface without its bottom, which lies on
the table and is open), the insertion region (STL: the closed surface itself), and which
faces of the table lie under it (aeration).
"""
import math

import numpy as np

from .closedmesh import ClosedMesh, read_stl


class ShoeError(ValueError):
    """Bad shoe input; the message names the file and what was expected."""


class Shoe:
    """Shoe.box(size, start), Shoe.cylinder(radius, height, start) or
    Shoe.from_stl(path, scale, start); lengths in metres, start = (x, y) of the footprint's
    centre.  Attributes: kind ('box', 'cylinder', 'stl'), half (x, y half sizes of the
    footprint's bounding box), height, start, area (footprint), volume."""

    def __init__(self, kind, half, height, start, area, mesh=None, bottom=None):
        self.kind, self.half, self.height = kind, np.asarray(half, float), float(height)
        self.start, self.area = np.asarray(start, float), float(area)
        self.volume = self.area * self.height if mesh is None else float(mesh.volume)
        self._mesh, self._bottom = mesh, bottom

    @classmethod
    def box(cls, size, start):
        size = np.asarray(size, float)
        return cls("box", size[:2] / 2, size[2], start, size[0] * size[1])

    @classmethod
    def cylinder(cls, radius, height, start):
        return cls("cylinder", [radius, radius], height, start, math.pi * radius ** 2)

    @classmethod
    def from_stl(cls, path, scale, start, name=None):
        name = name or path
        try:
            tris = read_stl(path, scale)
        except OSError as e:
            raise ShoeError(f"{name}: cannot read the STL file ({e.strerror})")
        except ValueError as e:
            raise ShoeError(str(e))
        if not np.all(np.isfinite(tris)):
            raise ShoeError(f"{name}: a vertex is not a finite number")
        try:
            mesh = ClosedMesh(tris, name)
        except ValueError as e:
            raise ShoeError(f"{e} (the shoe's STL is the closed surface of its inside, bottom included)")
        lo, hi = mesh.lo, mesh.hi
        # Placed: bottom on the table, the footprint's box centred on the start position
        shift = np.array([start[0] - 0.5 * (lo[0] + hi[0]), start[1] - 0.5 * (lo[1] + hi[1]), -lo[2]])
        mesh = ClosedMesh(mesh.triangles + shift, name)
        tolerance = 1e-6 * float(np.max(hi - lo))
        n = mesh.normals / np.linalg.norm(mesh.normals, axis=1)[:, None]
        bottom = (n[:, 2] < -1 + 1e-6) & np.all(np.abs(mesh.triangles[:, :, 2]) <= tolerance, axis=1)
        t = mesh.triangles[bottom]
        area = float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum())
        if not area > 0:
            raise ShoeError(f"{name}: no face of the shoe lies flat at its lowest level, facing down: expected the "
                            f"shoe's open bottom (on the table) as the bottom of the closed surface")
        half = 0.5 * (mesh.hi[:2] - mesh.lo[:2])
        return cls("stl", half, mesh.hi[2] - mesh.lo[2], start, area, mesh, bottom)

    # ------------------------------------------------------------------ geometry for the case
    def wall_triangles(self):
        """The DEM wall as (F, 3, 3) triangles at the start position: the box's four sides or the
        STL surface without its bottom; None for the cylinder (an analytic wall)."""
        if self.kind == "box":
            (hx, hy), h = self.half, self.height
            c = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
            tris = []
            for k in range(4):
                (ax, ay), (bx, by) = c[k], c[(k + 1) % 4]
                p = [np.array([ax, ay, 0.0]), np.array([bx, by, 0.0]), np.array([bx, by, h]), np.array([ax, ay, h])]
                tris += [(p[0], p[1], p[2]), (p[0], p[2], p[3])]
            return np.array(tris) + np.array([self.start[0], self.start[1], 0.0])
        if self.kind == "stl":
            return self._mesh.triangles[~self._bottom]
        return None

    def region_triangles(self):
        """The closed surface of the shoe's inside (STL shoes: the insertion region)."""
        return self._mesh.triangles if self.kind == "stl" else None

    def covers(self, xy, inset=0.0):
        """Whether each point (N, 2) of the table lies under the shoe at its start, at least
        `inset` inside its footprint."""
        xy = np.asarray(xy, float).reshape(-1, 2)
        rel = xy - self.start
        if self.kind == "box":
            return np.all(np.abs(rel) <= self.half - inset, axis=1)
        if self.kind == "cylinder":
            return np.linalg.norm(rel, axis=1) <= self.half[0] - inset
        z = np.full((len(xy), 1), 1e-3 * self.height)
        ok = self._mesh.contains(np.hstack([xy, z]))
        if inset > 0:
            for dx, dy in ((inset, 0), (-inset, 0), (0, inset), (0, -inset)):
                ok &= self._mesh.contains(np.hstack([xy + [dx, dy], z]))
        return ok

    def boxes_over(self, x_centres, y_centres, inset):
        """Rectangles ((x0, y0), (x1, y1)) that hold exactly the grid points (x_centres x
        y_centres) under the shoe (`covers` with `inset`), one per run of points along x."""
        xs, ys = np.asarray(x_centres, float), np.asarray(y_centres, float)
        dx = 0.25 * (np.min(np.diff(xs)) if len(xs) > 1 else 1.0)
        dy = 0.25 * (np.min(np.diff(ys)) if len(ys) > 1 else 1.0)
        boxes = []
        for y in ys:
            under = self.covers(np.column_stack([xs, np.full(len(xs), y)]), inset)
            k = 0
            while k < len(xs):
                if not under[k]:
                    k += 1
                    continue
                first = k
                while k + 1 < len(xs) and under[k + 1]:
                    k += 1
                boxes.append(((xs[first] - dx, y - dy), (xs[k] + dx, y + dy)))
                k += 1
        return boxes
