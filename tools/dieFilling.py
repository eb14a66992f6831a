#!/usr/bin/env python3
"""Results of the die-filling case (paper section 5): bed profile, angles, masses, fill ratio.

    dieFilling.py -case DIR [-openingStart T] [-runTime S]

Reads dem/ (HDF5 series, summary.csv) and constant/demProperties (die radius and height
from the 'dieWall' cylinder, the opening time from its motion) and writes to
postProcessing/:
  profile.csv / profile.png  bed surface in the plane of shoe motion (|y| < R/4) after
                             the opening, with the two fitted lines:
                             - central angle: fit over x in [-R/2, R/2] (the paper's 'central
                               region', 33.8 deg measured, 32.9 deg simulated), and
                               with its sign (centralAngleAlongMotion: positive where the
                               surface falls in the direction of the shoe's motion, as in
                               the experiment); massFractionFirstHalf: the bed's share in
                               the die's first half (x < 0);
                             - right-border angle: the bed's right edge (outermost particle
                               per height band, |y| < R/4) fitted against height between 20 %
                               and 80 % of the bed's height there; 90 deg = vertical
                               (paper: about 90 deg);
  fillRatio.png, .csv        mass in the die / mass poured, vs time;
  sideView_filled.png, sideView_final.png   the bed from the side (like the paper's Fig. 5b);
  air.png                    (runs with air) the pressure on the aeration plate while the shoe's
                             bed is conditioned; the air leaving the die vs the powder entering;
  results.json / results.csv, with the fill times (die mass reaching 50 % and 90 % of the
                             mass poured) and, in a run with air (diefillFoam), the mean
                             pressure on the aeration plate while air is blown through the
                             shoe's bed and the volume of air that left the die.
Heights are measured from the die base (z = -H).
A run that has not reached the die opening yet (a long run looked at while it goes) gets
fillRatio.png, sideView_latest.png, air.png and results.json with "state": "in progress" and
the fill so far; the profile and the angles come once the run is past the opening."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, finite, non_negative, out_dir, run_main  # noqa: E402
from diefillpost import foamdict, output, plots, profile, results, series, summary  # noqa: E402


def profile_plot(path, x, h, fits, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(x * 1e3, h * 1e3, "o-", ms=3, label="surface profile")
    for f, colour in zip(fits, ("r", "m")):
        xs = np.linspace(*f["window"], 20)
        ax.plot(xs * 1e3, (f["intercept"] + f["slope"] * xs) * 1e3, colour + "-", lw=2,
                label=f"fit {f['angle']:.1f} deg on [{f['window'][0]*1e3:.1f}, {f['window'][1]*1e3:.1f}] mm")
    ax.set_xlabel("x along the shoe motion [mm]")
    ax.set_ylabel("height above die base [mm]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    plots.save(fig, path, dpi=120)


def slope_along_motion(slope):
    """The central fit's angle with its sign: positive where the surface falls in the direction
    of the shoe's motion (+x; the experiment's 33.8 deg, most powder in the die's first half),
    negative where it rises."""
    return float(np.degrees(np.arctan(-slope)))


def half_masses(position, mass, radius):
    """Mass of the bed on the die base (within the die's radius) in the die's first half along
    the shoe's motion (x < 0) and in all: the paper's 'most of the material is deposited in the
    first half of the cylinder'."""
    on_base = np.hypot(position[:, 0], position[:, 1]) <= radius
    total = float(np.sum(mass[on_base]))
    first = float(np.sum(mass[on_base & (position[:, 0] < 0)]))
    return first, total


def value_at(t, values, when):
    """The column's value on the summary line nearest to time `when`."""
    return float(values[int(np.argmin(np.abs(np.asarray(t) - when)))])


def liquid_results(s, shoe_pass, opening):
    """The liquid coordination number (bridges per particle, paper: z = 8 at w = 0.05) when the
    shoe starts to move (the conditioned bed at rest) and before the opening (the bed in the die)."""
    if "liquidCoordinationNumber" not in s:
        return {}
    z = np.asarray(s["liquidCoordinationNumber"])
    res = {}
    if shoe_pass:
        res["liquidCoordinationPassStart"] = {
            "value": round(value_at(s["time"], z, shoe_pass[0]), 3), "unit": "-",
            "description": "liquid bridges per particle at t = %g s, the shoe's start (paper: z = 8)" % shoe_pass[0]}
    if opening is not None and opening <= s["time"][-1]:
        res["liquidCoordinationFilled"] = {
            "value": round(value_at(s["time"], z, opening), 3), "unit": "-",
            "description": "liquid bridges per particle at t = %g s, before the opening" % opening}
    return res


def write_fill_ratio_csv(path, t, fill):
    """fillRatio.csv: time and fill ratio of every summary line (the validation ladder keeps it)."""
    with output.open_replacing(path) as f:
        f.write("time_s,fillRatio\n")
        for ti, fi in zip(t, fill):
            f.write(f"{ti:.6g},{fi:.6g}\n")


def first_time_reaching(t, values, level):
    """Linear interpolation of the first time values >= level (None if never)."""
    above = np.nonzero(values >= level)[0]
    if len(above) == 0:
        return None
    k = int(above[0])
    if k == 0:
        return float(t[0])
    v0, v1 = values[k - 1], values[k]
    return float(t[k - 1] + (level - v0) / (v1 - v0) * (t[k] - t[k - 1]))


def read_function_object(case, name):
    """Columns of postProcessing/<name>/<start>/surfaceFieldValue.dat (all start times)."""
    root = os.path.join(case, "postProcessing", name)
    rows = []
    if os.path.isdir(root):
        for start in sorted(os.listdir(root), key=float):
            path = os.path.join(root, start, "surfaceFieldValue.dat")
            if os.path.isfile(path):
                for line in open(path):
                    if line.startswith("#") or not line.strip():
                        continue
                    rows.append([float(x) for x in line.replace("(", " ").replace(")", " ").split()])
    return np.array(rows) if rows else None


def air_results(case, rho, until, out=None, summary_t=None, solid_volume_in_die=None):
    """Aeration pressure and air leaving the die, from the function objects of the air run;
    with out: air.png (plate pressure, and air out of the die vs powder volume in it)."""
    res = {}
    curves = {}
    aeration = read_function_object(case, "aerationPressure")
    if aeration is not None:
        t, p, uz = aeration[:, 0], aeration[:, 1] * rho, aeration[:, 4]
        blowing = uz > 0.5 * np.max(uz) if np.max(uz) > 0 else np.zeros(len(t), bool)
        if blowing.any():
            stop = float(t[blowing].max())
            # the second half of the blowing (the bed in the shoe has formed), and the
            # 50 ms after it stopped (the air's own hydrostatic pressure on the plate)
            late = blowing & (t >= 0.5 * stop)
            after = (t > stop + 0.01) & (t <= stop + 0.05)
            res["aerationPressure"] = {"value": round(float(np.mean(p[late])), 3), "unit": "Pa",
                                       "description": "mean pressure on the aeration plate (relative to the room) "
                                                      "over the second half of the aeration, at superficial "
                                                      "velocity %.3g m/s" % float(np.max(uz))}
            curves["aeration"] = (t, p)
            if after.any():
                res["aerationOverpressure"] = {"value": round(float(np.mean(p[late]) - np.mean(p[after])), 3),
                                               "unit": "Pa",
                                               "description": "aerationPressure less the plate pressure in the "
                                                              "50 ms after the blowing stopped"}
    die_air = read_function_object(case, "dieAir")
    if die_air is not None and len(die_air) > 1:
        t, q = die_air[:, 0], die_air[:, 1]
        cumulative = np.concatenate(([0.0], np.cumsum(0.5 * (q[1:] + q[:-1]) * np.diff(t))))
        curves["dieAir"] = (t, cumulative)
        keep = t <= until + 1e-9
        t, q = t[keep], q[keep]
        volume = float(np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(t)))
        res["airVolumeOutOfDie"] = {"value": volume, "unit": "m3",
                                    "description": "net volume of air that left the die through its opening "
                                                   "until t = %g s (the die walls are sealed: it equals the "
                                                   "volume of powder that entered)" % until}
    if out is not None and curves:
        air_plot(os.path.join(out, "air.png"), curves, summary_t, solid_volume_in_die, until)
    return res


