#!/usr/bin/env python3
"""Fill density of a die of any shape: how full the cavity is over time, and where the
fill is uneven once it is filled.

    fillDensity.py -case DIR [-stl CAVITY.stl] [-time T] [-cell H] [-bulkDensity RHO]
                   [-sectionX X0] [-sectionY Y0] [-region NAME X0 Y0 X1 Y1]... [-regionGrid NX NY]
                   [-minCover F] [-samples N] [-scale S] [-name N]

CAVITY.stl is the cavity of the die as a closed surface (ASCII or binary STL, metres,
or -scale 0.001 for millimetres): its walls, its base and the top cap over its opening
(z = 0 for the die-filling cases).  Every edge must be shared by exactly two triangles;
an open surface is refused.  A particle is in the cavity when its centre is (a vertical
ray from it crosses the surface an odd number of times; exact for rings, cores, steps).
The powder's mass is the particles' mass (each sphere's volume times its density).
In a case written by writeDieCase.py (constant/dieCase.json) the defaults come from the
case: -stl constant/triSurface/cavity.stl, -time its filled time (timeline_s/filled: the
shoe has left, the die wall not yet lowered), its regionGrid and regions.

1. Fill ratio against time (every output): mass in the cavity / (cavity volume x RHO)
   with -bulkDensity RHO, else mass in the cavity / the mass in it at the time T.
2. At the time T (-time; the output nearest to it, default the latest, or the case's filled
   time; for a die-filling run the time before the die wall is lowered), on a grid of
   H x H columns over the cavity's bounding box in x, y (default H = the larger of its
   widths / 40):
     column bulk density  rho_c = m_c / V_c
       m_c  the mass of the particles in the cavity within the column, each sphere's
            volume split over the columns it overlaps (128 points per sphere, each an
            equal part of its volume; a sphere cut by a column's face is split within
            0.4 % of its volume);
       V_c  the cavity's volume over the column, exact: the integral of the cavity's
            depth (the length of a vertical line inside it) over the column's area.
     Columns with less than F of their area under the opening (-minCover, default 0.5)
     are masked.  Over the other columns, each weighted by its volume V_c:
       mean = sum m_c / sum V_c
       std  = sqrt( sum V_c (rho_c - mean)^2 / sum V_c )
       coefficientOfVariation = std / mean;  max, min and maxMinusMin of rho_c.
   Sections: the local bulk density (mass / cavity volume of each cell, cells of H x H x H
   clipped to the cavity; the volume exact in z, from N x N vertical lines per cell in
   plan, -samples, default 8) in the slab of thickness H about y = Y0 (x-z) and about
   x = X0 (y-z); default: through the cavity's centre.  The same field on the 3-D grid
   goes to a VTK file; cells less than F inside the cavity are masked (0, valid = 0).
3. Mass per region: plan-view boxes (-region NAME X0 Y0 X1 Y1, any number) and/or an
   NX x NY grid over the bounding box (-regionGrid, regions grid_<i>_<j>, i along x):
   the mass of the powder in the cavity over each (spheres split as above) and its bulk
   density, mass / the cavity's volume over the box.

Writes CASE/postProcessing/<N>/ (N default fillDensity): fillRatio.csv/.png, columns.csv,
map.png (top view, with the cavity's outline), sectionXZ.png/.csv, sectionYZ.png/.csv,
fillDensity.vtk (STRUCTURED_POINTS; open in ParaView), regions.csv; and adds <N>.mean,
.max, .min, .maxMinusMin, .coefficientOfVariation, .time, .cell, ... and the regions'
<N>.region.<NAME>.mass/.bulkDensity to CASE/postProcessing/results.json (the keys that
other tools wrote are kept); with a pre-compaction stamp (dieCase.json steps/stamp) also
<N>.stamp.peakForce, .pressure and .dieWallShare from dem/summary.csv's wall forces (and, for a
stamp of given mass, .depth: how far below the table it came to rest).  Units: SI (m, kg, kg/m3, s)."""
import csv
import json
import os
import sys
from argparse import ArgumentTypeError

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, finite, frame_at, out_dir, positive, positive_int, run_main  # noqa: E402
from diefillpost import closedmesh, output, plots, results, series, summary  # noqa: E402

