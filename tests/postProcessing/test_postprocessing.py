"""Tests of tools/diefillpost on synthetic data with known answers (see run)."""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.abspath(os.path.join(os.path.dirname(__file__), "../.."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import h5py  # noqa: E402

from diefillpost import foamdict, geometry, plate, plots, profile, results, series, summary  # noqa: E402

PASSED, FAILED = 0, 0
TMP = tempfile.mkdtemp(prefix="diefillpost_")


def check(name, ok, detail=""):
    global PASSED, FAILED
    if ok:
        PASSED += 1
        print(f"PASS: {name} {detail}")
    else:
        FAILED += 1
        print(f"FAIL: {name} {detail}")


def test(fn):
    try:
        fn()
    except Exception as e:  # a crashing test is a failed test
        check(fn.__name__, False, f"raised {type(e).__name__}: {e}")
    return fn


def cone_particles(angle_deg, height, r_particle, rng, base_z=0.0, centre=(0.0, 0.0)):
    """Spheres filling a cone (apex up) whose surface h(rho) = height - tan(a) rho; the
    outermost layer touches the surface (top = centre + radius on it)."""
    slope = np.tan(np.radians(angle_deg))
    R = height / slope
    pts = []
    # surface layer: tops exactly on the cone surface
    n_surface = int(4 * np.pi * R**2 / r_particle**2)
    rho = R * np.sqrt(rng.random(n_surface))
    phi = 2 * np.pi * rng.random(n_surface)
    top = height - slope * rho
    pts.append(np.column_stack([centre[0] + rho * np.cos(phi), centre[1] + rho * np.sin(phi), base_z + top - r_particle]))
    # interior: centres well below the surface
    n_in = n_surface
    rho = R * np.sqrt(rng.random(n_in))
    phi = 2 * np.pi * rng.random(n_in)
    z = (height - slope * rho) * rng.random(n_in) - 2 * r_particle
    pts.append(np.column_stack([centre[0] + rho * np.cos(phi), centre[1] + rho * np.sin(phi), base_z + z]))
    p = np.vstack(pts)
    return p[p[:, 2] >= base_z + r_particle * 0.0 - 10]  # keep all; tests only use the max per bin


@test
def cone_angle_is_recovered():
    rng = np.random.default_rng(1)
    for angle in (20.0, 28.0, 35.0):
        p = cone_particles(angle, 0.02, 5e-4, rng)
        r, h, n = profile.radial_profile(p, 5e-4, (0, 0, 0), (0, 0, 1), bin_width=1e-3, sectors=8)
        fit = profile.fit_line(r, h, profile.flank_window(r, h, 0.2, 0.8))
        check(f"cone {angle:g} deg: fitted angle within 0.5 deg", abs(fit["angle"] - angle) < 0.5,
              f"(got {fit['angle']:.3f}, window {fit['window'][0]*1e3:.1f}-{fit['window'][1]*1e3:.1f} mm)")


@test
def tilted_axis_cone():
    # the same cone about an axis tilted 20 deg from z, built in the axis frame and rotated
    rng = np.random.default_rng(2)
    p = cone_particles(30.0, 0.015, 4e-4, rng)
    R = geometry.rotation_matrix((1, 0, 0), np.radians(20))
    origin = np.array([0.01, -0.02, 0.005])
    pw = p @ R.T + origin
    r, h, _ = profile.radial_profile(pw, 4e-4, origin, R @ np.array([0, 0, 1.0]), bin_width=8e-4)
    fit = profile.fit_line(r, h, profile.flank_window(r, h))
    check("cone about a tilted, shifted axis: 30 deg within 0.5 deg", abs(fit["angle"] - 30) < 0.5, f"(got {fit['angle']:.3f})")


@test
def profile_heights_are_tops():
    # one particle per 1 mm bin, centre height 2x mm + radius offsets: max top per bin exact
    x = np.arange(20) * 1e-3 + 0.5e-3
    radius = np.full(20, 2e-4)
    z = 0.003 + 0.5 * x
    extra = np.column_stack([x, np.zeros(20), z - 1e-3])  # lower particles that must not count
    pos = np.vstack([np.column_stack([x, np.zeros(20), z]), extra])
    c, h = profile.line_profile(pos, np.concatenate([radius, radius]), (0, 0, 0), (1, 0, 0), (0, 0, 1), 1e-3, extent=(0, 0.02))
    check("line profile: max top per bin", np.allclose(h, z + 2e-4, atol=1e-12), f"(max err {np.max(np.abs(h - z - 2e-4)):.2e})")
    check("line profile: bin centres", np.allclose(c, x))
    fit = profile.fit_line(c, h, (0, 0.02))
    check("line fit: slope 0.5 -> 26.565 deg", abs(fit["angle"] - np.degrees(np.arctan(0.5))) < 1e-9 and abs(fit["intercept"] - 0.0032) < 1e-12)
    band = profile.line_profile(pos + [0, 0.01, 0], np.concatenate([radius, radius]), (0, 0, 0), (1, 0, 0), (0, 0, 1), 1e-3,
                                extent=(0, 0.02), band=0.005)[1]
    check("line profile: band excludes particles off the line", np.all(np.isnan(band)))
    try:
        profile.fit_line(c[:2], h[:2], (0, 1))
        check("fit needs 3 points", False)
    except ValueError:
        check("fit needs 3 points", True)


@test
def masses_in_regions():
    # 4 x 4 x 4 grid of unit-density particles
    g = np.stack(np.meshgrid(*[np.arange(4) * 1e-3] * 3, indexing="ij"), -1).reshape(-1, 3)
    f = series.Frame.from_arrays(g, 1e-4, density=1000.0)
    m1 = 1000.0 * 4 / 3 * np.pi * 1e-12
    box = geometry.Box((-1e-4, -1e-4, -1e-4), (1.5e-3, 3.5e-3, 0.5e-3))  # x in {0,1}, y all, z {0}
    check("mass in box: 8 particles", abs(geometry.mass_in_region(f, box) - 8 * m1) < 1e-18)
    cyl = geometry.Cylinder((0, 0, 0), (0, 0, 1), 1.05e-3, -1e-4, 2.5e-3)  # (0,0),(1,0),(0,1) x z {0,1,2}
    check("mass in cylinder: 9 particles", abs(geometry.mass_in_region(f, cyl) - 9 * m1) < 1e-18)
    d = geometry.region_from_dict({"type": "cylinder", "axisPoint": [0, 0, 0], "axis": [0, 0, 2], "radius": 1.05e-3, "range": [-1e-4, 2.5e-3]})
    check("region from a demProperties dict", abs(geometry.mass_in_region(f, d) - 9 * m1) < 1e-18)
    check("fill ratio", np.allclose(summary.fill_ratio([0, 5, 10], 10.0), [0, 0.5, 1.0]))


@test
def dictionary_reader():
    path = os.path.join(TMP, "dict")
    with open(os.path.join(TMP, "inc"), "w") as f:
        f.write("included 3;\n")
    with open(path, "w") as f:
        f.write('FoamFile { version 2.0; }\n/* block\n comment */ d 0.002; // line\n'
                'm { a $d; v (1 2 -3e-1); w "q s"; l ((1 2) (3 4)); #include "inc" }\n'
                'walls { p { type plane; motion { s1 { type rotate; start 0; end 1; angularVelocity 10; } } } }\n')
    d = foamdict.read(path)
    ok = (d["d"] == 0.002 and d["m"]["a"] == 0.002 and d["m"]["v"] == [1, 2, -0.3] and d["m"]["w"] == "q s"
          and d["m"]["l"] == [[1, 2], [3, 4]] and d["m"]["included"] == 3 and "FoamFile" not in d
          and d["walls"]["p"]["motion"]["s1"]["type"] == "rotate")
    check("OpenFOAM dictionary subset: values, lists, $var, #include, comments", ok, str(d) if not ok else "")
    case_dict = foamdict.read(os.path.join(ROOT, "tutorials/calibration/reposeAngle/constant/demProperties"))
    check("reads the reposeAngle tutorial's demProperties", case_dict["walls"]["tube"]["radius"] == 0.0215)


@test
def wall_pose():
    motion = {"a": {"type": "translate", "start": 0, "end": 1, "velocity": [0, 0, 0.1]},
              "b": {"type": "rotate", "start": 1, "end": 2, "axisPoint": [0, 0, 0.1], "axis": [0, -1, 0], "angularVelocity": 30}}
    w = geometry.WallPose(motion)
    R, x0 = w.pose(2.0)
    # point (1,0,0) of the reference: lifted by 0.1, then rotated 30 deg about -y through (0,0,0.1)
    p = R @ np.array([1.0, 0, 0]) + x0
    ok = np.allclose(p, [np.cos(np.radians(30)), 0, 0.1 + np.sin(np.radians(30))])
    check("wall pose: translate then rotate about a hinge", ok, str(p))
    check("rotation angle at mid-segment", abs(w.rotation_angle(1.5) - 15) < 1e-12 and w.rotation_angle(5) == 30)
    check("to_reference inverts the pose", np.allclose(w.to_reference(p[None, :], 2.0), [[1, 0, 0]]))


def write_case(case, props_text, frames_data, summary_rows, summary_header="time,step,particles,kineticEnergy,coordinationNumber,wallContacts,lostCount,lostMass"):
    os.makedirs(os.path.join(case, "constant"), exist_ok=True)
    os.makedirs(os.path.join(case, "dem"), exist_ok=True)
    with open(os.path.join(case, "constant", "demProperties"), "w") as f:
        f.write(props_text)
    lines = []
    for step, (t, pos, rad) in enumerate(frames_data):
        name = f"particles_{step:09d}.h5"
        n = len(pos)
        with h5py.File(os.path.join(case, "dem", name), "w") as h:
            h.attrs["time"] = t
            h.attrs["step"] = step
            h["id"] = np.arange(n, dtype=np.int64)
            h["position"] = np.asarray(pos, float)
            h["velocity"] = np.zeros((n, 3))
            h["omega"] = np.zeros((n, 3))
            h["force"] = np.zeros((n, 3))
            h["radius"] = np.asarray(rad, float)
            h["mass"] = 2650 * 4 / 3 * np.pi * np.asarray(rad, float) ** 3
            h["material"] = np.zeros(n, np.int32)
        lines.append(f"{t} {step} {n} {name}\n")
    with open(os.path.join(case, "dem", "particles.series"), "w") as f:
        f.writelines(lines)
    with open(os.path.join(case, "dem", "summary.csv"), "w") as f:
        f.write(summary_header + "\n")
        for r in summary_rows:
            f.write(",".join(str(v) for v in r) + "\n")


@test
def series_reader():
    case = os.path.join(TMP, "series")
    pos = np.array([[0, 0, 1.0], [1, 0, 0]])
    write_case(case, "a 1;\n", [(0.0, pos, [0.1, 0.2]), (0.5, pos + 1, [0.1, 0.2])], [(0, 0, 2, 0, 0, 0, 0, 0)])
    e = series.list_frames(case)
    f = series.last_frame(case)
    check("series index: times and files", [t for t, _ in e] == [0.0, 0.5])
    check("frame arrays", f.time == 0.5 and np.allclose(f.position, pos + 1) and f.count == 2
          and abs(f.total_mass - 2650 * 4 / 3 * np.pi * (0.1**3 + 0.2**3)) < 1e-9)
    os.remove(os.path.join(case, "dem", "particles.series"))
    check("glob fallback without the index", [t for t, _ in series.list_frames(case)] == [0.0, 0.5])
    s = summary.read(case)
    check("summary.csv columns", s["particles"][0] == 2 and "lostMass" in s)


@test
def plate_slid_fraction():
    hinge_motion = {"tilt": {"type": "rotate", "start": 0.0, "end": 1.0, "axisPoint": [0, 0, 0], "axis": [0, -1, 0], "angularVelocity": 40}}
    pose = geometry.WallPose(hinge_motion)
    lo, hi = np.array([0, -0.03, -0.002]), np.array([0.08, 0.03, 0.0])
    # 10 particles in the reference frame: 6 on the plate, 2 beyond its end, 1 too high, 1 below
    ref = np.array([[0.01 * k, 0, 0.001] for k in range(1, 7)] + [[-0.001, 0, 0.001], [0.09, 0, 0.001], [0.02, 0, 0.05], [0.02, 0, -0.01]])
    t = 0.5
    R, x0 = pose.pose(t)
    f = series.Frame.from_arrays(ref @ R.T + x0, 5e-4)
    mask = plate.on_plate(f, pose, t, lo, hi, 0.02)
    check("on-plate mask on a plate tilted 20 deg", mask.tolist() == [True] * 6 + [False] * 4)
    angles = np.array([0, 10, 20, 30, 40.0])
    frac = np.array([0, 0.1, 0.3, 0.7, 1.0])
    check("angle at 50 % by interpolation", abs(plate.angle_at_fraction(angles, frac, 0.5) - 25.0) < 1e-12)
    check("angle at fraction never reached", plate.angle_at_fraction(angles, frac * 0.4, 0.5) is None)
    check("monotone test", plate.is_monotone_non_decreasing(frac) and not plate.is_monotone_non_decreasing(frac[::-1]))
    stl = os.path.join(TMP, "plate.stl")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "writeBoxStl.py"), stl, "0", "-0.03", "-0.002", "0.08", "0.03", "0"], check=True)
    blo, bhi = plate.read_stl_bounds(stl)
    check("writeBoxStl + read_stl_bounds", np.allclose(blo, lo) and np.allclose(bhi, hi))
    v = np.array([l.split()[1:4] for l in open(stl) if l.strip().startswith("vertex")], float).reshape(-1, 3, 3)
    nrm = np.array([l.split()[2:5] for l in open(stl) if l.strip().startswith("facet")], float)
    centre = v.reshape(-1, 3).mean(0)
    check("box STL normals point outwards", len(v) == 12 and all(np.dot(nrm[i], v[i].mean(0) - centre) > 0 for i in range(12)))