def air_plot(path, curves, summary_t, solid_volume_in_die, opening):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    if "aeration" in curves:
        t, p = curves["aeration"]
        axes[0].plot(t, p, lw=1)
        axes[0].set_xlim(0, min(t[-1], 2 * max(0.2, t[np.argmax(p)] + 0.2)))
    axes[0].set_xlabel("time [s]")
    axes[0].set_ylabel("pressure on the aeration plate [Pa]")
    axes[0].set_title("conditioning: air blown through the shoe's bed", fontsize=9)
    if "dieAir" in curves:
        t, v = curves["dieAir"]
        axes[1].plot(t, v * 1e6, lw=1.5, label="air out of the die (through its opening)")
    if summary_t is not None and solid_volume_in_die is not None:
        axes[1].plot(summary_t, solid_volume_in_die * 1e6, "--", lw=1.5, label="powder volume in the die")
    axes[1].axvline(opening, color="k", ls=":", lw=1, label="die opening starts")
    axes[1].set_xlabel("time [s]")
    axes[1].set_ylabel("volume [cm$^3$]")
    axes[1].set_title("the sealed die: displaced air vs powder in", fontsize=9)
    axes[1].legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    plots.save(fig, path, dpi=120)


def shoe_pass_window(props):
    """(start, end) of the shoe's motion (walls/shoe/motion in demProperties), or None."""
    shoe = props["walls"].get("shoe", {})
    segments = [s for s in shoe.get("motion", {}).values() if isinstance(s, dict)]
    if not segments:
        return None
    return min(float(s["start"]) for s in segments), max(float(s["end"]) for s in segments)