CHUNK = 8000          # particles per chunk of quadrature points (8000 x 128 points)


def fraction(text):
    """argparse type: a number above 0 and at most 1."""
    value = finite(text)
    if not 0 < value <= 1:
        raise ArgumentTypeError(f"expected a number above 0 and at most 1, got '{text}'")
    return value


def edges_over(lo, hi, h):
    """Cell edges of width h from lo, enough cells to reach hi."""
    n = max(1, int(np.ceil((hi - lo) / h - 1e-9)))
    return lo + h * np.arange(n + 1)


def regions_from_options(parser, boxes, grid, lo, hi):
    """[(name, x0, y0, x1, y1)] from -region and -regionGrid, checked."""
    regions, names = [], set()
    for box in boxes:
        name = box[0]
        try:
            v = [finite(x) for x in box[1:]]
        except ArgumentTypeError as e:
            parser.error(f"argument -region {name}: {e}")
        if name in names:
            parser.error(f"argument -region {name}: the name is given to two regions")
        if not (v[0] < v[2] and v[1] < v[3]):
            parser.error(f"argument -region {name}: expected X0 Y0 (min) then X1 Y1 (max) with X0 < X1 and "
                         f"Y0 < Y1, got {' '.join(f'{x:g}' for x in v)}")
        names.add(name)
        regions.append((name, *v))
    if grid:
        gx, gy = edges_grid(lo, hi, grid)
        for i in range(grid[0]):
            for j in range(grid[1]):
                name = f"grid_{i}_{j}"
                if name in names:
                    parser.error(f"argument -region {name}: the name is taken by the -regionGrid regions")
                regions.append((name, gx[i], gy[j], gx[i + 1], gy[j + 1]))
    return regions


def edges_grid(lo, hi, grid):
    return np.linspace(lo[0], hi[0], grid[0] + 1), np.linspace(lo[1], hi[1], grid[1] + 1)


def bin_mass(points, weights, edges, clip):
    """Sum of `weights` per cell of the rectilinear grid `edges` (one array per axis);
    on an axis with clip the points beyond the grid count in its first or last cell,
    on the others they do not count."""
    shape = tuple(len(e) - 1 for e in edges)
    keep = np.ones(len(points), bool)
    index = []
    for a, (e, c) in enumerate(zip(edges, clip)):
        i = np.searchsorted(e, points[:, a], "right") - 1
        if c:
            i = np.clip(i, 0, len(e) - 2)
        else:
            keep &= (i >= 0) & (i < len(e) - 1)
        index.append(i)
    flat = np.ravel_multi_index([i[keep] for i in index], shape)
    return np.bincount(flat, weights=weights[keep], minlength=int(np.prod(shape))).reshape(shape)


def powder_samples(frame, inside, ball):
    """Chunks of (points, weights): each particle in the cavity as len(ball) points
    standing for equal parts of its volume, each with that share of its mass."""
    pos, rad, mass = frame.position[inside], frame.radius[inside], np.asarray(frame.mass, float)[inside]
    for k in range(0, len(pos), CHUNK):
        p, r, m = pos[k:k + CHUNK], rad[k:k + CHUNK], mass[k:k + CHUNK]
        pts = (p[:, None, :] + r[:, None, None] * ball[None, :, :]).reshape(-1, 3)
        yield pts, np.repeat(m / len(ball), len(ball))


def weighted_stats(density, volume):
    """Volume-weighted mean, std, CV, max, min over the columns given."""
    total = float(np.sum(volume))
    mean = float(np.sum(density * volume) / total)
    std = float(np.sqrt(np.sum(volume * (density - mean) ** 2) / total))
    return {"mean": mean, "std": std, "coefficientOfVariation": std / mean if mean > 0 else float("nan"),
            "max": float(np.max(density)), "min": float(np.min(density)),
            "maxMinusMin": float(np.max(density) - np.min(density))}