@test
def repose_script_end_to_end():
    case = os.path.join(TMP, "repose")
    rng = np.random.default_rng(3)
    p = cone_particles(28.0, 0.022, 6e-4, rng)
    props = ("walls { floor { type plane; material steel; point (0 0 0); normal (0 0 1); }\n"
             " tube { type cylinder; material steel; axisPoint (0 0 0); axis (0 0 1); radius 0.0215; range (0 0.5); side inside;\n"
             "  motion { lift { type translate; start 0.1; end 0.3; velocity (0 0 0.2); } } removeAt 0.3; } }\n"
             "contactModel { normal hertz; tangential history; rolling cdt; }\n")
    write_case(case, props, [(0.5, p, np.full(len(p), 6e-4))], [(0.5, 100, len(p), 1e-9, 4, 0, 0, 0)])
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "reposeAngle.py"), "-case", case], capture_output=True, text=True)
    ok = r.returncode == 0
    res = json.load(open(os.path.join(case, "postProcessing", "results.json"))) if ok else {}
    angle = res.get("reposeAngle", {}).get("value", -1)
    check("reposeAngle.py on a synthetic 28 deg cone: within 0.5 deg", ok and abs(angle - 28) < 0.5, f"(got {angle}) {r.stderr[-300:]}")
    for png in ("reposeProfile.png", "sideView.png"):
        pth = os.path.join(case, "postProcessing", png)
        check(f"reposeAngle.py writes {png}", os.path.exists(pth) and open(pth, "rb").read(4) == b"\x89PNG")
    csvp = os.path.join(case, "postProcessing", "results.csv")
    check("results.csv lists the angle", os.path.exists(csvp) and "reposeAngle" in open(csvp).read())