def die_geometry(d):
    wall = d["walls"]["dieWall"]
    radius = float(wall["radius"])
    z0, z1 = (float(v) for v in wall["range"])
    opening = None
    motion = wall.get("motion", {})
    for seg in motion.values():
        if isinstance(seg, dict):
            start = float(seg["start"])
            opening = start if opening is None else min(opening, start)
    return radius, z1 - z0, z0, opening


def wall_load_results(s, props, until, opening, mass_in_system, mass_in_die, out, shoe_end=None):
    """What the walls carry (the wallForce_<wall>_z columns of summary.csv, force of the
    particles on each wall): the loads in grams-force against time (wallLoads.png, the die's
    `opening` marked once the run is past it), and, as means before time `until` (see below),
    the share of the weight of all particles the walls carry together (1 at rest without air)
    and the share of the die's powder weight on the die base (below 1: the die wall holds the
    rest by friction, Janssen)."""
    names = [k[len("wallForce_"):-2] for k in s if k.startswith("wallForce_") and k.endswith("_z")]
    if not names:
        return {}
    g = abs(float(np.asarray(props.get("simulation", {}).get("gravity", (0, 0, -9.81)), float)[2]))
    t = s["time"]
    loads = {w: -np.asarray(s["wallForce_%s_z" % w]) / g for w in names}       # kg
    plots.curve(os.path.join(out, "wallLoads.png"), t, [loads[w] * 1e3 for w in names] + [s["mass_die"] * 1e3],
                ["load on %s" % w for w in names] + ["mass in the die"], "time [s]", "[g]",
                title="weight carried by the walls (force of the particles / g)",
                vlines=[(opening, "die opening starts")] if opening <= t[-1] else ())
    # Averaged over the lines between the shoe's pass (if it ended before) and `until`, at
    # most 0.5 s: a wet bed standing on a few contacts rattles, and at the opening's start the
    # die wall begins to slide along the bed.
    start = max(until - 0.5, shoe_end if shoe_end is not None and shoe_end < until else until - 0.1)
    window = (t >= start - 1e-9) & (t < until - 1e-9) if until < t[-1] else (t >= start - 1e-9)
    if not window.any():
        return {}
    k = np.flatnonzero(window)
    span = "mean over t = %.3g-%.3g s (%d lines)" % (t[k[0]], t[k[-1]], len(k))
    res = {"wallLoadFilled": {"value": round(sum(float(np.mean(loads[w][k])) for w in names) / mass_in_system, 4),
                              "unit": "-", "description": "weight carried by all walls together over the weight "
                                                          "of the particles, %s (1 at rest without air)" % span}}
    if "dieBase" in loads and mass_in_die > 0:
        res["dieBaseLoadFilled"] = {"value": round(float(np.mean(loads["dieBase"][k])) / mass_in_die, 4),
                                    "unit": "-",
                                    "description": "weight carried by the die base over the weight of the "
                                                   "powder in the die, %s (below 1: the die wall holds the "
                                                   "rest by friction)" % span}
    return res