def write_vtk(path, x_edges, y_edges, z_edges, h, fields, title):
    """Legacy VTK, STRUCTURED_POINTS with cell data: each field (nx, ny, nz), x fastest."""
    nx, ny, nz = len(x_edges) - 1, len(y_edges) - 1, len(z_edges) - 1
    with output.open_replacing(path) as f:
        f.write("# vtk DataFile Version 3.0\n")
        f.write(title[:250].replace("\n", " ") + "\n")
        f.write("ASCII\nDATASET STRUCTURED_POINTS\n")
        f.write(f"DIMENSIONS {nx + 1} {ny + 1} {nz + 1}\n")
        f.write(f"ORIGIN {x_edges[0]:.9g} {y_edges[0]:.9g} {z_edges[0]:.9g}\n")
        f.write(f"SPACING {h:.9g} {h:.9g} {h:.9g}\n")
        f.write(f"CELL_DATA {nx * ny * nz}\n")
        for name, (kind, values) in fields.items():
            f.write(f"SCALARS {name} {kind} 1\nLOOKUP_TABLE default\n")
            flat = np.transpose(values, (2, 1, 0)).ravel()     # x fastest, then y, then z
            fmt = "%d" if kind == "int" else "%.7g"
            for k in range(0, len(flat), 8):
                f.write(" ".join(fmt % v for v in flat[k:k + 8]) + "\n")


def draw_map(path, x_edges, y_edges, density, mesh, regions, named, x0, y0, title):
    named = {r[0] for r in named}
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    shown = np.ma.masked_invalid(density.T)
    mesh_plot = ax.pcolormesh(x_edges * 1e3, y_edges * 1e3, shown, cmap="viridis", shading="flat")
    fig.colorbar(mesh_plot, ax=ax, label="bulk density of the column [kg/m³]", shrink=0.85)
    rim, steps = mesh.outline()
    for seg in steps:
        ax.plot(seg[:, 0] * 1e3, seg[:, 1] * 1e3, color="0.4", lw=0.6, ls="--")
    for seg in rim:
        ax.plot(seg[:, 0] * 1e3, seg[:, 1] * 1e3, color="k", lw=1.2)
    ax.axhline(y0 * 1e3, color="w", lw=0.8, ls=":")
    ax.axvline(x0 * 1e3, color="w", lw=0.8, ls=":")
    for name, rx0, ry0, rx1, ry1 in regions:
        if name in named:
            ax.add_patch(plt.Rectangle((rx0 * 1e3, ry0 * 1e3), (rx1 - rx0) * 1e3, (ry1 - ry0) * 1e3, fill=False,
                                       ec="r", lw=1))
            ax.text(rx0 * 1e3, ry1 * 1e3, name, color="r", fontsize=7, va="bottom")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title, fontsize=8)
    plots.save(fig, path)


def draw_section(path, a_edges, z_edges, density, segments, axis_label, title):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.8))
    shown = np.ma.masked_invalid(density.T)
    pm = ax.pcolormesh(a_edges * 1e3, z_edges * 1e3, shown, cmap="viridis", shading="flat")
    fig.colorbar(pm, ax=ax, label="local bulk density [kg/m³]", shrink=0.85)
    for seg in segments:
        ax.plot(seg[:, 0] * 1e3, seg[:, 1] * 1e3, color="k", lw=1.2)
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label)
    ax.set_ylabel("z [mm]")
    ax.set_title(title, fontsize=8)
    plots.save(fig, path)