@test
def plate_script_end_to_end():
    # 10 particles on a plate tilted at 10 deg/s; at output k (angle 5k deg) k particles have fallen off
    case = os.path.join(TMP, "plate")
    os.makedirs(os.path.join(case, "constant", "triSurface"), exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "writeBoxStl.py"), os.path.join(case, "constant/triSurface/plate.stl"),
                    "0", "-0.03", "-0.002", "0.08", "0.03", "0"], check=True)
    props = ("simulation { gravity (0 0 -9.81); }\ncontactModel { normal hertz; tangential history; rolling epsd2; }\n"
             "walls { plate { type stl; material steel; file \"constant/triSurface/plate.stl\";\n"
             " motion { tilt { type rotate; start 0; end 5; axisPoint (0 0 0); axis (0 -1 0); angularVelocity 10; } } } }\n")
    pose = geometry.WallPose({"tilt": {"type": "rotate", "start": 0, "end": 5, "axisPoint": [0, 0, 0], "axis": [0, -1, 0], "angularVelocity": 10}})
    ref = np.array([[0.005 + 0.007 * k, 0, 0.0006] for k in range(10)])
    frames_data, rows = [], []
    for k in range(11):
        t = 0.5 * k
        q = ref.copy()
        q[:k, 2] = -0.05  # fallen: below the plate
        R, x0 = pose.pose(t)
        frames_data.append((t, q @ R.T + x0, np.full(10, 5e-4)))
        rows.append((t, k, 10, 0, 0, 0, 0, 0))
    write_case(case, props, frames_data, rows)
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "inclinedPlate.py"), "-case", case], capture_output=True, text=True)
    ok = r.returncode == 0
    res = json.load(open(os.path.join(case, "postProcessing", "results.json"))) if ok else {}
    a50 = res.get("angleAt50PercentSlid", {}).get("value", -1)
    check("inclinedPlate.py: 50 % slid exactly at 25 deg", ok and abs(a50 - 25.0) < 1e-9, f"(got {a50}) {r.stderr[-300:]}")
    check("inclinedPlate.py: monotone, final fraction 1", ok and res["slidFractionMonotone"]["value"] and abs(res["finalSlidFraction"]["value"] - 1) < 1e-12)
    check("inclinedPlate.py writes slidFraction.png", os.path.exists(os.path.join(case, "postProcessing", "slidFraction.png")))


@test
def command_line_tools():
    case = os.path.join(TMP, "cli")
    pos = np.array([[0.001, 0, 0.001], [0.002, 0, 0.003], [0.05, 0, 0.001]])
    write_case(case, "a 1;\n", [(0.0, pos, [5e-4] * 3), (1.0, pos + [0, 0, 0.1], [5e-4] * 3)], [(0, 0, 3, 0, 0, 0, 0, 0)])
    m1 = 2650 * 4 / 3 * np.pi * 5e-4**3
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "regionMasses.py"), "-case", case,
                        "-box", "near", "0", "-1", "0", "0.01", "1", "0.01", "-reference", str(2 * m1)], capture_output=True, text=True)
    rows = open(os.path.join(case, "postProcessing", "regionMasses.csv")).read().splitlines() if r.returncode == 0 else []
    ok = len(rows) == 3 and abs(float(rows[1].split(",")[1]) - 2 * m1) < 1e-5 * m1 and rows[1].split(",")[2] == "1" \
        and float(rows[2].split(",")[1]) == 0.0
    check("regionMasses.py: mass and fill ratio in a box over time", ok, r.stderr[-300:] + str(rows))
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "bedProfile.py"), "-case", case, "-time", "0",
                        "-line", "0", "0", "0", "1", "0", "0", "-binWidth", "0.001"], capture_output=True, text=True)
    rows = open(os.path.join(case, "postProcessing", "bedProfile.csv")).read().splitlines()[1:] if r.returncode == 0 else []
    ok = len(rows) > 3 and abs(float(rows[0].split(",")[1]) - 0.0015) < 1e-12 and abs(float(rows[1].split(",")[1]) - 0.0035) < 1e-12
    check("bedProfile.py: tops of the particles per 1 mm bin", ok, r.stderr[-300:] + str(rows[:3]))
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "sideView.py"), "-case", case, "-name", "sv"], capture_output=True, text=True)
    check("sideView.py writes a PNG", r.returncode == 0 and os.path.exists(os.path.join(case, "postProcessing", "sv.png")))