def common_results(t50, t90, mean_fill_pass, shoe_pass, with_air, wet, pass_note):
    """The entries of results.json that a finished run and one in progress share."""
    return {
        "fillTime50": {"value": t50, "unit": "s", "description": "die holds 50 % of the mass poured"},
        "fillTime90": {"value": t90, "unit": "s", "description": "die holds 90 % of the mass poured"},
        "meanFillRatioDuringPass": {"value": mean_fill_pass, "unit": "-",
                                    "description": "fill ratio averaged over the shoe's pass %s s (%s)"
                                                   % (list(shoe_pass) if shoe_pass else "", pass_note)},
        "air": {"value": with_air, "unit": "-", "description": "air solved with the powder (diefillFoam)"},
        "wet": {"value": wet, "unit": "-", "description": "capillary cohesion (5 % water)"},
    }


def case_air_results(case, props, until, out, s):
    """air_results with the case's air density and the powder volume in the die."""
    rho = float(foamdict.read(os.path.join(case, "constant", "transportProperties"))["rho"])
    density = float(props["materials"]["sand"]["density"])
    return air_results(case, rho, until, out, s["time"], np.asarray(s["mass_die"]) / density), density


def report_before_opening(case, out, props, s, frames, poured, fill, opening, end_time, shoe_pass, with_air, wet,
                          run_time):
    """The results of a run that has not reached the die opening yet: fill ratio so far,
    the latest side view, the air's figures; says what is missing and why."""
    t = s["time"]
    fill = np.asarray(fill)
    latest = series.read_frame(frames[-1][1])
    plots.curve(os.path.join(out, "fillRatio.png"), t, [fill], ["mass in die / mass poured"], "time [s]",
                "fill ratio [-]", title="die fill ratio (run in progress, t = %.3g s of %g s)" % (t[-1], end_time),
                vlines=[(opening, "die opening starts")] if opening <= t[-1] * 1.5 else ())
    plots.side_view(os.path.join(out, "sideView_latest.png"), latest, title=f"latest fields, t = {latest.time:.2f} s")
    write_fill_ratio_csv(os.path.join(out, "fillRatio.csv"), t, fill)
    during = (t >= shoe_pass[0]) & (t <= shoe_pass[1]) if shoe_pass else np.zeros(len(t), bool)
    t50 = first_time_reaching(t, fill, 0.5)
    t90 = first_time_reaching(t, fill, 0.9)
    res = {
        "state": {"value": "in progress", "unit": "-",
                  "description": "the run has not reached the die opening (t = %g s): no bed profile, angles or "
                                 "mass lost yet" % opening},
        "simulatedTime": {"value": float(t[-1]), "unit": "s",
                          "description": "last time in dem/summary.csv (the case ends at %g s)" % end_time},
        "massPoured": {"value": poured, "unit": "kg"},
        "fillRatioLatest": {"value": float(fill[-1]), "unit": "-", "description": "at t = %g s" % t[-1]},
    }
    res.update(common_results(t50, t90, float(np.mean(fill[during])) if during.any() else None, shoe_pass,
                              with_air, wet, "the part simulated so far"))
    res.update(liquid_results(s, shoe_pass, opening))
    if with_air:
        res.update(case_air_results(case, props, min(opening, float(t[-1])), out, s)[0])
    res.update(wall_load_results(s, props, float(t[-1]), opening, poured - float(s["lostMass"][-1]),
                                 float(s["mass_die"][-1]), out, shoe_pass[1] if shoe_pass else None))
    if run_time is not None:
        res["runTime"] = {"value": run_time, "unit": "s", "description": "wall time of the run"}
    results.write(case, res)
    # A case that fullRun manages (DIR/case beside DIR/run.sh) is continued with fullRun.
    run_dir = os.path.dirname(os.path.abspath(case))
    if os.path.exists(os.path.join(run_dir, "run.sh")) and os.path.isdir(os.path.join(run_dir, "build")):
        how = ("if it no longer runs (tutorials/dieFilling/fullRun status %s), continue it with "
               "tutorials/dieFilling/fullRun continue %s" % (run_dir, run_dir))
    else:
        how = "run ./Allrun again to continue"
    print("dieFilling (%s, %s): run in progress at t = %g s of %g s; the die opens at t = %g s: the bed profile, "
          "the angles and the mass lost at opening come once the run is past it (%s)"
          % ("wet" if wet else "dry", "air" if with_air else "vacuum", t[-1], end_time, opening, how))
    print("    so far: %.1f g poured, fill ratio %.3f, die 50 %% / 90 %% full at t = %s / %s"
          % (poured * 1e3, fill[-1], f"{t50:.3f} s" if t50 is not None else "not yet",
             f"{t90:.3f} s" if t90 is not None else "not yet"))
    return 0


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", default=".")
    ap.add_argument("-openingStart", type=finite, default=None)
    ap.add_argument("-runTime", type=non_negative, default=None, help="wall time of the run [s], for the summary")
    a = ap.parse_args()
    case = a.case
    props = foamdict.read_case(case)          # constant/demProperties
    radius, height, base_z, opening = die_geometry(props)
    if a.openingStart is not None:
        opening = a.openingStart
    if opening is None:
        sys.exit("dieFilling.py: no opening time: give -openingStart or a motion of the 'dieWall'")
    out = out_dir(case)

    s = summary.read(case)
    t = s["time"]
    frames = series.list_frames(case)
    # The mass poured: every particle inserted, i.e. the largest particle mass seen in
    # the fields plus what was lost before (particles are never added after the fill).
    poured = max(float(np.sum(series.read_frame(p).mass)) for _, p in frames[: min(len(frames), 12)])
    before = t <= opening + 1e-9
    mass_die_filled = float(s["mass_die"][before][-1])
    mass_base_final = float(s["mass_base"][-1])
    lost_total = float(s["lostMass"][-1])
    lost_before_opening = float(s["lostMass"][before][-1])
    lost_at_opening = lost_total - lost_before_opening
    fill = summary.fill_ratio(s["mass_die"], poured)
    shoe_pass = shoe_pass_window(props)
    during = (t >= shoe_pass[0]) & (t <= shoe_pass[1]) if shoe_pass else np.zeros(len(t), bool)
    mean_fill_pass = float(np.mean(np.asarray(fill)[during])) if during.any() else None
    t50 = first_time_reaching(t, np.asarray(fill), 0.5)
    t90 = first_time_reaching(t, np.asarray(fill), 0.9)
    with_air = os.path.isdir(os.path.join(case, "constant", "polyMesh"))
    wet = "cohesion" in props
    end_time = float(props.get("simulation", {}).get("endTime", t[-1]))
    dt = float(props.get("simulation", {}).get("timeStep", 0.0))
    in_progress = t[-1] < end_time - max(dt, 1e-9)
    if t[-1] < opening:
        # A long run looked at while it goes (or stopped early): what the fill has
        # shown so far; the profile and the angles need the die wall lowered.
        return report_before_opening(case, out, props, s, frames, poured, fill, opening, end_time, shoe_pass,
                                     with_air, wet, a.runTime)

    final = series.read_frame(frames[-1][1])
    filled = series.read_frame(min(frames, key=lambda e: abs(e[0] - opening))[1])
    pos = final.position.copy()
    pos[:, 2] -= base_z
    bin_width = 1.5 * float(np.mean(2 * final.radius))
    x, h = profile.line_profile(pos, final.radius, (0, 0, 0), (1, 0, 0), (0, 0, 1), bin_width,
                                extent=(-1.3 * radius, 1.3 * radius), band=radius / 4)
    centre = profile.fit_line(x, h, (-radius / 2, radius / 2))
    border = (x >= 0.8 * radius) & (x <= radius) & np.isfinite(h)
    right_height = float(np.mean(h[border])) if border.any() else None
    top = float(np.nanmax(h)) if np.isfinite(h).any() else None
    # The right border stands close to vertical: measured from the bed's edge position vs
    # height, which a height profile cannot resolve.
    right = None
    try:
        right = profile.edge_angle(pos, final.radius, (0, 0, 0), (1, 0, 0), (0, 0, 1), band=radius / 4,
                                   bin_height=bin_width)
    except ValueError as e:
        print("dieFilling.py: right border:", e)

    with output.open_replacing(os.path.join(out, "profile.csv")) as f:
        f.write("x_mm,height_mm\n")
        for xi, hi in zip(x, h):
            f.write(f"{xi * 1e3:.4f},{'' if not np.isfinite(hi) else f'{hi * 1e3:.4f}'}\n")
    profile_plot(os.path.join(out, "profile.png"), x, h, [centre],
                 f"bed profile after opening (plane of shoe motion): centre {centre['angle']:.1f} deg"
                 + (f", right border {right['angle']:.1f} deg" if right else ""))
    plots.curve(os.path.join(out, "fillRatio.png"), t, [fill], ["mass in die / mass poured"], "time [s]",
                "fill ratio [-]", title="die fill ratio", vlines=[(opening, "die opening starts")])
    write_fill_ratio_csv(os.path.join(out, "fillRatio.csv"), t, fill)
    first_half, on_base = half_masses(final.position, np.asarray(final.mass, float), radius)
    along = slope_along_motion(centre["slope"])
    plots.side_view(os.path.join(out, "sideView_filled.png"), filled, title=f"filled die, t = {filled.time:.2f} s")
    plots.side_view(os.path.join(out, "sideView_final.png"), final, title=f"after opening, t = {final.time:.2f} s")

    res = {
        "centralAngle": {"value": round(centre["angle"], 2), "unit": "deg",
                         "description": f"fit over x in [{-radius / 2 * 1e3:.1f}, {radius / 2 * 1e3:.1f}] mm "
                                        "(paper: 33.8 measured, 32.9 simulated)"},
        "centralAngleAlongMotion": {"value": round(along, 2), "unit": "deg",
                                    "description": "the central angle with its sign: positive where the surface "
                                                   "falls in the direction of the shoe's motion (the experiment's), "
                                                   "negative where it rises"},
        "centralSlopeFalls": {"value": bool(along > 0), "unit": "-",
                              "description": "the central surface falls in the direction of the shoe's motion "
                                             "(as in the experiment)"},
        "massFractionFirstHalf": {"value": round(first_half / on_base, 4) if on_base > 0 else None, "unit": "-",
                                  "description": "of the bed on the die base after the opening, the share in the "
                                                 "die's first half along the shoe's motion (x < 0; the paper: 'most "
                                                 "of the material' there)"},
        "centralFitRms": {"value": round(centre["rms"] * 1e3, 3), "unit": "mm",
                          "description": "rms distance of the central profile points from the fitted line: a "
                                         "large value (compared with a grain, %.2f mm) means the surface there is "
                                         "not a plane slope and the angle is not meaningful"
                                         % (float(np.mean(2 * final.radius)) * 1e3)},
        "rightBorderAngle": {"value": round(right["angle"], 2) if right else None, "unit": "deg",
                             "description": ("edge position vs height fitted over heights [%.1f, %.1f] mm "
                                             "above the base" % tuple(w * 1e3 for w in right["window"])
                                             if right else "no edge found") + " (paper: about 90)"},
        "rightBorderHeight": {"value": round(right_height * 1e3, 3) if right_height is not None else None,
                              "unit": "mm",
                              "description": "mean bed height above the base over x in [0.8 R, R] after "
                                             "the opening (none: no powder there)"},
        "bedHeight": {"value": round(top * 1e3, 3) if top is not None else None, "unit": "mm",
                      "description": "highest point of the surface profile after the opening"},
        "massPoured": {"value": poured, "unit": "kg"},
        "massInDieFilled": {"value": mass_die_filled, "unit": "kg", "description": f"at t = {opening} s"},
        "fillRatioFilled": {"value": mass_die_filled / poured, "unit": "-"},
        "massOnBaseFinal": {"value": mass_base_final, "unit": "kg"},
        "massLostAtOpening": {"value": lost_at_opening, "unit": "kg"},
        "fractionLostAtOpening": {"value": lost_at_opening / mass_die_filled if mass_die_filled > 0 else None,
                                  "unit": "-", "description": "of the mass in the die (paper: 0.10 simulated, 0.02 measured)"},
        "openingStart": {"value": opening, "unit": "s"},
    }
    res.update(common_results(t50, t90, mean_fill_pass, shoe_pass, with_air, wet, "lower: the die fills later"))
    res.update(liquid_results(s, shoe_pass, opening))
    if with_air:
        air, density = case_air_results(case, props, opening, out, s)
        res.update(air)
        res["shoeBedWeightPerArea"] = {"value": round(poured * 9.81 / (np.pi * radius**2), 3), "unit": "Pa",
                                       "description": "weight of the powder in the shoe over the shoe's "
                                                      "cross-section (the shoe and the die have one radius)"}
        res["solidVolumeInDieFilled"] = {"value": mass_die_filled / density, "unit": "m3",
                                         "description": f"mass in the die / {density:g} kg/m3 at t = {opening} s"}
    if a.runTime is not None:
        res["runTime"] = {"value": a.runTime, "unit": "s", "description": "wall time of demRun"}
    res["simulatedTime"] = {"value": float(t[-1]), "unit": "s",
                            "description": "last time in dem/summary.csv (the case ends at %g s)" % end_time}
    res.update(wall_load_results(s, props, opening, opening, poured - lost_before_opening, mass_die_filled, out,
                                 shoe_pass[1] if shoe_pass else None))
    if in_progress:
        print("dieFilling.py: the run is not finished (t = %g s of %g s): the figures below are those "
              "of that time, not the final ones" % (t[-1], end_time))
    results.write(case, res)
    print("dieFilling (%s, %s): central angle %.1f deg (fit rms %.1f mm; the surface %s in the shoe's direction), "
          "right border %s deg, fill ratio %.3f, "
          "lost at opening %.1f %%, die 50 %% / 90 %% full at t = %s / %s s"
          % ("wet" if wet else "dry", "air" if with_air else "vacuum", centre["angle"], centre["rms"] * 1e3,
             "falls" if along > 0 else "rises",
             f"{right['angle']:.1f}" if right else "n/a", mass_die_filled / poured,
             100 * lost_at_opening / max(mass_die_filled, 1e-30),
             f"{t50:.3f}" if t50 is not None else "n/a", f"{t90:.3f}" if t90 is not None else "n/a"))
    if "dieBaseLoadFilled" in res:
        print("    walls before the opening: together %.3f of the particles' weight; the die base %.3f of the die's "
              "powder (wallLoads.png)" % (res["wallLoadFilled"]["value"], res["dieBaseLoadFilled"]["value"]))
    if "aerationOverpressure" in res:
        print("    aeration: %.2f Pa over the air's own pressure on the plate under the shoe's bed "
              "(bed weight per area %.1f Pa)" % (res["aerationOverpressure"]["value"],
                                                res["shoeBedWeightPerArea"]["value"]))
    if "airVolumeOutOfDie" in res:
        print("    air out of the die until the opening: %.3g cm3; powder volume in the die: %.3g cm3"
              % (res["airVolumeOutOfDie"]["value"] * 1e6, res["solidVolumeInDieFilled"]["value"] * 1e6))
    return 0


if __name__ == "__main__":
    run_main(main)
