#!/usr/bin/python3
"""Plot the CSV written by demCapillaryScaling (capillary force vs coarse-grain factor).

Usage: plotCapillaryScaling.py [capillaryScaling.csv] [capillaryScaling.png]

Left: capillary force for particles l times larger, normalised by l = 1, for the
readings the app evaluates, against the paper's fit 0.95 l + 0.056.
Right: capillary Bond number (capillary force / particle weight) relative to
l = 1 without eq 9, with eq 9 (kappa = 2.0142) and with kappa = 2.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (backend must be chosen first)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import run_main  # noqa: E402
from diefillpost.output import replacing  # noqa: E402


COLUMNS = ("l", "ratioContact", "ratioGap", "ratioFixedVolumeContact", "ratioFixedVolumeFixedGap", "paperFit",
           "bondRatioUncorrected", "bondRatioEq9", "bondRatioKappa2")


def read_columns(path):
    """The columns of the CSV as lists of numbers; a missing column, a line with
    another number of fields than the header or a field that is not a number is a
    ValueError naming the file (and the line)."""
    with open(path, newline="") as handle:
        lines = list(csv.reader(handle))
    if not lines:
        raise ValueError(f"'{path}' is empty (no header); expected the CSV written by demCapillaryScaling")
    header = lines[0]
    missing = [name for name in COLUMNS if name not in header]
    if missing:
        raise ValueError(f"'{path}': no column {', '.join(missing)}; expected the CSV written by demCapillaryScaling")
    columns = {key: [] for key in header}
    for number, row in enumerate(lines[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise ValueError(f"'{path}' line {number}: {len(row)} fields, the header has {len(header)}")
        for key, text in zip(header, row):
            try:
                columns[key].append(float(text))
            except ValueError:
                raise ValueError(f"'{path}' line {number}: '{text}' is not a number") from None
    if not columns["l"]:
        raise ValueError(f"'{path}' has no data rows")
    return columns


def main(argv):
    if any(arg in ("-h", "-help", "--help") for arg in argv[1:]):
        print(__doc__)
        return 0
    source = argv[1] if len(argv) > 1 else "capillaryScaling.csv"
    target = argv[2] if len(argv) > 2 else source.rsplit(".", 1)[0] + ".png"
    data = read_columns(source)
    scale = data["l"]

    figure, (forces, bond) = plt.subplots(1, 2, figsize=(11, 4.5))
    forces.plot(scale, data["ratioContact"], "o-", label="eqs 1-5, radii and $V_b \\times l^3$ (contact)")
    forces.plot(scale, data["ratioGap"], "s--", label="eqs 1-5, radii and $V_b \\times l^3$ (gap $\\times l$)")
    forces.plot(scale, data["ratioFixedVolumeContact"], "^-", label="radii $\\times l$, $V_b$ unscaled (contact)")
    if any(value != 0.0 for value in data["ratioFixedVolumeFixedGap"]):
        forces.plot(scale, data["ratioFixedVolumeFixedGap"], "v-", label="radii $\\times l$, $V_b$ and gap unscaled")
    forces.plot(scale, data["paperFit"], "k:", label="paper fit $0.95\\,l + 0.056$")
    forces.set_xlabel("coarse-grain factor $l$")
    forces.set_ylabel("$f^C_n(l) / f^C_n(1)$")
    forces.set_title("Capillary force vs scale")
    forces.grid(True, alpha=0.3)
    forces.legend(fontsize=8)

    bond.semilogy(scale, data["bondRatioUncorrected"], "o-", label="no correction ($\\propto l^{-2}$)")
    bond.semilogy(scale, data["bondRatioEq9"], "s-", label="eq 9, $\\kappa = 2.0142$")
    bond.semilogy(scale, data["bondRatioKappa2"], "k--", label="$\\kappa = 2$ (exact)")
    bond.set_xlabel("coarse-grain factor $l$")
    bond.set_ylabel("$Bo(l) / Bo(1)$,  $Bo = |f^C_n| / (m g)$")
    bond.set_title("Capillary Bond number")
    bond.grid(True, which="both", alpha=0.3)
    bond.legend(fontsize=8)

    figure.tight_layout()
    with replacing(target) as tmp:
        figure.savefig(tmp, dpi=150, format="png")
    print(f"plotCapillaryScaling: wrote {target}")
    return 0


if __name__ == "__main__":
    run_main(main, sys.argv)