@test
def edge_angle_is_recovered():
    # A block of spheres whose right edge leans at a known angle (90 deg: a vertical
    # wall of powder, as the die's right border; 60 and 45 deg: leaning edges).
    rng = np.random.default_rng(7)
    r = 5e-4
    for angle in (90.0, 60.0, 45.0):
        cot = 1.0 / np.tan(np.radians(angle))
        h = rng.random(20000) * 0.02
        edge = 0.02 - cot * h                      # edge position at height h
        s = edge - r - rng.random(20000) * 0.02    # centres inside, outermost touching
        s[:2000] = edge[:2000] - r                 # an outer layer exactly on the edge
        p = np.column_stack([s, (rng.random(20000) - 0.5) * 0.004, h])
        fit = profile.edge_angle(p, r, band=0.002, bin_height=1e-3)
        check(f"edge at {angle:g} deg: fitted within 1 deg", abs(fit["angle"] - angle) < 1.0,
              f"(got {fit['angle']:.2f} over heights {fit['window'][0]*1e3:.1f}-{fit['window'][1]*1e3:.1f} mm)")


@test
def plots_and_results():
    rng = np.random.default_rng(4)
    f = series.Frame.from_arrays(rng.random((300, 3)) * 0.01, 3e-4, velocity=rng.random((300, 3)))
    out = os.path.join(TMP, "pics")
    os.makedirs(out, exist_ok=True)
    for cb in ("height", "speed", "omega"):
        pth = plots.side_view(os.path.join(out, f"side_{cb}.png"), f, color_by=cb)
        check(f"side view coloured by {cb} is a PNG", open(pth, "rb").read(4) == b"\x89PNG")
    jp, cp = results.write(os.path.join(TMP, "res"), {"a": {"value": 1.5, "unit": "deg"}, "b": [1, 2], "c": "x"})
    back = results.read(os.path.join(TMP, "res"))
    check("results.json round trip", back["a"]["value"] == 1.5 and back["b"]["value"] == [1, 2] and back["c"]["value"] == "x")
    check("results.csv rows", open(cp).read().splitlines()[1:] == ["a,1.5,deg,", "b,1 2,,", "c,x,,"])


@test
def missing_case_is_one_line_and_exit_1():
    # Every case script, pointed at a folder without a case: one line naming the
    # script and the missing file, exit status 1, no Python traceback.
    absent = os.path.join(TMP, "no-such-case")
    for script, args in (("dieFilling.py", ["-case", absent]), ("reposeAngle.py", ["-case", absent]),
                         ("inclinedPlate.py", ["-case", absent]), ("regionMasses.py", ["-case", absent]),
                         ("sideView.py", ["-case", absent]),
                         ("bedProfile.py", ["-case", absent, "-axis", "0", "0", "0", "0", "0", "1"]),
                         ("plotCapillaryScaling.py", [os.path.join(absent, "scaling.csv")])):
        r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", script)] + args, capture_output=True, text=True)
        lines = r.stderr.strip().splitlines()
        check(f"{script} without a case: one line naming it, exit 1",
              r.returncode == 1 and len(lines) == 1 and lines[0].startswith(f"{script}: error: ")
              and "no-such-case" in lines[0] and "Traceback" not in r.stderr,
              f"(exit {r.returncode}, stderr {r.stderr.strip()[-300:]!r})")


@test
def help_option_of_every_tool():
    # -help (OpenFOAM's and demRun's spelling), -h and --help print the usage and exit 0;
    # argparse alone read '-help' as '-h elp' and failed with exit 2.
    tools = sorted(f for f in os.listdir(os.path.join(ROOT, "tools")) if f.endswith(".py") and not f.startswith("_"))
    check("the tools to ask for help", len(tools) >= 8, f"({', '.join(tools)})")
    for script in tools:
        for option in ("-help", "-h", "--help"):
            r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", script), option], capture_output=True, text=True)
            check(f"{script} {option}: usage on stdout, exit 0",
                  r.returncode == 0 and ("usage:" in r.stdout.lower()) and r.stderr == "",
                  f"(exit {r.returncode}, stderr {r.stderr.strip()[-200:]!r})")


def run_tool(script, *args):
    return subprocess.run([sys.executable, os.path.join(ROOT, "tools", script)] + [str(a) for a in args],
                          capture_output=True, text=True)


def one_line_error(r, script, *words):
    """A refused run: exit status not 0, one line '<script>: error: ...' holding all
    `words`, no traceback."""
    lines = r.stderr.strip().splitlines()
    return (r.returncode != 0 and len(lines) == 1 and lines[0].startswith(f"{script}: error: ")
            and all(w in lines[0] for w in words) and "Traceback" not in r.stderr)


def small_case(name):
    """A case of 3 particles at t = 0 and t = 1 (the cli case of command_line_tools)."""
    case = os.path.join(TMP, name)
    pos = np.array([[0.001, 0, 0.001], [0.002, 0, 0.003], [0.05, 0, 0.001]])
    write_case(case, "a 1;\n", [(0.0, pos, [5e-4] * 3), (1.0, pos + [0, 0, 0.1], [5e-4] * 3)],
               [(0, 0, 3, 0, 0, 0, 0, 0), (1, 1, 3, 0, 0, 0, 0, 0)])
    return case


def outputs(case):
    """{name: content} of the files in case/postProcessing."""
    d = os.path.join(case, "postProcessing")
    return {n: open(os.path.join(d, n), "rb").read() for n in os.listdir(d)} if os.path.isdir(d) else {}


