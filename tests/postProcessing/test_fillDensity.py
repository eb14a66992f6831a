"""Tests of tools/fillDensity.py and tools/diefillpost/closedmesh.py on synthetic dies with
known answers (see run): a ring cavity with a packing of two known densities, a cavity with
two levels, point-in-mesh on the ring's core and on the triangulation's own edges, an open
STL.  Each asserted number comes with a negative control: the same check against a value
computed the wrong way (a wrong depth, the column not clipped to the cavity, the mass of
the other region) must fail, so that the check can fail."""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.abspath(os.path.join(os.path.dirname(__file__), "../.."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import h5py  # noqa: E402

from diefillpost import closedmesh  # noqa: E402

PASSED, FAILED = 0, 0
TMP = tempfile.mkdtemp(prefix="fillDensity_")
RHO_S = 2650.0


def check(name, ok, detail=""):
    global PASSED, FAILED
    if ok:
        PASSED += 1
        print(f"PASS: {name} {detail}")
    else:
        FAILED += 1
        print(f"FAIL: {name} {detail}")


def check_value(name, got, want, wrong, tol):
    """got within tol of want, and the control: the wrong value is not (the check can fail)."""
    ok = got is not None and abs(got - want) <= tol
    control = abs(wrong - want) > tol and (got is None or abs(got - wrong) > tol)
    check(name, ok, f"(got {got!r}, expected {want:.6g} within {tol:.3g})")
    check(f"{name}: control, {wrong:.6g} (computed the wrong way) is refused", control)


def test(fn):
    try:
        fn()
    except Exception as e:  # a crashing test is a failed test
        import traceback
        traceback.print_exc()
        check(fn.__name__, False, f"raised {type(e).__name__}: {e}")
    return fn


# ------------------------------------------------------------------ synthetic dies
RO, RI, DEPTH, N = 0.020, 0.008, 0.015, 64


def ring_triangles(ro=RO, ri=RI, depth=DEPTH, n=N):
    """A ring cavity: outer and inner walls (regular n-gons), top cap at z = 0, base at -depth."""
    a = 2 * np.pi * np.arange(n) / n

    def circle(r, z):
        return np.column_stack([r * np.cos(a), r * np.sin(a), np.full(n, z)])

    ot, ob, it, ib = circle(ro, 0), circle(ro, -depth), circle(ri, 0), circle(ri, -depth)
    tris = []
    for k in range(n):
        j = (k + 1) % n
        tris += [(ob[k], ob[j], ot[j]), (ob[k], ot[j], ot[k])]
        tris += [(ib[k], it[j], ib[j]), (ib[k], it[k], it[j])]
        tris += [(it[k], ot[j], it[j]), (it[k], ot[k], ot[j])]
        tris += [(ib[k], ib[j], ob[j]), (ib[k], ob[j], ob[k])]
    return np.array(tris)


def extruded_triangles(profile, y0, y1):
    """A prism along y of the polygon `profile` (x, z), its ends fanned from vertex 0 (which
    must see every other vertex)."""
    p = np.asarray(profile, float)
    n = len(p)
    front = np.column_stack([p[:, 0], np.full(n, y0), p[:, 1]])
    back = np.column_stack([p[:, 0], np.full(n, y1), p[:, 1]])
    tris = []
    for k in range(n):
        j = (k + 1) % n
        tris += [(front[k], back[k], back[j]), (front[k], back[j], front[j])]
    for k in range(1, n - 1):
        tris += [(front[0], front[k], front[k + 1]), (back[0], back[k + 1], back[k])]
    return np.array(tris)


# two levels: a 30 x 30 x 10 mm box, a 10 x 30 x 10 mm slot below its side x < 10 mm; the
# profile in x-z fanned from the inner corner (10, -10)
TWO_LEVEL_MM = [(10, -10), (10, -20), (0, -20), (0, 0), (30, 0), (30, -10)]


def write_ascii_stl(path, tris):
    with open(path, "w") as f:
        f.write("solid die\n")
        for t in tris:
            n = np.cross(t[1] - t[0], t[2] - t[0])
            n = n / np.linalg.norm(n)
            f.write(f" facet normal {n[0]:.6g} {n[1]:.6g} {n[2]:.6g}\n  outer loop\n")
            for v in t:
                f.write(f"   vertex {v[0]:.12g} {v[1]:.12g} {v[2]:.12g}\n")
            f.write("  endloop\n endfacet\n")
        f.write("endsolid die\n")


def write_binary_stl(path, tris):
    rec = np.zeros(len(tris), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tris
    with open(path, "wb") as f:
        f.write(b"solid-looking header of a binary STL".ljust(80, b" "))
        f.write(np.uint32(len(tris)).tobytes())
        f.write(rec.tobytes())


def write_case(case, frames_data):
    """Particle output as demRun writes it (dem/particles_<step>.h5 + particles.series)."""
    os.makedirs(os.path.join(case, "dem"), exist_ok=True)
    lines = []
    for step, (t, pos, rad) in enumerate(frames_data):
        name = f"particles_{step:09d}.h5"
        n = len(pos)
        rad = np.asarray(rad, float)
        with h5py.File(os.path.join(case, "dem", name), "w") as h:
            h.attrs["time"] = t
            h.attrs["step"] = step
            h["id"] = np.arange(n, dtype=np.int64)
            h["position"] = np.asarray(pos, float)
            h["velocity"] = np.zeros((n, 3))
            h["omega"] = np.zeros((n, 3))
            h["force"] = np.zeros((n, 3))
            h["radius"] = rad
            h["mass"] = RHO_S * 4 / 3 * np.pi * rad ** 3
            h["material"] = np.zeros(n, np.int32)
        lines.append(f"{t} {step} {n} {name}\n")
    with open(os.path.join(case, "dem", "particles.series"), "w") as f:
        f.writelines(lines)


def run_tool(*args):
    return subprocess.run([sys.executable, os.path.join(ROOT, "tools", "fillDensity.py")] + [str(a) for a in args],
                          capture_output=True, text=True)


def one_line_error(r, *words):
    lines = r.stderr.strip().splitlines()
    return (r.returncode != 0 and len(lines) == 1 and lines[0].startswith("fillDensity.py: error: ")
            and all(w in lines[0] for w in words) and "Traceback" not in r.stderr)


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def in_polygon_annulus(x, y, ro=RO, ri=RI, n=N):
    """Inside the regular n-gon of circumradius ro and outside that of ri (both with a vertex
    at angle 0): the projection on the sector's apothem direction against R cos(pi/n)."""
    phi = np.mod(np.arctan2(y, x), 2 * np.pi)
    mid = (np.floor(phi / (2 * np.pi / n)) + 0.5) * 2 * np.pi / n
    s = x * np.cos(mid) + y * np.sin(mid)
    return (s <= ro * np.cos(np.pi / n)) & (s > ri * np.cos(np.pi / n))


def polygon_area(r, n=N):
    return 0.5 * n * r * r * np.sin(2 * np.pi / n)


RING_VOLUME = (polygon_area(RO) - polygon_area(RI)) * DEPTH


# ------------------------------------------------------------------ point in mesh
@test
def ring_points_inside():
    stl = os.path.join(TMP, "ring.stl")
    write_ascii_stl(stl, ring_triangles())
    mesh = closedmesh.ClosedMesh.from_stl(stl)
    check_value("ring STL: volume equals the polygonal annulus's (m3)", mesh.volume, RING_VOLUME,
                np.pi * (RO ** 2 - RI ** 2) * (DEPTH - 0.001), 1e-6 * RING_VOLUME)
    rng = np.random.default_rng(11)
    n = 4000
    rho, phi = rng.uniform(0, 0.024, n), rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(-0.018, 0.003, n)
    p = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
    # clear of the walls by 0.1 mm (the polygons lie within 0.024 mm of the circles)
    clear = ((np.abs(rho - RO) > 1e-4) & (np.abs(rho - RI) > 1e-4) & (np.abs(z) > 1e-4) & (np.abs(z + DEPTH) > 1e-4))
    p = p[clear]
    rho, z = rho[clear], z[clear]
    want = (rho > RI) & (rho < RO) & (z < 0) & (z > -DEPTH)
    got = mesh.contains(p)
    core = (rho < RI) & (z < 0) & (z > -DEPTH)
    check("point in mesh: the ring's core is not inside", not got[core].any(), f"({np.count_nonzero(core)} points)")
    check("point in mesh: the annulus is inside, outside and above/below are not",
          np.array_equal(got, want), f"({np.count_nonzero(got != want)} of {len(p)} wrong)")
    check("point in mesh: control, a filled disk's answer (core inside) differs",
          not np.array_equal(got, (rho < RO) & (z < 0) & (z > -DEPTH)))
    # vertical rays exactly through the edges of the caps' triangulation: the radial edges
    # (midpoints between the vertices k of the two polygons) and the quads' diagonals
    a = 2 * np.pi * np.arange(N) / N
    radial = 0.5 * np.column_stack([(RO + RI) * np.cos(a), (RO + RI) * np.sin(a)])
    diagonal = 0.5 * np.column_stack([RI * np.cos(a) + RO * np.cos(np.roll(a, -1)),
                                      RI * np.sin(a) + RO * np.sin(np.roll(a, -1))])
    on_edges = np.vstack([radial, diagonal])
    for zz, inside in ((-0.007, True), (0.002, False), (-0.016, False)):
        q = np.column_stack([on_edges, np.full(len(on_edges), zz)])
        got = mesh.contains(q)
        check(f"point in mesh: {len(q)} rays through the caps' shared edges at z = {zz * 1e3:g} mm: "
              f"{'inside' if inside else 'outside'}", bool(np.all(got == inside)),
              f"({np.count_nonzero(got != inside)} wrong)")
    # control: counting every triangle that a ray touches (no tie rule) counts a shared edge
    # twice, which gets these points wrong: the points do test the degenerate case
    tri = mesh.triangles
    q = np.column_stack([on_edges, np.full(len(on_edges), -0.007)])
    naive = []
    for x, y, zz in q:
        count = 0
        for t in tri:
            a2 = (t[1, 0] - t[0, 0]) * (t[2, 1] - t[0, 1]) - (t[2, 0] - t[0, 0]) * (t[1, 1] - t[0, 1])
            if a2 == 0:
                continue
            # e[k]: edge k -> k+1 (its sign made positive inside); weight of the opposite vertex k+2
            e = [np.sign(a2) * ((t[(k + 1) % 3, 0] - t[k, 0]) * (y - t[k, 1])
                                - (t[(k + 1) % 3, 1] - t[k, 1]) * (x - t[k, 0])) for k in range(3)]
            if all(v >= 0 for v in e):
                height = sum(e[k] * t[(k + 2) % 3, 2] for k in range(3)) / abs(a2)
                count += height > zz
        naive.append(count % 2 == 1)
    check("point in mesh: control, a ray test without the tie rule gets some of these points wrong",
          not all(naive), f"({len(naive) - sum(naive)} of {len(naive)} wrong)")


@test
def open_stl_is_refused():
    tris = ring_triangles()
    closed = os.path.join(TMP, "ring_closed.stl")
    holed = os.path.join(TMP, "ring_open.stl")
    write_ascii_stl(closed, tris)
    write_ascii_stl(holed, np.delete(tris, 5, axis=0))
    try:
        closedmesh.ClosedMesh.from_stl(holed)
        check("an open STL (one triangle removed): ValueError", False, "(accepted)")
    except ValueError as e:
        check("an open STL (one triangle removed): ValueError naming the file and the hole",
              holed in str(e) and "not a closed surface" in str(e) and "3 edges of only one triangle" in str(e), str(e))
    try:
        closedmesh.ClosedMesh.from_stl(closed)
        check("control: the same STL with all its triangles is accepted", True)
    except ValueError as e:
        check("control: the same STL with all its triangles is accepted", False, str(e))
    case = os.path.join(TMP, "open_case")
    write_case(case, [(0.0, np.array([[0.014, 0, -0.007]]), [5e-4])])
    r = run_tool("-case", case, "-stl", holed)
    check("fillDensity.py with an open STL: one line naming the file, exit 1",
          one_line_error(r, "ring_open.stl", "not a closed surface") and r.returncode == 1, r.stderr.strip()[-300:])
    check("fillDensity.py with an open STL: nothing written", not os.path.exists(os.path.join(case, "postProcessing")))
    r = run_tool("-case", case, "-stl", closed)
    check("control: fillDensity.py with the closed STL runs", r.returncode == 0, r.stderr.strip()[-300:])


@test
def orientation_and_formats():
    tris = ring_triangles()
    flipped = tris.copy()
    flipped[::3] = flipped[::3][:, [0, 2, 1]]
    mesh = closedmesh.ClosedMesh(flipped, "flipped")
    a, b, c = flipped[:, 0], flipped[:, 1], flipped[:, 2]
    naive = float(np.sum(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6)
    check_value("a ring with a third of its triangles turned over: reoriented, the volume (m3)", mesh.volume,
                RING_VOLUME, naive, 1e-6 * RING_VOLUME)
    stl = os.path.join(TMP, "two_mm.stl")
    write_binary_stl(stl, extruded_triangles(TWO_LEVEL_MM, 0, 30))
    mesh = closedmesh.ClosedMesh.from_stl(stl, 1e-3)
    check_value("binary STL in mm, -scale 0.001: the two-level cavity's volume (m3)", mesh.volume, 12e-6, 9e-6,
                1e-6 * 12e-6)
    bad = os.path.join(TMP, "not.stl")
    with open(bad, "w") as f:
        f.write("hello\n")
    try:
        closedmesh.read_stl(bad)
        check("a file that is not an STL: ValueError", False)
    except ValueError as e:
        check("a file that is not an STL: ValueError naming it", bad in str(e) and "not an STL" in str(e), str(e))


@test
def ball_quadrature_splits_spheres():
    pts = closedmesh.ball_points()

    def cap(d):  # share of the unit ball with x < d
        return (d + 1) ** 2 * (2 - d) / 4

    d = np.linspace(-0.95, 0.95, 39)
    err = max(abs(np.mean(pts[:, a] < x) - cap(x)) for a in range(3) for x in d)
    check("ball quadrature: the share on one side of a plane within 0.5 % of the sphere", err < 0.005,
          f"(max error {err:.4f})")
    # control: splitting by the centre alone puts a sphere cut through its centre wholly on one side
    centre_only = float(0.0 < 0.0)
    check("ball quadrature: control, a centre-only split is off by 50 % there", abs(centre_only - cap(0.0)) > 0.005)


# ------------------------------------------------------------------ the ring, end to end
H = 0.0025                       # columns of 2.5 mm: 16 x 16 over the ring's box
AO, RPO = 0.00125, 0.00055       # outer half (14-20 mm): lattice 1.25 mm, spheres r 0.55 mm
AI, RPI = 0.000625, 0.00025      # inner half (8-14 mm): lattice 0.625 mm, spheres r 0.25 mm
RHO_OUTER = RHO_S * 4 / 3 * np.pi * RPO ** 3 / AO ** 3
RHO_INNER = RHO_S * 4 / 3 * np.pi * RPI ** 3 / AI ** 3
R_MID = 0.014


def lattice(a, r, keep):
    """Cubic lattice of pitch a from the box corner (-20, -20, 0) mm over the ring's depth,
    the points kept where keep(rho); every sphere lies within its lattice cube, so it is cut
    by no column face (the columns' faces lie on the lattice's)."""
    n = int(round(2 * RO / a))
    k = int(round(DEPTH / a))
    g = -RO + (np.arange(n) + 0.5) * a
    X, Y, Z = np.meshgrid(g, g, -(np.arange(k) + 0.5) * a, indexing="ij")
    p = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    rho = np.hypot(p[:, 0], p[:, 1])
    p = p[keep(rho)]
    return p, np.full(len(p), r)


def ring_packing():
    po, ro = lattice(AO, RPO, lambda rho: (rho >= R_MID) & (rho <= 0.0199))
    pi, ri = lattice(AI, RPI, lambda rho: (rho > 0.0081) & (rho < R_MID))
    return po, ro, pi, ri


def mass(r):
    return RHO_S * 4 / 3 * np.pi * np.asarray(r) ** 3


@test
def ring_fill_density():
    case = os.path.join(TMP, "ring_case")
    stl = os.path.join(TMP, "ring_die.stl")
    write_ascii_stl(stl, ring_triangles())
    po, ro, pi, ri = ring_packing()
    up = np.array([0, 0, 0.05])          # above the die: not in the cavity
    pos = np.vstack([po, pi])
    rad = np.concatenate([ro, ri])
    n_o = len(po)
    half = np.vstack([po, pi + up])
    write_case(case, [(0.0, pos + up, rad), (0.5, half, rad), (1.0, pos, rad)])
    os.makedirs(os.path.join(case, "postProcessing"))
    with open(os.path.join(case, "postProcessing", "results.json"), "w") as f:
        json.dump({"centralAngle": {"value": 33.8, "unit": "deg"}}, f)
    r = run_tool("-case", case, "-stl", stl, "-cell", H, "-region", "west", -0.02, -0.02, 0, 0.02,
                 "-regionGrid", 2, 2)
    check("fillDensity.py on the ring: exit 0", r.returncode == 0, r.stderr.strip()[-600:])
    if r.returncode != 0:
        return
    out = os.path.join(case, "postProcessing", "fillDensity")
    m_o, m_i = float(np.sum(mass(ro))), float(np.sum(mass(ri)))
    total = m_o + m_i

    # fill ratio against time, without -bulkDensity: the mass in the cavity / that at the latest time
    rows = read_csv(os.path.join(out, "fillRatio.csv"))
    got = [float(x["fillRatio"]) for x in rows]
    check("fillRatio.csv: one line per output", len(rows) == 3, str(rows))
    check_value("fill ratio at t = 0.5 s (outer half in place) = m_outer / m_total", got[1], m_o / total,
                n_o / len(pos), 1e-6)
    check_value("fill ratio at t = 0 (all above the die)", got[0], 0.0, 0.5, 1e-12)

    # the columns
    cols = read_csv(os.path.join(out, "columns.csv"))
    x = np.array([float(c["x_m"]) for c in cols])
    y = np.array([float(c["y_m"]) for c in cols])
    vol = np.array([float(c["cavityVolume_m3"]) for c in cols])
    cmass = np.array([float(c["mass_kg"]) for c in cols])
    valid = np.array([c["valid"] == "1" for c in cols])
    rho = np.array([float(c["bulkDensity_kgm3"]) if c["bulkDensity_kgm3"] else np.nan for c in cols])
    check("columns.csv: 16 x 16 columns of 2.5 mm", len(cols) == 256 and abs(x[1 * 16] - x[0] - H) < 1e-12)
    corners = [np.hypot(x + sx * H / 2, y + sy * H / 2) for sx in (-1, 1) for sy in (-1, 1)]
    pure_outer = valid & (np.min(corners, axis=0) >= R_MID) & (np.max(corners, axis=0) <= 0.0199)
    pure_inner = valid & (np.min(corners, axis=0) >= 0.0081) & (np.max(corners, axis=0) <= R_MID)
    check("the ring has columns wholly in each half", pure_outer.sum() >= 8 and pure_inner.sum() >= 8,
          f"({pure_outer.sum()} outer, {pure_inner.sum()} inner)")
    worst = lambda sel, want: float(np.max(np.abs(rho[sel] - want)))  # noqa: E731
    wrong_depth = (DEPTH - 0.001) / DEPTH
    check_value("columns wholly in the outer half: bulk density = m/a^3 of its lattice (largest deviation)",
                worst(pure_outer, RHO_OUTER) + RHO_OUTER, RHO_OUTER, RHO_OUTER / wrong_depth, 1e-6 * RHO_OUTER)
    check_value("columns wholly in the inner half: bulk density = m/a^3 of its lattice (largest deviation)",
                worst(pure_inner, RHO_INNER) + RHO_INNER, RHO_INNER, RHO_INNER / wrong_depth, 1e-6 * RHO_INNER)
    rc = np.hypot(x, y)
    for label, sel, want in (("outer", valid & (rc >= R_MID), RHO_OUTER), ("inner", valid & (rc < R_MID), RHO_INNER)):
        mean = float(np.sum(cmass[sel]) / np.sum(vol[sel]))
        check_value(f"mean column density of the {label} half within 4 % of the constructed {want:.1f} kg/m3",
                    mean, want, want / wrong_depth * 1.0, 0.04 * want)

    # by hand: the columns' masses from the lattice (no sphere is cut by a column face),
    # their cavity volume from 100 x 100 points per column in the polygonal annulus
    ix = np.floor((pos[:, 0] + RO) / H).astype(int)
    iy = np.floor((pos[:, 1] + RO) / H).astype(int)
    hand_mass = np.bincount(ix * 16 + iy, weights=mass(rad), minlength=256)
    s = (np.arange(100) + 0.5) / 100 * H
    hand_cover = np.zeros(256)
    for k in range(256):
        X, Y = np.meshgrid(-RO + (k // 16) * H + s, -RO + (k % 16) * H + s, indexing="ij")
        hand_cover[k] = np.mean(in_polygon_annulus(X, Y))
    hand_vol = hand_cover * H * H * DEPTH
    check_value("column masses from the tool equal the lattice's (largest difference, kg)",
                float(np.max(np.abs(cmass - hand_mass))), 0.0, float(np.max(mass(rad))), 1e-9 * total)
    sure = np.abs(hand_cover - 0.5) > 0.02
    check("masked columns: those less than half under the opening",
          np.array_equal(valid[sure], hand_cover[sure] >= 0.5), f"({np.count_nonzero(valid)} valid)")
    sel = valid

    def stats(m, v):
        d = m / v
        mean = np.sum(m) / np.sum(v)
        return np.sqrt(np.sum(v * (d - mean) ** 2) / np.sum(v)) / mean, np.max(d) - np.min(d), mean

    cv_hand, span_hand, mean_hand = stats(hand_mass[sel], hand_vol[sel])
    # the wrong way: columns not clipped to the cavity (a full cell's area under the depth)
    cv_wrong, span_wrong, mean_wrong = stats(hand_mass[sel], np.full(sel.sum(), H * H * DEPTH))
    res = json.load(open(os.path.join(case, "postProcessing", "results.json")))
    value = lambda k: res.get(k, {}).get("value")  # noqa: E731
    check_value("fillDensity.coefficientOfVariation as computed by hand", value("fillDensity.coefficientOfVariation"),
                cv_hand, cv_wrong, 0.01 * cv_hand)
    check_value("fillDensity.maxMinusMin as computed by hand (kg/m3)", value("fillDensity.maxMinusMin"), span_hand,
                span_wrong, 0.01 * span_hand)
    check_value("fillDensity.mean as computed by hand (kg/m3)", value("fillDensity.mean"), mean_hand, mean_wrong,
                0.002 * mean_hand)
    check("fillDensity.max - fillDensity.min = maxMinusMin, the cell and the time in results.json",
          abs(value("fillDensity.max") - value("fillDensity.min") - value("fillDensity.maxMinusMin")) < 1e-9
          and value("fillDensity.cell") == H and value("fillDensity.time") == 1.0)
    check("results.json: the keys other tools wrote are kept", value("centralAngle") == 33.8)
    check_value("fillDensity.cavityVolume (m3)", value("fillDensity.cavityVolume"), RING_VOLUME,
                np.pi * (RO ** 2 - RI ** 2) * (DEPTH - 0.001), 1e-6 * RING_VOLUME)

    # mass per region: the west half (x < 0) and the 2 x 2 grid's quadrants
    west = pos[:, 0] < 0
    check_value("region west: the mass of the spheres with x < 0 (kg)", value("fillDensity.region.west.mass"),
                float(np.sum(mass(rad[west]))), total, 1e-9 * total)
    check_value("region west: bulk density = its mass / half the cavity (kg/m3)",
                value("fillDensity.region.west.bulkDensity"), float(np.sum(mass(rad[west]))) / (RING_VOLUME / 2),
                float(np.sum(mass(rad[west]))) / RING_VOLUME, 1e-6 * RHO_OUTER)
    quadrant_sum = 0.0
    for i in range(2):
        for j in range(2):
            sel_q = ((pos[:, 0] >= 0) == bool(i)) & ((pos[:, 1] >= 0) == bool(j))
            want = float(np.sum(mass(rad[sel_q])))
            quadrant_sum += value(f"fillDensity.region.grid_{i}_{j}.mass")
            check_value(f"region grid_{i}_{j}: the mass of the spheres in the quadrant (kg)",
                        value(f"fillDensity.region.grid_{i}_{j}.mass"), want, want + float(np.max(mass(rad))),
                        1e-9 * total)
    check_value("the quadrants' masses add up to the mass in the cavity (kg)", quadrant_sum, total, total - m_i,
                1e-9 * total)
    regions = read_csv(os.path.join(out, "regions.csv"))
    check("regions.csv: the named region and the four of the grid", [x["region"] for x in regions]
          == ["west", "grid_0_0", "grid_0_1", "grid_1_0", "grid_1_1"], str([x["region"] for x in regions]))

    # the x-z section through y = 0: cells of the outer half's two lattice rows
    sec = read_csv(os.path.join(out, "sectionXZ.csv"))
    sx = np.array([float(c["x_m"]) for c in sec])
    sr = np.array([float(c["bulkDensity_kgm3"]) if c["bulkDensity_kgm3"] else np.nan for c in sec])
    cell_outer = (np.abs(sx) - H / 2 >= R_MID) & (np.abs(sx) + H / 2 <= 0.0199)
    cell_inner = (np.abs(sx) - H / 2 >= 0.0081) & (np.abs(sx) + H / 2 <= R_MID)
    check("sectionXZ: cells wholly in each half", cell_outer.sum() >= 6 and cell_inner.sum() >= 6)
    check_value("sectionXZ: outer cells' bulk density (largest deviation from m/a^3)",
                float(np.max(np.abs(sr[cell_outer] - RHO_OUTER))) + RHO_OUTER, RHO_OUTER, RHO_INNER, 1e-3 * RHO_OUTER)
    check_value("sectionXZ: inner cells' bulk density (largest deviation from m/a^3)",
                float(np.max(np.abs(sr[cell_inner] - RHO_INNER))) + RHO_INNER, RHO_INNER, RHO_OUTER, 1e-3 * RHO_INNER)
    core = np.abs(sx) + H / 2 <= 0.0079
    check("sectionXZ: the core is masked (no bulk density)", core.any() and np.all(np.isnan(sr[core])))

    # the pictures and the VTK file
    for png in ("map.png", "sectionXZ.png", "sectionYZ.png", "fillRatio.png"):
        path = os.path.join(out, png)
        check(f"fillDensity.py writes {png}", os.path.exists(path) and open(path, "rb").read(4) == b"\x89PNG")
    vtk = open(os.path.join(out, "fillDensity.vtk")).read().split("\n")
    dims = [ln for ln in vtk if ln.startswith("DIMENSIONS")]
    ncell = [ln for ln in vtk if ln.startswith("CELL_DATA")]
    ok = vtk[0].startswith("# vtk DataFile Version") and vtk[2] == "ASCII" and dims == ["DIMENSIONS 17 17 7"] \
        and ncell == ["CELL_DATA 1536"]
    check("fillDensity.vtk: legacy STRUCTURED_POINTS, 16 x 16 x 6 cells", ok, f"{dims} {ncell}")
    if ok:
        start = vtk.index("SCALARS bulkDensity float 1") + 2
        values = np.array(" ".join(vtk[start:start + 1536 // 8]).split(), float)
        field = values.reshape(6, 16, 16)            # z, y, x
        i = int(np.argmin(np.abs(x.reshape(16, 16)[:, 0] - 0.01625)))   # x column 15-17.5 mm, y 0-2.5 mm
        j = 8
        check_value("fillDensity.vtk: an outer cell's local bulk density", float(field[2, j, i]), RHO_OUTER,
                    RHO_INNER, 1e-3 * RHO_OUTER)
        check("fillDensity.vtk: the fields bulkDensity, columnBulkDensity, cavityFraction, valid",
              all(f"SCALARS {n}" in "\n".join(vtk) for n in ("bulkDensity", "columnBulkDensity", "cavityFraction",
                                                              "valid")))

    # with -bulkDensity: the fill ratio against the cavity's volume
    r = run_tool("-case", case, "-stl", stl, "-cell", H, "-bulkDensity", 700, "-time", 0.6)
    rows = read_csv(os.path.join(out, "fillRatio.csv")) if r.returncode == 0 else []
    check("-bulkDensity 700 -time 0.6 (the output at 0.5 s): exit 0", r.returncode == 0, r.stderr.strip()[-300:])
    if rows:
        check_value("fill ratio at t = 1 s = mass / (cavity volume x 700)", float(rows[2]["fillRatio"]),
                    total / (RING_VOLUME * 700), total / (np.pi * (RO ** 2 - RI ** 2) * (DEPTH - 0.001) * 700), 1e-6)
        res = json.load(open(os.path.join(case, "postProcessing", "results.json")))
        check("-time 0.6: the map is of the output at t = 0.5 s", res["fillDensity.time"]["value"] == 0.5)
        outer_mass = np.bincount(ix[:n_o] * 16 + iy[:n_o], weights=mass(ro), minlength=256)
        check_value("-time 0.5 s: the map's mean = the outer half's (kg/m3)", res["fillDensity.mean"]["value"],
                    float(np.sum(outer_mass[sel]) / np.sum(hand_vol[sel])), mean_hand, 0.002 * mean_hand)


# ------------------------------------------------------------------ two levels
@test
def two_level_cavity():
    case = os.path.join(TMP, "two_level")
    stl = os.path.join(TMP, "two_level_mm.stl")
    write_binary_stl(stl, extruded_triangles(TWO_LEVEL_MM, 0, 30))
    a, r = 0.001, 0.0004
    g = (np.arange(30) + 0.5) * a
    X, Y, Z = np.meshgrid(g, g, -(np.arange(20) + 0.5) * a, indexing="ij")
    p = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    p = p[(p[:, 2] > -0.010) | (p[:, 0] < 0.010)]
    write_case(case, [(2.0, p, np.full(len(p), r))])
    rho_lattice = RHO_S * 4 / 3 * np.pi * r ** 3 / a ** 3
    res_path = os.path.join(case, "postProcessing", "results.json")
    out = run_tool("-case", case, "-stl", stl, "-scale", 0.001, "-cell", 0.003)
    check("fillDensity.py on the two-level cavity (binary STL in mm): exit 0", out.returncode == 0,
          out.stderr.strip()[-600:])
    if out.returncode != 0:
        return
    res = json.load(open(res_path))
    cv = res["fillDensity.coefficientOfVariation"]["value"]
    cols = read_csv(os.path.join(case, "postProcessing", "fillDensity", "columns.csv"))
    x = np.array([float(c["x_m"]) for c in cols])
    vol = np.array([float(c["cavityVolume_m3"]) for c in cols])
    cmass = np.array([float(c["mass_kg"]) for c in cols])
    # the wrong way: each column as deep as the cavity at its centre
    centre_depth = np.where(x < 0.010, 0.020, 0.010)
    d_wrong = cmass / (0.003 ** 2 * centre_depth)
    cv_wrong = float(np.sqrt(np.mean((d_wrong - d_wrong.mean()) ** 2)) / d_wrong.mean())
    check("uniform packing on two levels: CV of the column densities below 2 %", cv < 0.02, f"(got {cv:.2e})")
    check("control: with each column's depth taken at its centre the CV is above 2 %", cv_wrong > 0.02,
          f"({cv_wrong:.3f})")
    straddle = np.abs(x - 0.0105) < 1e-9
    check_value("the column over the step (x 9-12 mm): volume 3 mm x (1 mm x 20 mm + 2 mm x 10 mm) (m3)",
                float(vol[straddle][0]), 0.003 * (0.001 * 0.020 + 0.002 * 0.010), 0.003 * 0.003 * 0.010, 1e-15)
    check_value("uniform packing on two levels: mean column density = m/a^3 (kg/m3)",
                res["fillDensity.mean"]["value"], rho_lattice, rho_lattice * 0.95, 1e-4 * rho_lattice)
    check_value("uniform packing on two levels: max - min of the columns (kg/m3)",
                res["fillDensity.maxMinusMin"]["value"], 0.0, float(d_wrong.max() - d_wrong.min()), 0.01 * rho_lattice)


@test
def spheres_split_over_columns():
    """Spheres cut by column faces: their mass is split by the volume on each side (by its
    centre alone it would all go to one column)."""
    case = os.path.join(TMP, "split")
    stl = os.path.join(TMP, "split_mm.stl")
    write_binary_stl(stl, extruded_triangles(TWO_LEVEL_MM, 0, 30))
    r = 0.0012
    centres = np.array([[3.0, 4.5, -5.0], [7.5, 6.0, -5.0], [15.0, 15.0, -5.0]]) * 1e-3
    write_case(case, [(1.0, centres, np.full(3, r))])
    out = run_tool("-case", case, "-stl", stl, "-scale", 0.001, "-cell", 0.003)
    check("fillDensity.py, three spheres on column faces: exit 0", out.returncode == 0, out.stderr.strip()[-300:])
    if out.returncode != 0:
        return
    cols = read_csv(os.path.join(case, "postProcessing", "fillDensity", "columns.csv"))
    m = float(mass(r))
    got = {(round(float(c["x_m"]) * 1e4), round(float(c["y_m"]) * 1e4)): float(c["mass_kg"]) for c in cols}
    for what, cells, share in (("a sphere on the face x = 3 mm", [(15, 45), (45, 45)], 0.5),
                               ("a sphere on the face y = 6 mm", [(75, 45), (75, 75)], 0.5),
                               ("a sphere on the corner (15, 15) mm", [(135, 135), (135, 165), (165, 135), (165, 165)],
                                0.25)):
        for cell in cells:
            check_value(f"{what}: the column at ({cell[0] / 10:g}, {cell[1] / 10:g}) mm holds {share:g} of it (kg)",
                        got.get(cell), share * m, m if cell == cells[-1] else 0.0,
                        (0.005 if share == 0.5 else 0.04) * m)


@test
def defaults_from_a_die_case():
    """A case written by writeDieCase.py: the cavity, the filled time, the region grid and the
    regions come from constant/dieCase.json when not given."""
    case = os.path.join(TMP, "die_case")
    os.makedirs(os.path.join(case, "constant", "triSurface"))
    write_ascii_stl(os.path.join(case, "constant", "triSurface", "cavity.stl"), ring_triangles())
    po, ro, pi, ri = ring_packing()
    pos, rad = np.vstack([po, pi]), np.concatenate([ro, ri])
    write_case(case, [(0.0, pos + [0, 0, 0.05], rad), (0.5, pos, rad), (1.0, pos - [0, 0, 0.05], rad)])
    r = run_tool("-case", case)
    check("control: without constant/dieCase.json and -stl the run is refused naming -stl", one_line_error(r, "-stl"),
          r.stderr.strip()[-300:])
    with open(os.path.join(case, "constant", "dieCase.json"), "w") as f:
        json.dump({"timeline_s": {"filled": 0.5, "opening": 0.5}, "regionGrid": [2, 1],
                   "regions_m": {"north": [-0.02, 0.0, 0.02, 0.02]}}, f)
    r = run_tool("-case", case, "-cell", H)
    check("a die case: fillDensity.py -case DIR alone runs", r.returncode == 0, r.stderr.strip()[-300:])
    if r.returncode != 0:
        return
    res = json.load(open(os.path.join(case, "postProcessing", "results.json")))
    value = lambda k: res.get(k, {}).get("value")  # noqa: E731
    check("a die case: the map is of the filled time (0.5 s), not of the latest output (1 s, the die emptied)",
          value("fillDensity.time") == 0.5, f"(got {value('fillDensity.time')})")
    total = float(np.sum(mass(rad)))
    north = float(np.sum(mass(rad[pos[:, 1] >= 0])))
    check_value("a die case: the region 'north' of dieCase.json (kg)", value("fillDensity.region.north.mass"), north,
                total, 1e-9 * total)
    check_value("a die case: its regionGrid 2 x 1, the region grid_0_0 is the half x < 0 (kg)",
                value("fillDensity.region.grid_0_0.mass"), float(np.sum(mass(rad[pos[:, 0] < 0]))), total,
                1e-9 * total)

    # With a pre-compaction stamp: its figures from dem/summary.csv's wall forces
    stamp = {"depth_m": 0.003, "pressed_s": 0.4, "released_s": 0.6}
    with open(os.path.join(case, "constant", "dieCase.json"), "w") as f:
        json.dump({"timeline_s": {"filled": 0.5, "opening": 0.5}, "regionGrid": [2, 1], "openingArea_m2": 4e-4,
                   "steps": {"stamp": stamp}}, f)
    summary = os.path.join(case, "dem", "summary.csv")
    value_of = lambda results, k: results.get(k, {}).get("value")  # noqa: E731

    def with_stamp(rows):
        with open(summary, "w") as f:
            f.write("time,step,wallForce_stamp_z,wallForce_dieWalls_z,wallForce_dieFloors_z\n")
            for t, stamp_z, walls_z in rows:
                f.write(f"{t},{int(t * 1000)},{stamp_z},{walls_z},{-stamp_z - walls_z}\n")
    # held 0.4-0.6 s: 10, 12, 14 N on the stamp, a quarter of it on the die wall; a peak of 20 N while pressing
    with_stamp([(0.0, 0.0, 0.0), (0.3, 20.0, -5.0), (0.4, 10.0, -2.5), (0.5, 12.0, -3.0), (0.6, 14.0, -3.5),
                (0.7, 0.0, 0.0)])
    r = run_tool("-case", case, "-cell", H)
    res = json.load(open(os.path.join(case, "postProcessing", "results.json")))
    check("a die case with a stamp: peak force, pressure (mean force held / opening area), die wall's share",
          r.returncode == 0 and value_of(res, "fillDensity.stamp.peakForce") == 20.0
          and abs(value_of(res, "fillDensity.stamp.pressure") - 12.0 / 4e-4) < 1e-9
          and abs(value_of(res, "fillDensity.stamp.dieWallShare") - 0.25) < 1e-12,
          r.stderr.strip()[-300:] + str({k: v for k, v in res.items() if "stamp" in k}))
    os.remove(os.path.join(case, "postProcessing", "results.json"))
    with_stamp([(0.0, 0.0, 0.0), (0.3, 20.0, -5.0), (0.4, 10.0, -2.5), (0.5, 12.0, -3.0)])
    r = run_tool("-case", case, "-cell", H)
    res = json.load(open(os.path.join(case, "postProcessing", "results.json")))
    check("a die case whose summary ends before the stamp is released: the map, no stamp figures, said so",
          r.returncode == 0 and "fillDensity.mean" in res and not any("stamp" in k for k in res)
          and "no stamp figures" in r.stdout, r.stdout.strip()[-200:])
    os.remove(os.path.join(case, "postProcessing", "results.json"))

    # A stamp of given mass (0.5 kg, its figures over 0.4-0.6 s): where it stood is the mean of the
    # summary's wallOffset_stamp then; on its stop (the stroke), that is said
    def weighted(rows, stroke=0.01):
        with open(os.path.join(case, "constant", "dieCase.json"), "w") as f:
            json.dump({"timeline_s": {"filled": 0.5, "opening": 0.5}, "regionGrid": [2, 1], "openingArea_m2": 4e-4,
                       "steps": {"stamp": {"mass_kg": 0.5, "stroke_m": stroke, "pressed_s": 0.4,
                                           "released_s": 0.6}}}, f)
        with open(summary, "w") as f:
            f.write("time,step,wallForce_stamp_z,wallForce_dieWalls_z,wallForce_dieFloors_z,wallOffset_stamp\n")
            for t, stamp_z, walls_z, offset in rows:
                f.write(f"{t},{int(t * 1000)},{stamp_z},{walls_z},{-stamp_z - walls_z},{offset}\n")
        r = run_tool("-case", case, "-cell", H)
        res = json.load(open(os.path.join(case, "postProcessing", "results.json")))
        os.remove(os.path.join(case, "postProcessing", "results.json"))
        return r, res
    resting = [(0.0, 0.0, 0.0, 0.0), (0.3, 6.0, -1.0, 0.002), (0.4, 4.9, -1.0, 0.0031), (0.5, 4.91, -1.2, 0.0030),
               (0.6, 4.9, -1.1, 0.0029), (0.7, 0.0, 0.0, 0.0)]
    r, res = weighted(resting)
    check("a stamp of given mass: its depth (mean offset while resting), pressure, share; no stop said",
          r.returncode == 0 and abs(value_of(res, "fillDensity.stamp.depth") - 0.003) < 1e-12
          and abs(value_of(res, "fillDensity.stamp.pressure") - 4.9033333333333 / 4e-4) < 1e-6
          and abs(value_of(res, "fillDensity.stamp.dieWallShare") - 1.1 / 4.9033333333333) < 1e-9
          and "stop" not in res["fillDensity.stamp.depth"]["description"] and "not at rest" not in r.stdout,
          r.stdout.strip()[-300:] + str({k: v for k, v in res.items() if "stamp" in k}))
    r, res = weighted([(t, 0.0, 0.0, min(o * 4, 0.004)) for t, _, _, o in resting], stroke=0.004)
    check("a stamp of given mass that reached its stop: the depth says so (the powder did not carry it)",
          r.returncode == 0 and value_of(res, "fillDensity.stamp.depth") == 0.004
          and "stood on its stop" in res["fillDensity.stamp.depth"]["description"],
          str({k: v for k, v in res.items() if "stamp" in k}))
    r, res = weighted([(t, f * 0.5, w, o) for t, f, w, o in resting])
    check("a stamp of given mass the powder carried only half of: 'not at rest' said",
          r.returncode == 0 and "not at rest" in r.stdout, r.stdout.strip()[-300:])
    os.remove(summary)


# ------------------------------------------------------------------ refused options
def outputs(case):
    d = os.path.join(case, "postProcessing")
    found = {}
    for base, _, files in os.walk(d):
        for n in files:
            found[os.path.join(base, n)] = open(os.path.join(base, n), "rb").read()
    return found


@test
def bad_options_are_refused():
    case = os.path.join(TMP, "options")
    stl = os.path.join(TMP, "options_ring.stl")
    write_ascii_stl(stl, ring_triangles())
    pos = np.array([[0.014, 0.0, -0.007], [-0.014, 0.0, -0.007], [0.0, 0.0, 0.05]])
    write_case(case, [(0.0, pos + [0, 0, 0.1], [5e-4] * 3), (1.0, pos, [5e-4] * 3)])
    r = run_tool("-case", case, "-stl", stl)
    check("control: a good run on the options case", r.returncode == 0, r.stderr.strip()[-300:])
    before = outputs(case)
    cases = [
        (["-cell", 0], "-cell"), (["-cell", -1], "-cell"), (["-cell", "nan"], "-cell"),
        (["-minCover", 0], "-minCover"), (["-minCover", 1.5], "-minCover"),
        (["-bulkDensity", -1], "-bulkDensity"), (["-time", "inf"], "-time"),
        (["-region", "r", 0, 0, 0, 0.01], "-region r"), (["-region", "r", 0, 0, "nan", 0.01], "-region r"),
        (["-region", "r", 0.05, 0.05, 0.06, 0.06], "-region r"),
        (["-region", "r", 0, 0, 0.01, 0.01, "-region", "r", 0, 0, 0.01, 0.01], "-region r"),
        (["-regionGrid", 0, 2], "-regionGrid"), (["-sectionY", 0.03], "-sectionY"),
        (["-sectionX", -0.021], "-sectionX"),
        (["-samples", 0], "-samples"), (["-scale", 0], "-scale"), (["-name", "a/b"], "-name"),
        (["-time", 0], "t = 0 s"),
    ]
    for args, words in cases:
        r = run_tool("-case", case, "-stl", stl, *args)
        check(f"fillDensity.py {' '.join(str(x) for x in args)}: refused naming {words}", one_line_error(r, words),
              f"(exit {r.returncode}, {r.stderr.strip()[-300:]!r})")
    for args, words in ((["-stl", os.path.join(TMP, "none.stl")], "none.stl"), (["-stl", __file__], "not an STL")):
        r = run_tool("-case", case, *args)
        check(f"fillDensity.py {args[0]} {os.path.basename(args[1])}: one line naming the file",
              one_line_error(r, words),
              f"(exit {r.returncode}, {r.stderr.strip()[-300:]!r})")
    r = run_tool("-case", os.path.join(TMP, "no-such-case"), "-stl", stl)
    check("fillDensity.py without a case: one line naming it, exit 1",
          one_line_error(r, "no-such-case") and r.returncode == 1, r.stderr.strip()[-300:])
    check("refused runs leave the outputs as they were", outputs(case) == before)
    with open(os.path.join(case, "postProcessing", "results.json"), "w") as f:
        f.write("{not json")
    r = run_tool("-case", case, "-stl", stl)
    check("a results.json that is not JSON: refused naming it, not overwritten",
          one_line_error(r, "results.json", "not valid JSON")
          and open(os.path.join(case, "postProcessing", "results.json")).read() == "{not json", r.stderr.strip()[-300:])


shutil.rmtree(TMP, ignore_errors=True)
print(f"{PASSED} passed, {FAILED} failed")
sys.exit(1 if FAILED else 0)
