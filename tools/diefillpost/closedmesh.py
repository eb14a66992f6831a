"""A die cavity given as a closed triangulated surface (an STL file): reading it,
checking that it is closed, which points lie inside, the cavity's depth along vertical
lines, its exact volume under each cell of a plan-view grid, and its volume in the
cells of a 3-D grid.

Inside is decided by casting a vertical ray from each point and counting the surface
crossings above it (odd: inside).  The count is made robust with a symbolic
perturbation: a ray that passes exactly through an edge or a vertex of the projected
triangulation is counted as if it were moved an infinitesimal step along (1, eps) in
plan view, so that it meets exactly one of the triangles that share the edge (each edge
function is evaluated once, in a canonical vertex order, so that two triangles sharing
an edge see the same value).  Triangles standing vertically (the walls) are never met
by a vertical ray and play no part.  The parity is thus exact for any closed surface:
a ring with its core, a cavity with two levels, a gear.

The volume under a plan-view cell is exact: by the divergence theorem the volume of the
cavity inside the vertical prism over the cell is the sum over the surface, clipped to
the prism, of z n_z dA (the prism's own walls are vertical and add nothing), i.e. of
each clipped piece's signed projected area times the height of its centroid.  This
needs the triangles oriented consistently; a surface whose triangles are not is
reoriented (per connected part, outward: positive volume)."""
import re

import numpy as np

_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")
_BINARY = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])


def read_stl(path, scale=1.0):
    """The triangles of an STL file (ASCII or binary) as an (M, 3, 3) array, times
    `scale`.  A file that is neither, or holds no triangle, or a coordinate that is not
    a finite number, is a ValueError naming it."""
    with open(path, "rb") as f:
        data = f.read()
    tri = None
    if len(data) >= 84:
        n = int.from_bytes(data[80:84], "little")
        if n > 0 and len(data) == 84 + 50 * n:
            tri = np.frombuffer(data, dtype=_BINARY, count=n, offset=84)["vertices"].astype(float)
    if tri is None:
        if not data.lstrip().lower().startswith(b"solid"):
            raise ValueError(f"'{path}' is not an STL file: expected an ASCII STL ('solid', then 'facet ... "
                             "outer loop', three 'vertex X Y Z' and 'endloop endfacet' per triangle) or a binary "
                             "one (80-byte header, triangle count, 50 bytes per triangle)")
        found = _VERTEX.findall(data)
        try:
            v = np.array(found, dtype=float)
        except ValueError:
            bad = next(t for t in (x for row in found for x in row) if not _is_number(t))
            raise ValueError(f"'{path}': '{bad.decode(errors='replace')}' after 'vertex' is not a number") from None
        if len(v) % 3:
            raise ValueError(f"'{path}': {len(v)} vertices, not a multiple of 3; expected three per facet")
        tri = v.reshape(-1, 3, 3)
    if len(tri) == 0:
        raise ValueError(f"'{path}' holds no triangle")
    if not np.all(np.isfinite(tri)):
        raise ValueError(f"'{path}' has a vertex coordinate that is not a finite number")
    return tri * float(scale)


def _is_number(token):
    try:
        float(token)
    except ValueError:
        return False
    return True


def ball_points(shells=4, directions=32):
    """Points in the unit ball (shells x directions, 128 by default), each standing for
    an equal part of its volume: equal-volume shells, near-uniform directions (a
    Fibonacci spiral, turned differently in each shell), then each coordinate moved to
    the quantiles of the ball's marginal density 3/4 (1 - x^2), so that the share of
    the points on one side of any plane x, y or z = const is the ball's within 1/(2N)
    (0.4 % of a sphere with 128 points; a cell's corner is met within 4 %)."""
    rng = np.random.default_rng(12345)
    edges = (np.arange(shells + 1) / shells) ** (1.0 / 3.0)
    radius = np.sqrt(0.6 * (edges[1:] ** 5 - edges[:-1] ** 5) / (edges[1:] ** 3 - edges[:-1] ** 3))
    k = np.arange(directions) + 0.5
    z = 1 - 2 * k / directions
    phi = np.pi * (1 + 5 ** 0.5) * k
    d = np.column_stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z])
    pts = np.vstack([r * d @ np.linalg.qr(rng.normal(size=(3, 3)))[0].T for r in radius])
    q = (np.arange(len(pts)) + 0.5) / len(pts)
    quantile = 2 * np.sin(np.arcsin(2 * q - 1) / 3)   # solves (2 + 3x - x^3)/4 = q
    for a in range(3):
        pts[np.argsort(pts[:, a], kind="stable"), a] = quantile
    return pts