@test
def bad_option_values_are_refused():
    # Zero, negative, NaN or contradictory values of the numeric options: one line
    # naming the option, a non-zero exit, and no output written.  Before, -sectors 0
    # ended in an IndexError traceback, -binWidth -1 wrote a garbage bedProfile.csv
    # with exit 0, a -box with min > max gave mass 0 at every time with exit 0.
    case = small_case("options")
    line = ["-line", 0, 0, 0, 1, 0, 0]
    axis = ["-axis", 0, 0, 0, 0, 0, 1]
    cases = [
        ("bedProfile.py", axis + ["-sectors", 0], "-sectors"),
        ("bedProfile.py", axis + ["-sectors", -3], "-sectors"),
        ("bedProfile.py", line + ["-binWidth", -1], "-binWidth"),
        ("bedProfile.py", line + ["-binWidth", 0], "-binWidth"),
        ("bedProfile.py", line + ["-binWidth", "nan"], "-binWidth"),
        ("bedProfile.py", line + ["-band", 0], "-band"),
        ("bedProfile.py", ["-line", 0, 5, 0, 1, 0, 0, "-band", 1e-6], "-band"),
        ("bedProfile.py", line + ["-time", "nan"], "-time"),
        ("bedProfile.py", line + ["-window", 5, 2], "-window"),
        ("bedProfile.py", line + ["-window", "auto", "x"], "-window"),
        ("bedProfile.py", line + ["-up", 1, 0, 0], "-up"),
        ("bedProfile.py", ["-axis", 0, 0, 0, 0, 0, 0], "-axis"),
        ("bedProfile.py", ["-line", 0, 0, 0, 0, 0, "nan"], "-line"),
        ("regionMasses.py", ["-box", "b", 1, 1, 1, 0, 0, 0], "-box b"),
        ("regionMasses.py", ["-box", "b", 0, 0, 0, 1, "nan", 1], "-box b"),
        ("regionMasses.py", ["-box", "b", 0, 0, 0, 1, "one", 1], "-box b"),
        ("regionMasses.py", ["-cylinder", "c", 0, 0, 0, 0, 0, 1, -1, 0, 1], "-cylinder c"),
        ("regionMasses.py", ["-cylinder", "c", 0, 0, 0, 0, 0, 0, 1, 0, 1], "-cylinder c"),
        ("regionMasses.py", ["-cylinder", "c", 0, 0, 0, 0, 0, 1, 1, 1, 0], "-cylinder c"),
        ("regionMasses.py", ["-box", "b", 0, 0, 0, 1, 1, 1, "-reference", -3], "-reference"),
        ("regionMasses.py", ["-box", "b", 0, 0, 0, 1, 1, 1, "-reference", 0], "-reference"),
        ("sideView.py", ["-time", "nan"], "-time"),
        ("sideView.py", ["-horizontal", 0, 0, 2], "-horizontal"),
        ("sideView.py", ["-up", 0, 0, 0], "-up"),
        ("reposeAngle.py", ["-sectors", 0], "-sectors"),
        ("reposeAngle.py", ["-binWidth", -1], "-binWidth"),
        ("reposeAngle.py", ["-heights", 0.8, 0.2], "-heights"),
        ("reposeAngle.py", ["-window", 5, 2], "-window"),
        ("reposeAngle.py", ["-runTime", -1], "-runTime"),
        ("inclinedPlate.py", ["-height", 0], "-height"),
        ("inclinedPlate.py", ["-moved", -1], "-moved"),
        ("dieFilling.py", ["-openingStart", "nan"], "-openingStart"),
        ("dieFilling.py", ["-runTime", -1], "-runTime"),
    ]
    # the repose and plate cases of the end-to-end tests, on which the scripts run
    case_of = {"reposeAngle.py": os.path.join(TMP, "repose"), "inclinedPlate.py": os.path.join(TMP, "plate")}
    before = {c: outputs(c) for c in set(case_of.values()) | {case}}
    for script, args, option in cases:
        r = run_tool(script, "-case", case_of.get(script, case), *args)
        check(f"{script} {' '.join(str(a) for a in args)}: refused naming {option}", one_line_error(r, script, option),
              f"(exit {r.returncode}, stderr {r.stderr.strip()[-300:]!r})")
    r = run_tool("writeBoxStl.py", os.path.join(TMP, "box.stl"), 0, 0, 0, 1, 1, "inf")
    check("writeBoxStl.py with an infinite corner: refused", one_line_error(r, "writeBoxStl.py", "inf"),
          r.stderr.strip()[-300:])
    for c, files in before.items():
        check(f"refused options leave {os.path.basename(c)}/postProcessing as it was", outputs(c) == files,
              str(sorted(outputs(c))))


@test
def library_refuses_meaningless_parameters():
    p = np.array([[0.001, 0, 0.001], [0.002, 0, 0.003]])
    for what, call in (("radial_profile sectors 0", lambda: profile.radial_profile(p, 5e-4, sectors=0)),
                       ("radial_profile bin_width -1", lambda: profile.radial_profile(p, 5e-4, bin_width=-1)),
                       ("line_profile bin_width nan", lambda: profile.line_profile(p, 5e-4, bin_width=np.nan)),
                       ("sector_angles sectors 0", lambda: profile.sector_angles(p, 5e-4, (0, 0, 0), (0, 0, 1), 1e-3, (0, 1), 0)),
                       ("Box min > max", lambda: geometry.Box((1, 0, 0), (0, 1, 1))),
                       ("Cylinder radius 0", lambda: geometry.Cylinder((0, 0, 0), (0, 0, 1), 0, 0, 1)),
                       ("fill_ratio reference nan", lambda: summary.fill_ratio([1], np.nan))):
        try:
            call()
            check(f"{what}: ValueError", False, "(accepted)")
        except ValueError:
            check(f"{what}: ValueError", True)
        except Exception as e:
            check(f"{what}: ValueError", False, f"({type(e).__name__}: {e})")


@test
def refused_reference_keeps_the_old_results():
    # regionMasses.py -reference -3 named an internal function ('fill_ratio:
    # reference_mass must be positive') and had already truncated the good
    # regionMasses.csv of an earlier run to its header.
    case = small_case("keep")
    box = ["-box", "b", -1, -1, -1, 1, 1, 1]
    r = run_tool("regionMasses.py", "-case", case, *box)
    csv_path = os.path.join(case, "postProcessing", "regionMasses.csv")
    good = open(csv_path).read() if r.returncode == 0 else ""
    check("regionMasses.py: a first good run", r.returncode == 0 and len(good.splitlines()) == 3, r.stderr.strip()[-300:])
    r = run_tool("regionMasses.py", "-case", case, *box, "-reference", -3)
    check("regionMasses.py -reference -3: one line naming -reference, not fill_ratio",
          one_line_error(r, "regionMasses.py", "-reference", "-3") and "fill_ratio" not in r.stderr, r.stderr.strip()[-300:])
    check("regionMasses.py -reference -3: the earlier regionMasses.csv is intact", open(csv_path).read() == good)
    # a failure half-way through a write (here: a frame that cannot be read) keeps it too
    with open(os.path.join(case, "dem", "particles_000000001.h5"), "r+b") as f:
        f.truncate(1000)
    r = run_tool("regionMasses.py", "-case", case, *box, "-reference", 1)
    check("regionMasses.py on a damaged frame: the earlier regionMasses.csv is intact",
          r.returncode != 0 and open(csv_path).read() == good, r.stderr.strip()[-300:])
    check("no temporary file is left behind", sorted(os.listdir(os.path.join(case, "postProcessing")))
          == ["regionMasses.csv", "regionMasses.png"], str(os.listdir(os.path.join(case, "postProcessing"))))


@test
def replacing_output_only_when_complete():
    from diefillpost import output
    path = os.path.join(TMP, "replace.csv")
    with open(path, "w") as f:
        f.write("old\n")
    try:
        with output.open_replacing(path) as f:
            f.write("half")
            raise RuntimeError("stopped")
    except RuntimeError:
        pass
    check("open_replacing: an error in the block keeps the old file", open(path).read() == "old\n"
          and os.listdir(TMP).count("replace.csv") == 1 and not [n for n in os.listdir(TMP) if n.startswith(".replace")])
    with output.open_replacing(path) as f:
        f.write("new\n")
    check("open_replacing: the new content once complete", open(path).read() == "new\n")


