#!/usr/bin/env python3
"""Number checks of tests/diefillFoam/run.  Each subcommand prints what it
measured and what was expected, and exits 0 (pass) or 1 (fail).

  terminal LOG RHO_P RHO_F MU D G [NOBUOY]  terminal velocity vs Schiller-Naumann
  balance LOG                                drag on particles == air's loss
  ergun CASE TIME:U... D MU RHO L            bed pressure drop vs Ergun
  same A B TOL                               two figure files agree within TOL
"""
import math
import re
import sys

VEC = r"\(([^()]*)\)"


def log_values(log, pattern):
    return [m for m in re.findall(pattern, open(log).read())]


def schiller_naumann_terminal(rho_p, rho_f, mu, d, g, buoyancy=True):
    """Solve (rho_p - rho_f) g V = 3 pi mu d v (1 + 0.15 Re^0.687) by bisection."""
    volume = math.pi * d**3 / 6
    weight = ((rho_p - rho_f) if buoyancy else rho_p) * g * volume

    def excess(v):
        re_p = rho_f * d * v / mu
        return 3 * math.pi * mu * d * v * (1 + 0.15 * re_p**0.687) - weight

    lo, hi = 0.0, 100.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def terminal(args):
    log, rho_p, rho_f, mu, d, g = args[0], *map(float, args[1:6])
    vz = [float(v.split()[2]) for v in log_values(log, r"mean particle velocity " + VEC)]
    v_end = -vz[-1]
    v_sn = schiller_naumann_terminal(rho_p, rho_f, mu, d, g)
    v_nobuoy = schiller_naumann_terminal(rho_p, rho_f, mu, d, g, buoyancy=False)
    err = abs(v_end - v_sn) / v_sn
    re_p = rho_f * d * v_sn / mu
    print(f"    terminal velocity {v_end:.6g} m/s; Schiller-Naumann force balance {v_sn:.6g} m/s "
          f"(Re {re_p:.3g}); error {100*err:.3f} % (tolerance 2 %); "
          f"without buoyancy it would be {v_nobuoy:.6g} m/s")
    # The velocity must also have settled: the last 10 % of the run changes < 0.2 %
    late = -vz[int(0.9 * len(vz))]
    settled = abs(v_end - late) / v_sn < 2e-3
    print(f"    velocity at 90 % of the run {late:.6g} m/s (settled: {settled})")
    with open(log + ".figures", "w") as f:
        f.write(f"terminalVelocity {v_end:.10g}\n")
    return err < 0.02 and settled


def balance(args):
    log = args[0]
    text = open(log).read()
    drags = [math.sqrt(sum(float(x) ** 2 for x in v.split()))
             for v in re.findall(r"drag on particles " + VEC, text)]
    imbalance = [float(x) for x in re.findall(r"imbalance ([0-9.eE+-]+)", text)]
    worst = max(imbalance, default=float("inf"))
    scale = max(drags, default=0.0)
    print(f"    {len(imbalance)} coupling steps; largest |drag on particles - air's loss| / |drag| = "
          f"{worst:.3e} (tolerance 1e-10); largest |drag| {scale:.4g} N")
    return len(imbalance) > 0 and scale > 0 and worst < 1e-10


def read_internal_scalars(path):
    text = open(path).read()
    m = re.search(r"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\((.*?)\)\s*;", text, re.S)
    return [float(v) for v in m.group(2).split()]


def ergun(args):
    case, pairs = args[0], [a for a in args[1:] if ":" in a]
    d, mu, rho, length = map(float, [a for a in args[1:] if ":" not in a])
    rows = [l.split() for l in open(f"{case}/postProcessing/bedPressure/0/p") if not l.startswith("#")]
    rows = [[float(x) for x in r] for r in rows if r]
    eps = None
    if len(args) and __import__("os").path.isdir(case):
        import glob, os
        times = sorted((t for t in os.listdir(case) if re.fullmatch(r"[0-9.e-]+", t) and t != "0"), key=float)
        if times:
            alpha = read_internal_scalars(f"{case}/{times[-1]}/alpha.air")
            # cells: 4 x 4 per layer, bed in layers 2..9
            bed = [alpha[i] for i in range(len(alpha)) if 2 <= i // 16 <= 9]
            eps = sum(bed) / len(bed)
    if eps is None:
        print("    no alpha.air field to measure the porosity")
        return False
    print(f"    bed porosity measured from alpha.air: {eps:.6f}")
    ok = True
    out = open(f"{case}/ergun.figures", "w")
    for p in pairs:
        t, u = map(float, p.split(":"))
        row = min(rows, key=lambda r: abs(r[0] - t))
        dp = rho * (row[1] - row[2])
        expected = length * (150 * mu * (1 - eps) ** 2 * u / (eps**3 * d**2)
                             + 1.75 * rho * (1 - eps) * u**2 / (eps**3 * d))
        err = abs(dp - expected) / expected
        ok = ok and err < 0.03
        print(f"    U = {u:g} m/s: pressure drop {dp:.6g} Pa over {1000*length:g} mm, "
              f"Ergun {expected:.6g} Pa, error {100*err:.3f} % (tolerance 3 %)")
        out.write(f"dp_{u:g} {dp:.10g}\n")
    return ok


def same(args):
    a, b, tol = args[0], args[1], float(args[2])
    fa = dict(l.split() for l in open(a))
    fb = dict(l.split() for l in open(b))
    ok = set(fa) == set(fb) and len(fa) > 0
    for k in sorted(fa):
        va, vb = float(fa[k]), float(fb.get(k, "nan"))
        rel = abs(va - vb) / max(abs(va), 1e-300)
        ok = ok and rel < tol
        print(f"    {k}: serial {va:.8g}, parallel {vb:.8g}, relative difference {rel:.2e} (tolerance {tol:g})")
    return ok


if __name__ == "__main__":
    command = {"terminal": terminal, "balance": balance, "ergun": ergun, "same": same}[sys.argv[1]]
    sys.exit(0 if command(sys.argv[2:]) else 1)
