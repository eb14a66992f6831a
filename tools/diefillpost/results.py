"""results.json + results.csv: the numbers a case reports, with units."""
import csv
import json
import os

from .output import open_replacing


def write(case_dir, results, name="results"):
    """results: {key: {"value": v, "unit": u, "description": d}} or {key: v}.
    Writes <case>/postProcessing/<name>.json and .csv; returns both paths."""
    out = os.path.join(case_dir, "postProcessing")
    os.makedirs(out, exist_ok=True)
    rows = {k: (v if isinstance(v, dict) and "value" in v else {"value": v}) for k, v in results.items()}
    jpath, cpath = os.path.join(out, name + ".json"), os.path.join(out, name + ".csv")
    with open_replacing(jpath) as f:
        json.dump(rows, f, indent=2)
        f.write("\n")
    with open_replacing(cpath, newline="") as f:
        w = csv.writer(f)
        w.writerow(["quantity", "value", "unit", "description"])
        for k, r in rows.items():
            v = r["value"]
            if isinstance(v, (list, tuple)):
                v = " ".join(str(x) for x in v)
            w.writerow([k, v, r.get("unit", ""), r.get("description", "")])
    return jpath, cpath


def read(case_dir, name="results"):
    with open(os.path.join(case_dir, "postProcessing", name + ".json")) as f:
        return json.load(f)


def existing(case_dir, name="results"):
    """The results in <case>/postProcessing/<name>.json ({} when there is none); a file that
    is not a JSON object is a ValueError naming it."""
    path = os.path.join(case_dir, "postProcessing", name + ".json")
    if not os.path.exists(path):
        return {}
    try:
        with open(path) as f:
            old = json.load(f)
    except ValueError as e:
        raise ValueError(f"'{path}' is not valid JSON ({e}); move it aside to write new results") from None
    if not isinstance(old, dict):
        raise ValueError(f"'{path}' is not a JSON object of results; move it aside to write new results")
    return old


def update(case_dir, results, name="results"):
    """Adds `results` to <case>/postProcessing/<name>.json and .csv (as write()), keeping
    the keys that are there already (other tools' results); a key given again is replaced.
    A <name>.json that is not a JSON object is a ValueError naming it (it is left as it is)."""
    merged = existing(case_dir, name)
    merged.update(results)
    return write(case_dir, merged, name)