def broken_summaries():
    """(what, summary.csv text, words the message must hold)."""
    head = "time,step,particles,kineticEnergy,coordinationNumber,wallContacts,lostCount,lostMass"
    return [("empty", "", ["summary.csv", "empty"]),
            ("a short row", head + "\n0,0,3,0,0,0,0,0\n0.5,1,3,0,0,0,0\n", ["summary.csv", "line 3", "7 fields", "the header has 8"]),
            ("a header longer than the rows", head + ",mass_die\n0,0,3,0,0,0,0,0\n",
             ["summary.csv", "line 2", "8 fields", "the header has 9"]),
            ("no time column", head.replace("time,", "t,") + "\n0,0,3,0,0,0,0,0\n", ["summary.csv", "no column 'time'"]),
            ("a field that is not a number", head + "\n0,0,3,x,0,0,0,0\n", ["summary.csv", "line 2", "'x'"]),
            ("no data line", head + "\n", ["summary.csv", "no data"])]


@test
def malformed_summary_is_named():
    # An empty summary.csv gave 'error: time', a short row 'setting an array element
    # with a sequence', a longer header 'cannot reshape array': neither the file nor
    # what was wrong.
    for what, text, words in broken_summaries():
        case = small_case("summary_" + what.replace(" ", "_"))
        with open(os.path.join(case, "dem", "summary.csv"), "w") as f:
            f.write(text)
        try:
            summary.read(case)
            check(f"summary.read, {what}: ValueError", False, "(accepted)")
        except ValueError as e:
            check(f"summary.read, {what}: ValueError naming the file and the fault",
                  all(w in str(e) for w in words) and case in str(e), str(e))
        except Exception as e:
            check(f"summary.read, {what}: ValueError", False, f"({type(e).__name__}: {e})")
        r = run_tool("regionMasses.py", "-case", case)
        check(f"regionMasses.py, summary.csv with {what}: one line naming the file",
              one_line_error(r, "regionMasses.py", *words), f"(exit {r.returncode}, {r.stderr.strip()[-300:]!r})")
    case = small_case("summary_columns")
    try:
        summary.read(case)["mass_die"]
        check("summary.read: a missing column is a KeyError naming the file", False)
    except KeyError as e:
        check("summary.read: a missing column is a KeyError naming the file and the column",
              "summary.csv" in e.args[0] and "mass_die" in e.args[0], e.args[0])


@test
def damaged_particle_file_is_named():
    # A truncated particles_*.h5: the tools said 'Unable to open file (truncated
    # file...)' without naming it; sideView.py without -time failed on an older
    # truncated frame (the series was read whole) though it draws the newest only.
    case = small_case("truncated")
    old = os.path.join(case, "dem", "particles_000000000.h5")
    with open(old, "r+b") as f:
        f.truncate(1000)
    for script, args in (("regionMasses.py", ["-box", "b", -1, -1, -1, 1, 1, 1]),
                         ("bedProfile.py", ["-time", 0, "-line", 0, 0, 0, 1, 0, 0]),
                         ("sideView.py", ["-time", 0])):
        r = run_tool(script, "-case", case, *args)
        check(f"{script} on a truncated frame: one line naming it", one_line_error(r, script, "particles_000000000.h5"),
              f"(exit {r.returncode}, {r.stderr.strip()[-300:]!r})")
    for index in ("particles.series", None):
        if index is None:
            os.remove(os.path.join(case, "dem", "particles.series"))
        r = run_tool("sideView.py", "-case", case, "-name", "newest")
        check(f"sideView.py without -time ({index or 'no index'}): draws the newest frame, the damaged older one unread",
              r.returncode == 0 and os.path.exists(os.path.join(case, "postProcessing", "newest.png")), r.stderr.strip()[-300:])
        r = run_tool("bedProfile.py", "-case", case, "-line", 0, 0, 0, 1, 0, 0)
        check(f"bedProfile.py without -time ({index or 'no index'}): the newest frame", r.returncode == 0, r.stderr.strip()[-300:])
    try:
        series.read_frame(old)
        check("read_frame on a truncated file: ValueError", False)
    except ValueError as e:
        check("read_frame on a truncated file: ValueError naming it", old in str(e), str(e))
    empty = os.path.join(TMP, "not_particles.h5")
    with h5py.File(empty, "w") as h:
        h["x"] = np.zeros(3)
    try:
        series.read_frame(empty)
        check("read_frame on a file without particle fields: ValueError", False)
    except ValueError as e:
        check("read_frame on a file without particle fields: ValueError naming it and the field",
              empty in str(e) and "position" in str(e), str(e))


@test
def capillary_scaling_csv_is_checked():
    head = ("l,radius_m,bridgeVolume_m3,weight_N,hertzOverlap_m,capillaryContact_N,capillaryGap_N,ratioContact,ratioGap,"
            "ratioFixedVolumeContact,ratioFixedVolumeFixedGap,paperFit,contactToCapillary,bondUncorrected,bondEq9,"
            "bondKappa2,bondRatioUncorrected,bondRatioEq9,bondRatioKappa2")
    good = os.path.join(TMP, "scaling.csv")
    with open(good, "w") as f:
        f.write(head + "\n" + "\n".join(",".join(str(l * (k + 1)) for k in range(19)) for l in (1, 2, 4)) + "\n")
    r = run_tool("plotCapillaryScaling.py", good)
    check("plotCapillaryScaling.py: a PNG from a good CSV", r.returncode == 0 and os.path.exists(good[:-4] + ".png"),
          r.stderr.strip()[-300:])
    short = os.path.join(TMP, "scaling_short.csv")
    with open(short, "w") as f:
        f.write(head + "\n1,2,3\n")
    r = run_tool("plotCapillaryScaling.py", short)
    check("plotCapillaryScaling.py, a short row: one line naming the file and the line",
          one_line_error(r, "plotCapillaryScaling.py", "scaling_short.csv", "line 2"), r.stderr.strip()[-300:])


DIE_PROPS = """simulation { timeStep 1e-5; endTime 2.0; gravity (0 0 -9.81); }
cohesion { model capillary; waterContent 0.05; }
materials { sand { youngsModulus 5e6; poissonRatio 0.3; density 2650; } }
walls
{
    dieWall { type cylinder; material steel; side inside; axisPoint (0 0 0); axis (0 0 1); radius 0.05;
              range (-0.1 0); motion { open { type translate; start 1.0; end 1.5; velocity (0 0 -0.2); } } }
    shoe { type cylinder; material steel; side inside; axisPoint (-0.1 0 0); axis (0 0 1); radius 0.05;
           range (0 0.1); motion { pass { type translate; start 0.1; end 0.5; velocity (0.5 0 0); } } }
}
"""