def write_rows(path, header, rows):
    with output.open_replacing(path, newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow([v if isinstance(v, str) else ("" if v is None or not np.isfinite(v) else f"{v:.9g}")
                        for v in r])


def stamp_figures(case, p, stamp, opening_area):
    """The pre-compaction stamp's force from dem/summary.csv (the powder's force on the walls):
    its peak, its mean while held at depth as a pressure over the opening, and the share of it
    that the die's side walls carry by friction (the rest reaches the floors)."""
    columns = summary.read(case)
    t = columns["time"]
    force = columns["wallForce_stamp_z"]
    held = (t >= stamp["pressed_s"]) & (t <= stamp["released_s"])
    if len(t) == 0 or t[-1] < stamp["released_s"] or not np.any(held):
        print(f"fillDensity: no stamp figures: dem/summary.csv ends before the stamp's hold ends "
              f"({stamp['released_s']:.4g} s)")
        return {}
    mean = float(np.mean(force[held]))
    walls = float(-np.mean(columns["wallForce_dieWalls_z"][held]))
    window = f"{stamp['pressed_s']:.4g}-{stamp['released_s']:.4g} s"
    if "mass_kg" in stamp:
        when = f"resting under its weight ({stamp['mass_kg']:g} kg), {window}"
    else:
        when = f"held at {stamp['depth_m'] * 1e3:g} mm below the table, {window}"
    out = {
        f"{p}.stamp.peakForce": {"value": float(np.max(force)), "unit": "N",
                                 "description": "largest force of the powder on the pre-compaction stamp"},
        f"{p}.stamp.pressure": {"value": mean / opening_area, "unit": "Pa",
                                "description": f"mean force on the stamp / opening area, {when}"},
        f"{p}.stamp.dieWallShare": {"value": walls / mean if mean > 0 else None, "unit": "-",
                                    "description": f"the die side walls' share of the stamp force (friction), {when}"},
    }
    if "mass_kg" in stamp:
        # A stamp of given weight sinks as far as the powder lets it: how far is the result.
        offset = columns.get("wallOffset_stamp")
        if offset is None:
            print("fillDensity: no stamp depth: dem/summary.csv has no column wallOffset_stamp")
            return out
        depth = float(np.mean(offset[held]))
        stopped = depth >= stamp["stroke_m"] * (1 - 1e-9)
        out[f"{p}.stamp.depth"] = {
            "value": depth, "unit": "m",
            "description": f"how far below the table the stamp stood, {when}" +
                           (f"; it stood on its stop ({stamp['stroke_m'] * 1e3:g} mm): the powder did not carry it"
                            if stopped else "")}
        weight = stamp["mass_kg"] * 9.81
        if not stopped and abs(mean - weight) > 0.1 * weight:
            print(f"fillDensity: the stamp was not at rest {window}: the powder carried {mean:.4g} N of its "
                  f"{weight:.4g} N (a longer hold, steps/stamp/hold, lets it settle)")
    return out


def die_case(case):
    """The defaults that a case written by writeDieCase.py gives (constant/dieCase.json):
    {filled: time, regionGrid: [nx, ny], regions: {name: [x0, y0, x1, y1]}}; {} without
    that file.  A file that cannot be read as such is a ValueError naming it."""
    path = os.path.join(case, "constant", "dieCase.json")
    if not os.path.exists(path):
        return {}
    try:
        with open(path) as f:
            d = json.load(f)
        out = {"filled": (d.get("timeline_s") or {}).get("filled")}
        if out["filled"] is not None:
            out["filled"] = float(out["filled"])
        if d.get("regionGrid") is not None:
            out["regionGrid"] = [int(v) for v in d["regionGrid"]]
            if len(out["regionGrid"]) != 2 or min(out["regionGrid"]) < 1:
                raise ValueError("regionGrid")
        out["regions"] = {str(k): [float(x) for x in v] for k, v in (d.get("regions_m") or {}).items()}
        out["stamp"] = (d.get("steps") or {}).get("stamp")
        if out["stamp"] is not None:
            keys = ("mass_kg", "stroke_m") if "mass_kg" in out["stamp"] else ("depth_m",)
            out["stamp"] = {k: float(out["stamp"][k]) for k in keys + ("pressed_s", "released_s")}
            out["openingArea"] = float(d["openingArea_m2"])
        if any(len(v) != 4 for v in out["regions"].values()):
            raise ValueError("regions_m")
    except (ValueError, TypeError, AttributeError) as e:
        raise ValueError(f"'{path}' cannot be read ({e}): expected the file that writeDieCase.py writes "
                         "(timeline_s/filled, regionGrid, regions_m)") from None
    return out


def mass_inside(mesh, frame):
    if frame.count == 0:
        return 0.0
    return float(np.sum(np.asarray(frame.mass, float)[mesh.contains(frame.position)]))


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-stl", default=None, help="the cavity as a closed STL surface (default: the case's "
                    "constant/triSurface/cavity.stl when it has constant/dieCase.json)")
    ap.add_argument("-time", type=finite, default=None, help="[s] the filled die (default: the latest output)")
    ap.add_argument("-cell", type=positive, default=None, help="[m] column width (default: the larger width / 40)")
    ap.add_argument("-bulkDensity", type=positive, default=None, help="[kg/m3] the reference bulk density")
    ap.add_argument("-sectionX", type=finite, default=None, help="[m] x of the y-z section (default: the centre)")
    ap.add_argument("-sectionY", type=finite, default=None, help="[m] y of the x-z section (default: the centre)")
    ap.add_argument("-region", nargs=5, action="append", default=[], metavar=("NAME", "X0", "Y0", "X1", "Y1"))
    ap.add_argument("-regionGrid", type=positive_int, nargs=2, default=None, metavar=("NX", "NY"))
    ap.add_argument("-minCover", type=fraction, default=0.5,
                    help="columns (cells) with less of their area (volume) in the cavity are masked")
    ap.add_argument("-samples", type=positive_int, default=8, help="vertical lines per cell side for the sections")
    ap.add_argument("-scale", type=positive, default=1.0, help="factor to metres of the STL's coordinates")
    ap.add_argument("-name", default="fillDensity")
    a = ap.parse_args()
    if not a.name or os.sep in a.name or a.name.startswith("."):
        ap.error(f"argument -name: expected a plain folder name, got '{a.name}'")

    die = die_case(a.case)
    if a.stl is None:
        if not die:
            ap.error("argument -stl: expected the cavity's closed STL file (the case has no constant/dieCase.json "
                     "to take it from)")
        a.stl = os.path.join(a.case, "constant", "triSurface", "cavity.stl")
    if a.time is None and die.get("filled") is not None:
        a.time = die["filled"]
    if not a.regionGrid and die.get("regionGrid"):
        a.regionGrid = die["regionGrid"]
    given = {r[0] for r in a.region}
    a.region += [[name, *map(str, box)] for name, box in die.get("regions", {}).items() if name not in given]
    mesh = closedmesh.ClosedMesh.from_stl(a.stl, a.scale)
    lo, hi = mesh.lo, mesh.hi
    h = a.cell if a.cell is not None else float(max(hi[0] - lo[0], hi[1] - lo[1])) / 40.0
    x_edges, y_edges = edges_over(lo[0], hi[0], h), edges_over(lo[1], hi[1], h)
    nz = max(1, int(np.ceil((hi[2] - lo[2]) / h - 1e-9)))
    z_edges = hi[2] - h * nz + h * np.arange(nz + 1)
    x0 = a.sectionX if a.sectionX is not None else 0.5 * (lo[0] + hi[0])
    y0 = a.sectionY if a.sectionY is not None else 0.5 * (lo[1] + hi[1])
    for option, value, axis in (("-sectionX", x0, 0), ("-sectionY", y0, 1)):
        if not lo[axis] < value < hi[axis]:
            ap.error(f"argument {option}: {value:g} m is not within the cavity, which spans "
                     f"{lo[axis]:g} to {hi[axis]:g} m in {'xy'[axis]}")
    regions = regions_from_options(ap, a.region, a.regionGrid, lo, hi)
    named = regions[:len(a.region)]
    region_volume = {}
    for name, rx0, ry0, rx1, ry1 in named:
        region_volume[name] = float(mesh.column_volumes([rx0, rx1], [ry0, ry1])[0][0, 0])
        if not region_volume[name] > 0:
            ap.error(f"argument -region {name}: the box {rx0:g} {ry0:g} to {rx1:g} {ry1:g} m holds none of the "
                     f"cavity, which spans x {lo[0]:g} to {hi[0]:g}, y {lo[1]:g} to {hi[1]:g} m")
    if a.regionGrid:
        region_grid = edges_grid(lo, hi, a.regionGrid)
        grid_volume = mesh.column_volumes(*region_grid)[0]
        for i in range(a.regionGrid[0]):
            for j in range(a.regionGrid[1]):
                region_volume[f"grid_{i}_{j}"] = float(grid_volume[i, j])

    results.existing(a.case)          # a damaged results.json stops the run before any output

    # ------------------------------------------------------------ the fill over time
    frame = frame_at(a.case, a.time)
    if a.time is not None and abs(frame.time - a.time) > 1e-9 * max(1.0, abs(a.time)):
        print(f"fillDensity: the output nearest to t = {a.time:g} s is that of t = {frame.time:g} s")
    inside = mesh.contains(frame.position)
    mass_now = float(np.sum(np.asarray(frame.mass, float)[inside]))
    if not mass_now > 0:
        raise ValueError(f"no particle lies in the cavity at t = {frame.time:g} s ('{frame.path}', {frame.count} "
                         f"particles, the cavity spans z {lo[2]:g} to {hi[2]:g} m): give -time of the filled die, "
                         "or check that the STL is placed as the die (-scale for millimetres)")
    times, masses = [], []
    for t, path in series.list_frames(a.case):
        times.append(t)
        masses.append(mass_now if path == frame.path else mass_inside(mesh, series.read_frame(path)))
    times, masses = np.array(times), np.array(masses)
    reference = mesh.volume * a.bulkDensity if a.bulkDensity else mass_now
    fill = masses / reference

    # ------------------------------------------------------------ the powder at time T
    ball = closedmesh.ball_points()
    col_edges = (x_edges, y_edges)
    xz_edges = (x_edges, np.array([y0 - h / 2, y0 + h / 2]), z_edges)
    yz_edges = (np.array([x0 - h / 2, x0 + h / 2]), y_edges, z_edges)
    grid_edges = (x_edges, y_edges, z_edges)
    m_col = np.zeros((len(x_edges) - 1, len(y_edges) - 1))
    m_3d = np.zeros((len(x_edges) - 1, len(y_edges) - 1, nz))
    m_xz = np.zeros((len(x_edges) - 1, 1, nz))
    m_yz = np.zeros((1, len(y_edges) - 1, nz))
    m_region = {name: 0.0 for name, *_ in regions}
    for pts, w in powder_samples(frame, inside, ball):
        m_col += bin_mass(pts, w, col_edges, (True, True))
        m_3d += bin_mass(pts, w, grid_edges, (True, True, True))
        m_xz += bin_mass(pts, w, xz_edges, (True, False, True))
        m_yz += bin_mass(pts, w, yz_edges, (False, True, True))
        for name, rx0, ry0, rx1, ry1 in named:
            sel = (pts[:, 0] >= rx0) & (pts[:, 0] < rx1) & (pts[:, 1] >= ry0) & (pts[:, 1] < ry1)
            m_region[name] += float(np.sum(w[sel]))
        if a.regionGrid:
            in_grid = bin_mass(pts, w, region_grid, (True, True))
            for i in range(a.regionGrid[0]):
                for j in range(a.regionGrid[1]):
                    m_region[f"grid_{i}_{j}"] += float(in_grid[i, j])

    v_col, cover = mesh.column_volumes(x_edges, y_edges)
    valid = (cover >= a.minCover) & (v_col > 0)
    if not valid.any():
        raise ValueError(f"no column of {h:g} m has {a.minCover:g} of its area under the cavity's opening: "
                         "give a smaller -cell or -minCover")
    rho_col = np.full(m_col.shape, np.nan)
    rho_col[valid] = m_col[valid] / v_col[valid]
    stats = weighted_stats(rho_col[valid], v_col[valid])

    def local(mass, edges):
        volume = mesh.cell_volumes(*edges, samples=a.samples)
        cell = np.einsum("i,j,k->ijk", *(np.diff(e) for e in edges))
        share = volume / cell
        rho = np.full(mass.shape, np.nan)
        ok = (share >= a.minCover) & (volume > 0)
        rho[ok] = mass[ok] / volume[ok]
        return rho, share, volume

    rho_3d, share_3d, _ = local(m_3d, grid_edges)
    rho_xz, share_xz, v_xz = local(m_xz, xz_edges)
    rho_yz, share_yz, v_yz = local(m_yz, yz_edges)

    # ------------------------------------------------------------ outputs
    folder = os.path.join(out_dir(a.case), a.name)
    os.makedirs(folder, exist_ok=True)
    write_rows(os.path.join(folder, "fillRatio.csv"), ["time_s", "massInCavity_kg", "fillRatio"],
               zip(times, masses, fill))
    ref_label = (f"mass in the cavity / (cavity volume x {a.bulkDensity:g} kg/m³)" if a.bulkDensity
                 else f"mass in the cavity / mass in it at t = {frame.time:g} s")
    plots.curve(os.path.join(folder, "fillRatio.png"), times, [fill], [ref_label], "time [s]", "fill ratio [-]",
                title=f"fill of the cavity {os.path.basename(a.stl)} ({mesh.volume * 1e6:.4g} cm³)",
                vlines=[(frame.time, "density map")])
    xc, yc = 0.5 * (x_edges[1:] + x_edges[:-1]), 0.5 * (y_edges[1:] + y_edges[:-1])
    rows = []
    area = h * h
    for i in range(len(xc)):
        for j in range(len(yc)):
            depth = v_col[i, j] / (cover[i, j] * area) if cover[i, j] > 0 else 0.0
            rows.append([xc[i], yc[j], cover[i, j], depth, v_col[i, j], m_col[i, j], rho_col[i, j], int(valid[i, j])])
    write_rows(os.path.join(folder, "columns.csv"),
               ["x_m", "y_m", "cover", "meanDepth_m", "cavityVolume_m3", "mass_kg", "bulkDensity_kgm3", "valid"], rows)
    zc = 0.5 * (z_edges[1:] + z_edges[:-1])
    write_rows(os.path.join(folder, "sectionXZ.csv"), ["x_m", "z_m", "cavityVolume_m3", "mass_kg", "bulkDensity_kgm3"],
               [[xc[i], zc[k], v_xz[i, 0, k], m_xz[i, 0, k], rho_xz[i, 0, k]]
                for i in range(len(xc)) for k in range(nz)])
    write_rows(os.path.join(folder, "sectionYZ.csv"), ["y_m", "z_m", "cavityVolume_m3", "mass_kg", "bulkDensity_kgm3"],
               [[yc[j], zc[k], v_yz[0, j, k], m_yz[0, j, k], rho_yz[0, j, k]]
                for j in range(len(yc)) for k in range(nz)])
    when = f"t = {frame.time:g} s"
    draw_map(os.path.join(folder, "map.png"), x_edges, y_edges, rho_col, mesh, regions, named, x0, y0,
             f"bulk density of the {h * 1e3:.3g} mm columns, {when}: mean {stats['mean']:.1f} kg/m³, "
             f"CV {100 * stats['coefficientOfVariation']:.2f} %, max-min {stats['maxMinusMin']:.1f} kg/m³")
    cut_y = mesh.section(1, y0)
    draw_section(os.path.join(folder, "sectionXZ.png"), x_edges, z_edges, rho_xz[:, 0, :], cut_y[:, :, [0, 2]],
                 "x [mm]", f"local bulk density in the slab |y - {y0 * 1e3:.3g} mm| < {h * 500:.3g} mm, {when}")
    cut_x = mesh.section(0, x0)
    draw_section(os.path.join(folder, "sectionYZ.png"), y_edges, z_edges, rho_yz[0, :, :], cut_x[:, :, [1, 2]],
                 "y [mm]", f"local bulk density in the slab |x - {x0 * 1e3:.3g} mm| < {h * 500:.3g} mm, {when}")
    ok_3d = np.isfinite(rho_3d)
    column_field = np.repeat(np.nan_to_num(rho_col, nan=0.0)[:, :, None], nz, axis=2)
    write_vtk(os.path.join(folder, "fillDensity.vtk"), x_edges, y_edges, z_edges, h,
              {"bulkDensity": ("float", np.where(ok_3d, rho_3d, 0.0)),
               "columnBulkDensity": ("float", column_field * ok_3d),
               "cavityFraction": ("float", np.clip(share_3d, 0, 1)),
               "valid": ("int", ok_3d.astype(int))},
              f"fillDensity: local bulk density [kg/m3] at {when}, cells of {h:g} m clipped to the cavity "
              f"{os.path.basename(a.stl)} (masked: valid 0)")
    region_rows = []
    for name, rx0, ry0, rx1, ry1 in regions:
        vol = region_volume[name]
        region_rows.append([name, rx0, ry0, rx1, ry1, m_region[name], vol, m_region[name] / vol if vol > 0 else None])
    if regions:
        write_rows(os.path.join(folder, "regions.csv"),
                   ["region", "x0_m", "y0_m", "x1_m", "y1_m", "mass_kg", "cavityVolume_m3", "bulkDensity_kgm3"],
                   region_rows)

    p = a.name
    res = {
        f"{p}.time": {"value": frame.time, "unit": "s", "description": f"output used for the map ({frame.path})"},
        f"{p}.cell": {"value": h, "unit": "m", "description": "width of the square columns of the map"},
        f"{p}.mean": {"value": stats["mean"], "unit": "kg/m3",
                      "description": "column bulk density, mean over the columns weighted by their cavity volume"},
        f"{p}.max": {"value": stats["max"], "unit": "kg/m3", "description": "largest column bulk density"},
        f"{p}.min": {"value": stats["min"], "unit": "kg/m3", "description": "smallest column bulk density"},
        f"{p}.maxMinusMin": {"value": stats["maxMinusMin"], "unit": "kg/m3"},
        f"{p}.coefficientOfVariation": {"value": stats["coefficientOfVariation"], "unit": "-",
                                        "description": "std / mean of the column bulk density, both weighted by "
                                                       "the columns' cavity volume"},
        f"{p}.columns": {"value": int(np.count_nonzero(valid)), "unit": "-",
                         "description": f"columns with at least {a.minCover:g} of their area under the opening"},
        f"{p}.cavityVolume": {"value": mesh.volume, "unit": "m3", "description": a.stl},
        f"{p}.massInCavity": {"value": mass_now, "unit": "kg",
                              "description": f"particle centres in the cavity, {when}"},
        f"{p}.bulkDensityOverall": {"value": mass_now / mesh.volume, "unit": "kg/m3",
                                    "description": "mass in the cavity / cavity volume"},
    }
    if a.bulkDensity:
        res[f"{p}.fillRatio"] = {"value": mass_now / reference, "unit": "-",
                                 "description": f"mass in the cavity / (cavity volume x {a.bulkDensity:g} kg/m3), "
                                                f"{when}"}
    for name, rx0, ry0, rx1, ry1, mass, vol, rho in region_rows:
        box = f"x {rx0:g} to {rx1:g}, y {ry0:g} to {ry1:g} m"
        res[f"{p}.region.{name}.mass"] = {"value": mass, "unit": "kg",
                                          "description": f"powder in the cavity over {box}"}
        res[f"{p}.region.{name}.bulkDensity"] = {"value": rho, "unit": "kg/m3",
                                                 "description": f"mass / cavity volume ({vol:.6g} m3) over {box}"}
    if die.get("stamp"):
        res.update(stamp_figures(a.case, p, die["stamp"], die["openingArea"]))
    results.update(a.case, res)
    print(f"fillDensity: {when}, {mass_now * 1e3:.4g} g in the cavity ({mesh.volume * 1e6:.4g} cm3, overall "
          f"{mass_now / mesh.volume:.1f} kg/m3); columns of {h * 1e3:.3g} mm: mean {stats['mean']:.1f} kg/m3, "
          f"min {stats['min']:.1f}, max {stats['max']:.1f}, CV {100 * stats['coefficientOfVariation']:.2f} %")
    print(f"wrote {folder}/ (fillRatio, columns, map, sectionXZ, sectionYZ, fillDensity.vtk"
          + (", regions" if regions else "") + ") and postProcessing/results.json")
    return 0


if __name__ == "__main__":
    run_main(main)