def _clip(poly, axis, value, keep_below):
    """The part of a convex polygon (list of (x, y, z)) on one side of the plane
    coordinate `axis` = value (z follows linearly)."""
    out = []
    n = len(poly)
    for i in range(n):
        p, q = poly[i], poly[(i + 1) % n]
        dp, dq = p[axis] - value, q[axis] - value
        p_in = dp <= 0 if keep_below else dp >= 0
        q_in = dq <= 0 if keep_below else dq >= 0
        if p_in:
            out.append(p)
        if p_in != q_in and dp != dq:
            t = dp / (dp - dq)
            point = tuple(p[k] + t * (q[k] - p[k]) for k in range(3))
            point = tuple(value if k == axis else point[k] for k in range(3))
            out.append(point)
    return out


def _area_and_moment(poly):
    """Signed projected area (x-y, counter-clockwise positive) of a planar polygon and
    the integral of z over it (exact: z is linear on the polygon)."""
    area, moment = 0.0, 0.0
    x0, y0, z0 = poly[0]
    for k in range(1, len(poly) - 1):
        (x1, y1, z1), (x2, y2, z2) = poly[k], poly[k + 1]
        a = 0.5 * ((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0))
        area += a
        moment += a * (z0 + z1 + z2) / 3.0
    return area, moment


