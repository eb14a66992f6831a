"""Physical checks of an own-die example run (tests/ownDie/run): the masses in the cavity and
its regions from dem/summary.csv, the figures of postProcessing/results.json, the derived
figures of constant/dieCase.json.  Usage: check_example.py ring|twoLevel CASE.
One line per check, 'PASS: ...' or 'FAIL: ...'."""
import csv
import json
import os
import sys

SAND = 2650.0


def main(name, case):
    ok = []

    def check(what, cond, detail=""):
        ok.append(bool(cond))
        print(("PASS: " if cond else "FAIL: ") + f"{name}: {what}" + (f" ({detail})" if detail else ""), flush=True)

    try:
        info = json.load(open(os.path.join(case, "constant", "dieCase.json")))
        rows = list(csv.DictReader(open(os.path.join(case, "dem", "summary.csv"))))
    except OSError as e:
        check("the run's dieCase.json and dem/summary.csv exist", False, str(e))
        return 1
    t = [float(r["time"]) for r in rows]
    filled_time = info["timeline_s"]["filled"]
    k_filled = max(i for i, x in enumerate(t) if x <= filled_time + 1e-9)
    at = rows[k_filled]
    volume = info["cavityVolume_m3"]
    cavity = float(at["mass_cavity"])
    fraction = cavity / (volume * SAND)
    check(f"filled at t = {filled_time:.3g} s: solid fraction in the cavity {fraction:.3f} within 0.40-0.66 "
          f"(a poured packing of F32 parcels; {cavity * 1e3:.2f} g in {volume * 1e6:.2f} cm3)", 0.40 <= fraction <= 0.66)
    grid = sum(float(v) for k, v in at.items() if k.startswith("mass_grid_"))
    check("the region grid's masses add up to the cavity's (every parcel in one region)",
          abs(grid - cavity) <= 0.01 * cavity, f"{grid * 1e3:.3f} g vs {cavity * 1e3:.3f} g")
    results_path = os.path.join(case, "postProcessing", "results.json")
    try:
        results = json.load(open(results_path))
    except (OSError, ValueError) as e:
        results = {}
        check("postProcessing/results.json written", False, str(e))

    def number(key):
        """results.json rows are {"value": v, "unit": u, "description": d} (diefillpost.results)."""
        v = results.get("fillDensity." + key)
        return v.get("value") if isinstance(v, dict) else v

    mean = number("mean")
    check("results.json holds the fill density's mean, max - min and coefficient of variation",
          all(isinstance(number(k), float) for k in ("mean", "maxMinusMin", "coefficientOfVariation")),
          ", ".join(f"{k} {number(k)}" for k in ("mean", "maxMinusMin", "coefficientOfVariation")))
    if mean is not None:
        check(f"the mean column bulk density {mean:.0f} kg/m3 is the cavity's mass / volume "
              f"{cavity / volume:.0f} kg/m3 within 5 %", abs(mean - cavity / volume) <= 0.05 * cavity / volume)

    if name == "ring":
        # The shoe comes from -x: the half of the ring it reaches first holds more when half the
        # final mass is in (the powder falls in from the shoe's front as it passes).
        half = 0.5 * cavity
        k50 = next(i for i, r in enumerate(rows) if float(r["mass_cavity"]) >= half)
        near, far = float(rows[k50]["mass_nearHalf"]), float(rows[k50]["mass_farHalf"])
        check(f"at half fill (t = {t[k50]:.3f} s) the near half holds more than the far half "
              f"({near * 1e3:.2f} g vs {far * 1e3:.2f} g)", near > far)
        check("near + far halves = the cavity (regions from the dieDict)",
              abs(float(at["mass_nearHalf"]) + float(at["mass_farHalf"]) - cavity) <= 0.01 * cavity)
        stamp = info["steps"].get("stamp")
        check("the ring example has a pre-compaction stamp", bool(stamp))
        if stamp:
            # Held at depth, the stamp's force goes through the powder to the floors and, by
            # friction, to the die wall: the forces on the walls balance (plus the powder's weight).
            held = [r for r in rows if stamp["pressed_s"] <= float(r["time"]) <= stamp["released_s"]]
            f = lambda r, w: float(r[f"wallForce_{w}_z"])
            pressed = [f(r, "stamp") for r in held]
            weight = 9.81 * cavity
            residual = max(abs(f(r, "stamp") + f(r, "dieFloors") + f(r, "dieWalls") + weight) for r in held)
            before = next(float(r["mass_cavity"]) for r in reversed(rows) if float(r["time"]) <= stamp["comesDown_s"])
            mean_force = sum(pressed) / len(pressed) if held else 0.0
            if "mass_kg" in stamp:
                # Resting under its weight: the powder carries it, and it stands as deep as the
                # powder let it sink, short of its stop (summary's wallOffset_stamp = results.json's depth).
                stamp_weight = 9.81 * stamp["mass_kg"]
                sank = [float(r["wallOffset_stamp"]) for r in held]
                depth = number("stamp.depth")
                check(f"stamp of {stamp['mass_kg']:g} kg at rest on the powder: it carries {mean_force:.3f} N of its "
                      f"weight {stamp_weight:.3f} N (5 % allowed)",
                      held and abs(mean_force - stamp_weight) <= 0.05 * stamp_weight)
                depth_text = f"{depth * 1e3:.3f}" if isinstance(depth, float) else f"{depth!r}"
                check(f"stamp: it sank {depth_text} mm below the table (results.json), into the "
                      f"powder and short of its stop ({stamp['stroke_m'] * 1e3:g} mm)",
                      isinstance(depth, float) and 0 < depth < stamp["stroke_m"]
                      and abs(depth - sum(sank) / len(sank)) <= 1e-9)
            else:
                check(f"stamp held {stamp['depth_m'] * 1e3:g} mm in: pressed by the powder ({min(pressed):.2f}-"
                      f"{max(pressed):.2f} N)", held and min(pressed) > 10 * weight)
            # (While the stamp presses, CDT's rolling torque makes the walls' friction forces
            # alternate by about +-0.14 N from step to step; summary.csv logs each wall's mean
            # force over the log interval, which balances to about 0.001 N: 1 % allowed.
            # docs/own-die.md, "Limits".)
            check(f"stamp: balanced by floors + die wall - the powder's weight ({weight:.3f} N) to {residual:.3f} N "
                  f"(1 % of its force allowed)", held and residual <= 0.01 * mean_force)
            walls = -sum(f(r, "dieWalls") for r in held) / sum(pressed)
            check(f"stamp: the die wall carries part of it by friction ({walls:.2f}), the floors the rest",
                  0.05 < walls < 0.95)
            check(f"stamp: no powder pressed out of the cavity ({before * 1e3:.3f} g before, {cavity * 1e3:.3f} g "
                  "after)", abs(cavity - before) <= 0.005 * before)
            pressure = number("stamp.pressure")
            check(f"results.json: the stamp's pressure {pressure} Pa = its mean force while held / the opening area",
                  isinstance(pressure, float) and abs(pressure * info["openingArea_m2"] - sum(pressed) / len(pressed))
                  <= 1e-6 * sum(pressed) / len(pressed))
    else:
        v_shallow, v_deep = 24e-3 * 24e-3 * 10e-3, 8e-3 * 24e-3 * 20e-3
        shallow = float(at["mass_shallow"]) / v_shallow
        deep = float(at["mass_deepStrip"]) / v_deep

        def half_time(key):
            final = float(at[key])
            return next(float(r["time"]) for r in rows if float(r[key]) >= 0.5 * final)
        t_shallow, t_deep = half_time("mass_shallow"), half_time("mass_deepStrip")
        # The shoe comes from -x: the deep strip at the far side gets its powder last.
        check(f"the deep strip on the far side is half filled after the wide level ({t_deep:.3f} s vs "
              f"{t_shallow:.3f} s; bulk densities {deep:.0f} and {shallow:.0f} kg/m3)", t_deep > t_shallow)
        check("both levels hold powder at a poured density (> 0.3 of the sand's)", deep > 0.3 * SAND and shallow > 0.3 * SAND)
    lost = float(rows[-1]["lostMass"])
    check(f"after the die wall is lowered the bed stands on the floors: {lost * 1e3:.2f} g lost of "
          f"{cavity * 1e3:.2f} g", lost <= 0.5 * cavity)
    return 0 if all(ok) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