def wedge_bed(angle_deg, falls_along_motion, r=1.5e-3, radius=0.05, base_z=-0.1, mid_height=0.03):
    """Spheres in columns on the die base (a grid of pitch 2r inside the die's circle) whose top
    sphere touches the plane surface h(x) = mid_height -+ tan(angle) x: falling in +x (the shoe's
    direction) or rising."""
    slope = np.tan(np.radians(angle_deg)) * (-1 if falls_along_motion else 1)
    pts = []
    for x in np.arange(-radius + r, radius, 2 * r):
        for y in np.arange(-radius + r, radius, 2 * r):
            if np.hypot(x, y) > radius - r:
                continue
            top = mid_height + slope * x
            for z in np.arange(top - r, r - 1e-12, -2 * r):
                pts.append((x, y, base_z + z))
    return np.array(pts)


@test
def die_filling_slope_direction():
    """dieFilling.py on a synthetic bed: the signed central angle, the slope's direction and the
    share in the die's first half follow the bed's tilt, both ways; z read at the shoe's start and
    before the opening."""
    for falls in (True, False):
        case = os.path.join(TMP, "dieFill_%s" % ("falls" if falls else "rises"))
        bed = wedge_bed(30.0, falls)
        radii = np.full(len(bed), 1.5e-3)
        m = float(np.sum(2650 * 4 / 3 * np.pi * radii ** 3))
        header = ("time,step,particles,kineticEnergy,coordinationNumber,wallContacts,lostCount,lostMass,"
                  "liquidCoordinationNumber,mass_die,mass_base")
        rows = [(t, k, len(bed), 0, 5, 0, 0, 0, z, md, m) for k, (t, z, md) in
                enumerate([(0.0, 0, 0), (0.1, 7.5, 0), (0.5, 7.9, 0.6 * m), (1.0, 8.2, m), (1.5, 8.2, m), (2.0, 8.1, m)])]
        write_case(case, DIE_PROPS, [(0.0, bed, radii), (1.0, bed, radii), (2.0, bed, radii)], rows, header)
        r = run_tool("dieFilling.py", "-case", case)
        res = json.load(open(os.path.join(case, "postProcessing", "results.json"))) if r.returncode == 0 else {}
        value = lambda k: res.get(k, {}).get("value")  # noqa: E731
        signed, first = value("centralAngleAlongMotion"), value("massFractionFirstHalf")
        want = 30.0 if falls else -30.0
        check("dieFilling.py, a 30 deg bed that %s along the shoe's motion: signed central angle %+.0f within 1.5 deg"
              % ("falls" if falls else "rises", want), signed is not None and abs(signed - want) < 1.5,
              f"(got {signed}) {r.stderr[-300:]}")
        check("dieFilling.py: centralSlopeFalls is %s" % falls, value("centralSlopeFalls") is falls,
              f"(got {value('centralSlopeFalls')})")
        # The wedge's share at x < 0: 1/2 + (4 R tan a / 3 pi) / (2 h_mid) = 0.5 +- 0.204 for 30 deg.
        expected = 0.5 + (1 if falls else -1) * (4 * 0.05 * np.tan(np.radians(30)) / (3 * np.pi)) / (2 * 0.03)
        check("dieFilling.py: share of the bed in the first half %.3f within 0.03" % expected,
              first is not None and abs(first - expected) < 0.03, f"(got {first})")
        check("dieFilling.py: liquid coordination at the shoe's start (7.5) and before the opening (8.2)",
              value("liquidCoordinationPassStart") == 7.5 and value("liquidCoordinationFilled") == 8.2,
              f"(got {value('liquidCoordinationPassStart')}, {value('liquidCoordinationFilled')})")
        fill = os.path.join(case, "postProcessing", "fillRatio.csv")
        lines = open(fill).read().split() if os.path.exists(fill) else []
        check("dieFilling.py writes fillRatio.csv (one line per summary line)",
              len(lines) == 7 and lines[0] == "time_s,fillRatio" and lines[3] == "0.5,0.6", f"{lines[:4]}")


LADDER = os.path.join(ROOT, "tutorials", "dieFilling", "validation", "ladder")


def ladder_run(folder, factor, exponent, seed, angle, lost, wall):
    record = {"name": "cg%g-k%g-s%d-air" % (factor, exponent, seed), "coarseGrain": factor,
              "capillaryExponent": exponent, "seed": seed, "air": True, "timeStep": 6.25e-7 * factor,
              "particles": 100, "wallTime": wall, "threads": 2, "build": "abcdef0", "finished": "2026-12-03 12:00 UTC",
              "results": {"centralAngleAlongMotion": angle, "centralAngle": abs(angle), "centralSlopeFalls": angle > 0,
                          "centralFitRms": 1.0, "rightBorderAngle": 85.0, "fractionLostAtOpening": lost,
                          "massFractionFirstHalf": 0.6, "liquidCoordinationPassStart": 8.5, "fillTime50": 3.0},
              "profile": [[x, 30.0 - 0.5 * x] for x in range(-50, 51, 5)], "fillRatio": [[0, 0], [5, 1]]}
    with open(os.path.join(folder, record["name"] + ".json"), "w") as f:
        json.dump(record, f)