class ClosedMesh:
    """A closed triangulated surface.  `ClosedMesh.from_stl(path)` reads and checks it;
    attributes: triangles (M, 3, 3), outward oriented; volume; lo, hi (bounding box)."""

    def __init__(self, triangles, name="the surface"):
        tri = np.asarray(triangles, float).reshape(-1, 3, 3)
        self.name = name
        lo, hi = tri.reshape(-1, 3).min(0), tri.reshape(-1, 3).max(0)
        size = float(np.max(hi - lo))
        if not size > 0:
            raise ValueError(f"'{name}' has no extent: all its vertices are one point")
        # Weld the vertices that coincide (to 1e-9 of the surface's size), drop
        # triangles that collapse to a line or a point.
        tol = 1e-9 * size
        keys = np.round((tri.reshape(-1, 3) - lo) / tol).astype(np.int64)
        _, first, index = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        index = index.reshape(-1, 3)
        vertices = tri.reshape(-1, 3)[first]
        faces = index
        area = 0.5 * np.linalg.norm(np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]],
                                             vertices[faces[:, 2]] - vertices[faces[:, 0]]), axis=1)
        good = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2]) & (area > 0)
        self.dropped = int(np.count_nonzero(~good))
        faces = faces[good]
        if len(faces) < 4:
            raise ValueError(f"'{name}' has {len(faces)} triangles of non-zero area: not a closed surface")
        self._check_closed(vertices, faces)
        faces = self._orient(vertices, faces)
        self.vertices, self.faces = vertices, faces
        self.triangles = vertices[faces]
        self.lo, self.hi = self.triangles.reshape(-1, 3).min(0), self.triangles.reshape(-1, 3).max(0)
        a, b, c = self.triangles[:, 0], self.triangles[:, 1], self.triangles[:, 2]
        self.volume = float(np.sum(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0)
        self.normals = np.cross(b - a, c - a)
        self._prepare_rays()

    @classmethod
    def from_stl(cls, path, scale=1.0):
        return cls(read_stl(path, scale), path)

    # ---------------------------------------------------------------- checks
    def _check_closed(self, vertices, faces):
        edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        unique, counts = np.unique(edges, axis=0, return_counts=True)
        bad = counts != 2
        if bad.any():
            e = unique[np.argmax(bad)]
            open_edges, shared = int(np.count_nonzero(counts == 1)), int(np.count_nonzero(counts > 2))
            what = []
            if open_edges:
                what.append(f"{open_edges} edge{'s' if open_edges > 1 else ''} of only one triangle (a hole)")
            if shared:
                what.append(f"{shared} edge{'s' if shared > 1 else ''} of more than two triangles")
            p, q = vertices[e[0]], vertices[e[1]]
            raise ValueError(f"'{self.name}' is not a closed surface: {' and '.join(what)}, e.g. the edge from "
                             f"({p[0]:.6g} {p[1]:.6g} {p[2]:.6g}) to ({q[0]:.6g} {q[1]:.6g} {q[2]:.6g}); expected "
                             "every edge shared by exactly two triangles (the cavity's walls, its base and the top "
                             "cap over its opening, no gap)")

    def _orient(self, vertices, faces):
        """Faces turned so that each shared edge is walked once each way, and each
        connected part encloses a positive volume (normals outward)."""
        directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        owner = np.repeat(np.arange(len(faces)), 3)
        key = np.sort(directed, axis=1)
        order = np.lexsort((key[:, 1], key[:, 0]))
        # each undirected edge appears exactly twice (checked): pairs are neighbours in `order`
        first, second = order[0::2], order[1::2]
        same_way = directed[first, 0] == directed[second, 0]   # both triangles walk it a -> b
        faces = faces.copy()
        if same_way.any():
            neighbours = [[] for _ in range(len(faces))]
            for i, j, s in zip(owner[first], owner[second], same_way):
                neighbours[i].append((j, s))
                neighbours[j].append((i, s))
            flip = np.full(len(faces), -1, int)
            for start in range(len(faces)):
                if flip[start] >= 0:
                    continue
                flip[start] = 0
                stack = [start]
                while stack:
                    i = stack.pop()
                    for j, s in neighbours[i]:
                        want = flip[i] ^ int(s)
                        if flip[j] < 0:
                            flip[j] = want
                            stack.append(j)
                        elif flip[j] != want:
                            raise ValueError(f"'{self.name}' cannot be oriented (a Moebius-like surface): not the "
                                             "boundary of a volume")
            faces[flip == 1] = faces[flip == 1][:, [0, 2, 1]]
        # one connected part after another: outward (positive volume)
        part = self._parts(faces)
        a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
        signed = np.einsum("ij,ij->i", a, np.cross(b, c))
        volume = np.bincount(part, weights=signed)
        turn = volume[part] < 0
        faces[turn] = faces[turn][:, [0, 2, 1]]
        return faces

    @staticmethod
    def _parts(faces):
        """The connected part (by shared vertices) of each face."""
        n = int(faces.max()) + 1
        parent = np.arange(n)

        def root(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for f in faces:
            r0 = root(f[0])
            for v in f[1:]:
                r = root(v)
                if r != r0:
                    parent[r] = r0
        roots = np.array([root(f[0]) for f in faces])
        return np.unique(roots, return_inverse=True)[1]

    # ------------------------------------------------------- vertical rays
    def _prepare_rays(self):
        t = self.triangles
        xy, z = t[:, :, :2], t[:, :, 2]
        area2 = ((xy[:, 1, 0] - xy[:, 0, 0]) * (xy[:, 2, 1] - xy[:, 0, 1])
                 - (xy[:, 2, 0] - xy[:, 0, 0]) * (xy[:, 1, 1] - xy[:, 0, 1]))
        keep = area2 != 0                                   # vertical triangles: never met
        xy, z, area2 = xy[keep], z[keep], area2[keep]
        ccw = area2 > 0
        order = np.where(ccw[:, None], [0, 1, 2], [0, 2, 1])
        xy = np.take_along_axis(xy, order[:, :, None], axis=1)
        z = np.take_along_axis(z, order, axis=1)
        self._ray = {"xy": xy, "z": z, "area2": np.abs(area2),
                     "lo": xy.min(axis=1), "hi": xy.max(axis=1)}
        # each edge u -> v (opposite vertex k) of the counter-clockwise triangle, evaluated from its
        # lexicographically smaller end (the same value for both triangles of a shared edge)
        edges = []
        for k, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):
            u, v = xy[:, i], xy[:, j]
            u_first = (u[:, 0] < v[:, 0]) | ((u[:, 0] == v[:, 0]) & (u[:, 1] < v[:, 1]))
            start = np.where(u_first[:, None], u, v)
            delta = np.where(u_first[:, None], v - u, u - v)
            sign = np.where(u_first, 1.0, -1.0)
            dx, dy = v[:, 0] - u[:, 0], v[:, 1] - u[:, 1]
            # a point on the edge counts when the interior (to the left of u -> v) lies
            # towards (1, eps): the ray moved by that infinitesimal step meets this triangle
            tie = (dy < 0) | ((dy == 0) & (dx > 0))
            edges.append((start, delta, sign, tie))
        self._edges = edges

    def crossings(self, xy):
        """Where the vertical lines through the points `xy` (P, 2) cross the surface:
        (line index, z) arrays, in no particular order; each line crosses it an even
        number of times."""
        xy = np.asarray(xy, float).reshape(-1, 2)
        r = self._ray
        order = np.argsort(xy[:, 0], kind="stable")
        xs, ys = xy[order, 0], xy[order, 1]
        i0 = np.searchsorted(xs, r["lo"][:, 0], "left")
        i1 = np.searchsorted(xs, r["hi"][:, 0], "right")
        lines, heights = [], []
        for t in np.nonzero(i1 > i0)[0]:
            px, py = xs[i0[t]:i1[t]], ys[i0[t]:i1[t]]
            near = np.nonzero((py >= r["lo"][t, 1]) & (py <= r["hi"][t, 1]))[0]
            if len(near) == 0:
                continue
            px, py = px[near], py[near]
            inside = np.ones(len(near), bool)
            weight = []
            for start, delta, sign, tie in self._edges:
                e = sign[t] * (delta[t, 0] * (py - start[t, 1]) - delta[t, 1] * (px - start[t, 0]))
                inside &= (e > 0) | ((e == 0) & tie[t])
                weight.append(e)
            if not inside.any():
                continue
            z = r["z"][t]
            w = [wk[inside] for wk in weight]
            lines.append(order[i0[t] + near[inside]])
            heights.append((w[0] * z[0] + w[1] * z[1] + w[2] * z[2]) / r["area2"][t])
        if not lines:
            return np.zeros(0, int), np.zeros(0)
        return np.concatenate(lines), np.concatenate(heights)

    def contains(self, points):
        """Whether each point (N, 3) lies inside the closed surface (an odd number of
        crossings above it)."""
        p = np.asarray(points, float).reshape(-1, 3)
        inside = np.zeros(len(p), bool)
        near = np.nonzero(np.all((p >= self.lo) & (p <= self.hi), axis=1))[0]
        if len(near) == 0:
            return inside
        line, z = self.crossings(p[near, :2])
        above = np.bincount(line, weights=z > p[near[line], 2], minlength=len(near))
        inside[near] = above.astype(np.int64) % 2 == 1
        return inside

    def intervals(self, xy):
        """The parts of the vertical lines through `xy` that lie inside: (line, z_low,
        z_high) arrays."""
        line, z = self.crossings(xy)
        order = np.lexsort((z, line))
        line, z = line[order], z[order]
        count = np.bincount(line, minlength=len(np.asarray(xy).reshape(-1, 2)))
        if np.any(count % 2):
            # cannot happen for a closed surface; a line with an odd count is left out
            good = (count % 2 == 0)[line]
            line, z = line[good], z[good]
        return line[0::2], z[0::2], z[1::2]

    def depth(self, xy):
        """The length of each vertical line through `xy` inside the cavity."""
        n = len(np.asarray(xy).reshape(-1, 2))
        line, z0, z1 = self.intervals(xy)
        return np.bincount(line, weights=z1 - z0, minlength=n)

    def layer_lengths(self, xy, z_edges):
        """(P, nz): the length of each vertical line inside the cavity within each layer
        z_edges[k] <= z < z_edges[k + 1]."""
        xy = np.asarray(xy, float).reshape(-1, 2)
        z_edges = np.asarray(z_edges, float)
        line, z0, z1 = self.intervals(xy)
        out = np.zeros((len(xy), len(z_edges) - 1))
        for k in range(len(z_edges) - 1):
            length = np.clip(np.minimum(z1, z_edges[k + 1]) - np.maximum(z0, z_edges[k]), 0, None)
            out[:, k] = np.bincount(line, weights=length, minlength=len(xy))
        return out

    # ------------------------------------------------------- plan-view cells
    def column_volumes(self, x_edges, y_edges):
        """Exact volume of the cavity over each cell of the plan-view grid (nx, ny), and
        the fraction of each cell's area under the cavity's upward-facing surface (its
        opening, for a die)."""
        x_edges, y_edges = np.asarray(x_edges, float), np.asarray(y_edges, float)
        nx, ny = len(x_edges) - 1, len(y_edges) - 1
        volume = np.zeros((nx, ny))
        up_area = np.zeros((nx, ny))
        nz = self.normals[:, 2]
        for t in np.nonzero(nz != 0)[0]:
            tri = self.triangles[t]
            ix0 = max(int(np.searchsorted(x_edges, tri[:, 0].min(), "right")) - 1, 0)
            ix1 = min(int(np.searchsorted(x_edges, tri[:, 0].max(), "left")), nx)
            iy0 = max(int(np.searchsorted(y_edges, tri[:, 1].min(), "right")) - 1, 0)
            iy1 = min(int(np.searchsorted(y_edges, tri[:, 1].max(), "left")), ny)
            rest = [tuple(v) for v in tri]
            rest = _clip(_clip(rest, 0, x_edges[0], False), 0, x_edges[-1], True)
            for i in range(ix0, ix1):
                if len(rest) < 3:
                    break
                strip = _clip(rest, 0, x_edges[i + 1], True)
                rest = _clip(rest, 0, x_edges[i + 1], False)
                strip = _clip(_clip(strip, 1, y_edges[0], False), 1, y_edges[-1], True)
                for j in range(iy0, iy1):
                    if len(strip) < 3:
                        break
                    piece = _clip(strip, 1, y_edges[j + 1], True)
                    strip = _clip(strip, 1, y_edges[j + 1], False)
                    if len(piece) < 3:
                        continue
                    area, moment = _area_and_moment(piece)
                    volume[i, j] += moment
                    if nz[t] > 0:
                        up_area[i, j] += area
        cell = np.outer(np.diff(x_edges), np.diff(y_edges))
        return volume, np.clip(up_area / cell, 0, 1)

    def cell_volumes(self, x_edges, y_edges, z_edges, samples=8, lines_per_pass=200000):
        """Volume of the cavity in each cell (nx, ny, nz) of a rectilinear grid: exact along
        z, from samples x samples vertical lines per cell in plan view (taken a few rows of
        cells at a time, at most about `lines_per_pass` lines)."""
        x_edges, y_edges, z_edges = (np.asarray(e, float) for e in (x_edges, y_edges, z_edges))
        nx, ny, nz = len(x_edges) - 1, len(y_edges) - 1, len(z_edges) - 1
        s = (np.arange(samples) + 0.5) / samples
        ys = (y_edges[:-1, None] + np.diff(y_edges)[:, None] * s).ravel()
        out = np.zeros((nx, ny, nz))
        rows = max(1, lines_per_pass // (samples * samples * ny))
        for i0 in range(0, nx, rows):
            i1 = min(nx, i0 + rows)
            xs = (x_edges[i0:i1, None] + np.diff(x_edges)[i0:i1, None] * s).ravel()
            X, Y = np.meshgrid(xs, ys, indexing="ij")
            lengths = self.layer_lengths(np.column_stack([X.ravel(), Y.ravel()]), z_edges)
            out[i0:i1] = lengths.reshape(i1 - i0, samples, ny, samples, nz).mean(axis=(1, 3))
        return out * np.outer(np.diff(x_edges), np.diff(y_edges))[:, :, None]

    # ------------------------------------------------------------ drawing
    def outline(self):
        """Plan-view segments (K, 2, 2): the edges between an upward-facing triangle and
        one that is not (the rim of the opening), and `steps`: the edges between a
        downward-facing triangle and a vertical one (where the floor changes level)."""
        n = self.normals / np.linalg.norm(self.normals, axis=1)[:, None]
        kind = np.where(n[:, 2] > 1e-9, 1, np.where(n[:, 2] < -1e-9, -1, 0))
        directed = self.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        owner = np.repeat(np.arange(len(self.faces)), 3)
        key = np.sort(directed, axis=1)
        order = np.lexsort((key[:, 1], key[:, 0]))
        first, second = order[0::2], order[1::2]
        k1, k2 = kind[owner[first]], kind[owner[second]]
        rim = (k1 == 1) != (k2 == 1)
        step = ((k1 == -1) & (k2 == 0)) | ((k1 == 0) & (k2 == -1))
        seg = self.vertices[key[first]][:, :, :2]
        return seg[rim], seg[step]

    def section(self, axis, value):
        """Segments (K, 2, 3) where the plane coordinate `axis` = value cuts the surface."""
        t = self.triangles
        d = t[:, :, axis] - value
        cut = (d.min(axis=1) < 0) & (d.max(axis=1) > 0)
        out = []
        for tri, dist in zip(t[cut], d[cut]):
            pts = []
            for i, j in ((0, 1), (1, 2), (2, 0)):
                if (dist[i] < 0) != (dist[j] < 0):
                    s = dist[i] / (dist[i] - dist[j])
                    pts.append(tri[i] + s * (tri[j] - tri[i]))
                elif dist[i] == 0:
                    pts.append(tri[i])
            if len(pts) >= 2:
                out.append(pts[:2])
        return np.array(out).reshape(-1, 2, 3)
