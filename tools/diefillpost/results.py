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