@test
def ladder_report_statistics():
    """validation/ladder report on made-up run files: ensembles grouped by everything but the
    seed, mean and sample standard deviation, the table between the README's markers, -check
    passes on what report wrote and fails once a run file changes; collect refuses an unfinished run."""
    runs = os.path.join(TMP, "ladder", "runs")
    out = os.path.join(TMP, "ladder")
    os.makedirs(runs)
    for seed, angle in ((1, 20.0), (2, 30.0), (3, 40.0)):
        ladder_run(runs, 10, 1, seed, angle, 0.01 * seed, 3600.0 * seed)
    ladder_run(runs, 10, 2.0142, 1, -5.0, 0.0, 3600.0)
    readme = os.path.join(out, "README.md")
    with open(readme, "w") as f:
        f.write("intro\n<!-- ladder table: written by ./ladder report from runs/*.json; do not edit by hand -->\n"
                "old\n<!-- end of the ladder table -->\nafter\n")
    r = subprocess.run([sys.executable, LADDER, "report", "-runs", runs, "-out", out, "-readme", readme],
                       capture_output=True, text=True)
    ens = json.load(open(os.path.join(out, "ensemble.json"))) if r.returncode == 0 else []
    k1 = [e for e in ens if e["capillaryExponent"] == 1]
    ok = len(ens) == 2 and len(k1) == 1 and k1[0]["runs"] == 3
    check("ladder report: two ensembles, three seeds in one", ok, r.stderr[-300:])
    if ok:
        a = k1[0]["centralAngleAlongMotion"]
        check("ladder report: mean 30 and sample sd 10 of 20, 30, 40", a["mean"] == 30.0 and a["sd"] == 10.0, f"{a}")
        check("ladder report: the wall time's mean (2 h) and the slope's count (3 of 3)",
              k1[0]["wallTime"]["mean"] == 7200.0 and k1[0]["slopeFallsAlongMotion"] == 3)
        k2 = [e for e in ens if e["capillaryExponent"] == 2.0142]
        check("ladder report: the bed's strength against the real powder's, l^(κ-1): 1 for κ = 1, "
              "10^1.0142 = 10.3324 for the paper's exponent at coarse grain 10",
              k1[0]["strengthRatio"] == 1.0 and len(k2) == 1 and k2[0]["strengthRatio"] == 10.3324,
              f"({k1[0].get('strengthRatio')}, {k2[0].get('strengthRatio') if k2 else None})")
    text = open(readme).read()
    check("ladder report: the table replaces what stood between the markers, the rest kept",
          text.startswith("intro\n") and text.endswith("after\n") and "old" not in text
          and "30.0 ± 10.0" in text and "| cg10-k1-s2-air |" in text, text[:200])
    for png in ("profiles.png", "fillRatio.png", "strength.png"):
        path = os.path.join(out, png)
        check(f"ladder report writes {png}", os.path.exists(path) and open(path, "rb").read(4) == b"\x89PNG")
    check_cmd = [sys.executable, LADDER, "report", "-check", "-runs", runs, "-out", out, "-readme", readme]
    r = subprocess.run(check_cmd, capture_output=True, text=True)
    check("ladder report -check passes on what report wrote", r.returncode == 0, r.stderr[-300:])
    ladder_run(runs, 10, 1, 2, 31.0, 0.02, 7200.0)
    r = subprocess.run(check_cmd, capture_output=True, text=True)
    check("ladder report -check fails once a run file changed, naming the table",
          r.returncode == 1 and "README.md's ladder table is not what runs/*.json give" in r.stderr, r.stderr[-300:])
    unfinished = os.path.join(TMP, "ladder", "unfinished")
    os.makedirs(os.path.join(unfinished, "case", "dem"))
    with open(os.path.join(unfinished, "case", "dem", "summary.csv"), "w") as f:
        f.write("time,step\n0.5,10\n")
    r = subprocess.run([sys.executable, LADDER, "collect", unfinished], capture_output=True, text=True)
    check("ladder collect refuses a run that has not finished", r.returncode == 1 and "has not finished" in r.stderr,
          r.stderr[-300:])


@test
def ladder_wall_time():
    """validation/ladder's wall time of a run: the solver's segments (a start and a continuation,
    the first stopped by the machine before its last line) summed from their progress lines, less
    the paused time logged by fullRun; a wrong reading (only the last segment, or the pause kept)
    differs by 1 h or more."""
    from importlib.machinery import SourceFileLoader
    ladder = SourceFileLoader("ladder_module", LADDER).load_module()
    run = os.path.join(TMP, "ladder", "walltime")
    os.makedirs(os.path.join(run, "case"))
    with open(os.path.join(run, "case", "log.diefillFoam"), "w") as f:
        f.write("Exec   : diefillFoam\nProgress: t = 1 s of 13 s (7.7 %), elapsed 30 s, ETA 6 min\n"
                "Progress: t = 9.8 s of 13 s (75.6 %), elapsed 2 h 46 min, ETA 43 min 21 s\n"
                "Exec   : diefillFoam\nProgress: t = 10 s of 13 s (77 %), elapsed 2 min 3 s, ETA 40 min\n"
                "t = 13.0000 s (100.0 %)  step 2080000  particles 19066  elapsed 1h1m53s  ETA 0s\r\n")
    with open(os.path.join(run, "run.log"), "w") as f:
        f.write("==== 2026-12-03 16:00:00 UTC: fullRun pause\n==== 2026-12-03 16:30:00 UTC: fullRun resume\n")
    got = ladder.wall_seconds(run)
    want = 2 * 3600 + 46 * 60 + 3600 + 60 + 53 - 1800
    check("ladder wall time: segments summed from their progress lines, the logged pause left out",
          abs(got - want) < 1e-9, f"(got {got} s, want {want} s)")


@test
def phase_table_of_diefillFoam():
    """diefillFoam's wall-time table (phaseTimes.C) as printed serially and on 2 ranks, in a
    log continued once (two tables: the last is the run's), read to the printed digits; a
    log without one gives None.  The bench (bench/run) and tests/diefillFoam read it so."""
    from diefillpost import phasetimes
    serial = ("Wall time of the time loop, 9059 s:\n"
              "    DEM (particle steps)                    8930 s  98.6 %\n"
              "    coupling (void fraction, drag)         103.1 s   1.1 %\n"
              "    air (PIMPLE loop)                       24.7 s   0.3 %\n"
              "    output (fields, restart files)        0.1834 s   0.0 %\n"
              "    rest (time control, progress)          0.589 s   0.0 %\n\nEnd\n")
    ranks = ("Wall time of the time loop, 131.8 s (2 ranks: the most over ranks, and least - most):\n"
             "    DEM (particle steps)                     111 s  84.2 %  (110.9 - 111 s)\n"
             "      of which in the DEM's exchanges      16.93 s  12.9 %  (9.971 - 16.93 s)\n"
             "    coupling (void fraction, drag)         9.609 s   7.3 %  (9.607 - 9.609 s)\n"
             "    air (PIMPLE loop)                      10.75 s   8.2 %  (10.68 - 10.75 s)\n"
             "    output (fields, restart files)      0.009358 s   0.0 %  (0.009231 - 0.009358 s)\n"
             "    rest (time control, progress)         0.4755 s   0.4 %  (0.47 - 0.4755 s)\n\nEnd\n")
    one = phasetimes.parse("Time = 5.2\n" + serial)
    check("phase table, serial: total, one rank, the five phases to their digits, no range",
          one is not None and one.total == 9059 and one.ranks == 1
          and phasetimes.phase_seconds(one) == {"dem": 8930, "coupling": 103.1, "air": 24.7, "output": 0.1834,
                                                "rest": 0.589}
          and one.rows["air (PIMPLE loop)"].percent == 0.3 and one.rows["DEM (particle steps)"].least is None,
          f"(total {one.total if one else None} s, {len(one.rows) if one else 0} rows)")
    two = phasetimes.parse(serial.replace("9059", "1") + "Exec   : diefillFoam -parallel\n" + ranks)
    ex = two.rows.get(phasetimes.EXCHANGES) if two else None
    check("phase table, 2 ranks, second of two tables: total, ranks, exchanges and least - most",
          two is not None and two.total == 131.8 and two.ranks == 2 and len(two.rows) == 6
          and ex == (16.93, 12.9, 9.971, 16.93) and phasetimes.phase_seconds(two)["air"] == 10.75
          and two.rows["output (fields, restart files)"].least == 0.009231,
          f"(total {two.total if two else None} s, {len(two.rows) if two else 0} rows)")
    check("phase table: a log without one gives None",
          phasetimes.parse("Time = 1\nEnd\n") is None)


import shutil  # noqa: E402

shutil.rmtree(TMP, ignore_errors=True)
print(f"{PASSED} passed, {FAILED} failed")
sys.exit(1 if FAILED else 0)
