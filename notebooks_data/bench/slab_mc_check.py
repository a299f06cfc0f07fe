#!/usr/bin/env python3
"""Independent Monte Carlo of a pencil beam on a homogeneous slab, checked against `lucent simulate`.

Written from the physics (MCML conventions, Wang & Jacques 1995), not from lucent's source:
- slab 0 > z > -d (mm), index 1 above and below, relative index eta = n_sample / n_outside;
- a pencil beam of unit power enters at the origin along -z; the specular part
  R_sp = ((eta - 1) / (eta + 1))^2 is removed, the rest enters;
- free paths exponential with sigma_t = sigma_a + sigma_s; Henyey-Greenstein scattering with g;
- absorption analog (the photon dies with probability 1 - albedo at an interaction; default) or by
  implicit capture (weight *= albedo, Russian roulette below 1e-4 with survival 0.1: --implicit);
- at a surface the photon is reflected with the unpolarised Fresnel probability R(theta) (total
  internal reflection included), else it escapes with its whole weight (stochastic boundary); a
  fresh exponential path is drawn after a reflection (the exponential law is memoryless);
- escaping weight is scored by the radius of the exit point, top (R(r)) and bottom (T(r)) apart,
  per mm^2 per unit incident power, in the annuli of lucent's own CSV; photons that never scattered
  (the ballistic beam and its internal bounces) are tallied apart, not in the bins.

Each photon escapes at most once, so a bin's (or a total's) standard error is the sample standard
error of the per-photon contributions.

Then for each case `lucent simulate --profile-only --exitance-csv` is run for both sides (the three
colour channels carry the same coefficients: three independent lucent estimates, averaged) and the
totals and radial bins are compared. Writes slab_mc_check.md beside this file.

Usage: python3 notebooks_data/bench/slab_mc_check.py [--lucent PATH] [--scale F] [--cases 1,2,..]
       [--implicit] [--self-test] [--out FILE]
numpy is needed; when the running interpreter lacks it and /usr/bin/python3 has it, the script
re-runs itself there.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

try:
    import numpy as np
except ImportError:  # e.g. a pyenv python without numpy; Debian's python3-numpy lives in /usr/bin/python3
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))

# (label, eta, g, sigma_a, sigma_s, d, my photons, lucent photons per channel)
CASES = [
    (1, 1.0, 0.75, 1.0, 9.0, 0.2, 20_000_000, 5_000_000),
    (2, 1.4, 0.0, 0.05, 2.0, 2.0, 10_000_000, 5_000_000),
    (3, 1.3, 0.5, 0.02, 1.6, 5.0, 8_000_000, 5_000_000),
    (4, 1.5, 0.8, 0.01, 5.0, 1.0, 8_000_000, 5_000_000),
    (5, 1.4, 0.0, 0.1, 1.0, 10.0, 10_000_000, 5_000_000),
    # a convention probe: a thin, weakly scattering slab whose unscattered beam leaves the top after
    # one internal reflection (3% of the power): which total holds it, and whether the bins do
    (6, 1.5, 0.0, 0.01, 0.1, 1.0, 10_000_000, 5_000_000),
]


# ----------------------------------------------------------------------------------------------
# The independent Monte Carlo
# ----------------------------------------------------------------------------------------------
def fresnel_out(cos_i, eta):
    """Unpolarised Fresnel reflectance for light inside (index eta) meeting index 1 at cos_i."""
    if eta == 1.0:
        return np.zeros_like(cos_i)
    sin_t2 = eta * eta * (1.0 - cos_i * cos_i)
    tir = sin_t2 >= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin_t2, 0.0, 1.0))
    rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    rp = (eta * cos_t - cos_i) / (eta * cos_t + cos_i)
    return np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))


def hg_cos(g, xi):
    if abs(g) < 1e-9:
        return 2.0 * xi - 1.0
    t = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi)
    return np.clip((1.0 + g * g - t * t) / (2.0 * g), -1.0, 1.0)


def scatter(ux, uy, uz, g, rng):
    n = ux.size
    ct = hg_cos(g, rng.random(n))
    st = np.sqrt(np.maximum(0.0, 1.0 - ct * ct))
    phi = 2.0 * np.pi * rng.random(n)
    cp, sp = np.cos(phi), np.sin(phi)
    nearz = np.abs(uz) > 0.99999
    tmp = np.sqrt(np.maximum(1e-300, 1.0 - uz * uz))
    nx = np.where(nearz, st * cp, st * (ux * uz * cp - uy * sp) / tmp + ux * ct)
    ny = np.where(nearz, st * sp, st * (uy * uz * cp + ux * sp) / tmp + uy * ct)
    nz = np.where(nearz, np.sign(uz) * ct, -st * cp * tmp + uz * ct)
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    return nx / norm, ny / norm, nz / norm


class Tally:
    """Sums of per-photon contributions (each photon adds to one bin at most once)."""

    def __init__(self, edges_R, edges_T):
        self.edges = {"R": np.asarray(edges_R), "T": np.asarray(edges_T)}
        self.bins = {s: np.zeros((2, e.size - 1)) for s, e in self.edges.items()}
        self.tot = {k: np.zeros(2) for k in ("R_diff", "R_ball", "T_scat", "T_ball", "A", "lost")}
        self.n = 0
        self.interactions = 0

    def add_total(self, key, w):
        self.tot[key] += (w.sum(), (w * w).sum())

    def add_bins(self, side, r, w):
        e = self.edges[side]
        i = np.searchsorted(e, r, side="right") - 1
        ok = (i >= 0) & (i < e.size - 1)
        nb = e.size - 1
        self.bins[side][0] += np.bincount(i[ok], weights=w[ok], minlength=nb)
        self.bins[side][1] += np.bincount(i[ok], weights=w[ok] ** 2, minlength=nb)

    def merge(self, o):
        for s in self.bins:
            self.bins[s] += o.bins[s]
        for k in self.tot:
            self.tot[k] += o.tot[k]
        self.n += o.n
        self.interactions += o.interactions

    @staticmethod
    def mean_se(s, n):
        m = s[0] / n
        var = np.maximum(s[1] / n - m * m, 0.0) * n / max(n - 1, 1)
        return m, np.sqrt(var / n)

    def totals(self):
        return {k: self.mean_se(v, self.n) for k, v in self.tot.items()}

    def radial(self, side):
        e = self.edges[side]
        area = np.pi * (e[1:] ** 2 - e[:-1] ** 2)
        m, se = self.mean_se(self.bins[side], self.n)
        return m / area, se / area


def run_batch(n, sa, ss, g, eta, d, tally, rng, implicit):
    st_ = sa + ss
    albedo = ss / st_
    rsp = ((eta - 1.0) / (eta + 1.0)) ** 2
    x = np.zeros(n)
    y = np.zeros(n)
    z = np.zeros(n)
    ux = np.zeros(n)
    uy = np.zeros(n)
    uz = -np.ones(n)
    w = np.full(n, 1.0 - rsp)
    scat = np.zeros(n, dtype=bool)
    ab = np.zeros(n)  # absorbed weight of each live photon (implicit capture)
    tally.n += n
    while x.size:
        m = x.size
        s = -np.log1p(-rng.random(m)) / st_  # 1 - U in (0, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            dist = np.where(uz < 0.0, (z + d) / -uz, -z / uz)
        dist = np.where(np.isfinite(dist), dist, np.inf)
        hit = s >= dist
        step = np.minimum(s, dist)
        x += step * ux
        y += step * uy
        z += step * uz
        alive = np.ones(m, dtype=bool)

        # --- boundary
        h = np.nonzero(hit)[0]
        if h.size:
            top = uz[h] > 0.0
            z[h] = np.where(top, 0.0, -d)
            refl = rng.random(h.size) < fresnel_out(np.abs(uz[h]), eta)
            uz[h[refl]] = -uz[h[refl]]
            e = h[~refl]
            if e.size:
                et = top[~refl]
                we = w[e]
                r = np.hypot(x[e], y[e])
                sc = scat[e]
                for side, mask in (("R", et), ("T", ~et)):
                    ms = mask & sc
                    tally.add_bins(side, r[ms], we[ms])
                tally.add_total("R_diff", we * (et & sc))
                tally.add_total("R_ball", we * (et & ~sc))
                tally.add_total("T_scat", we * (~et & sc))
                tally.add_total("T_ball", we * (~et & ~sc))
                tally.add_total("A", ab[e])
                alive[e] = False

        # --- interaction
        k = np.nonzero(~hit)[0]
        if k.size:
            tally.interactions += k.size
            if implicit:
                ab[k] += w[k] * (1.0 - albedo)
                w[k] *= albedo
                sk = k
            else:
                dead = rng.random(k.size) >= albedo
                kd = k[dead]
                ab[kd] += w[kd]
                tally.add_total("A", ab[kd])
                alive[kd] = False
                sk = k[~dead]
            if sk.size:
                ux[sk], uy[sk], uz[sk] = scatter(ux[sk], uy[sk], uz[sk], g, rng)
                scat[sk] = True
            if implicit:
                low = k[w[k] < 1e-4]
                if low.size:
                    survive = rng.random(low.size) < 0.1
                    w[low[survive]] /= 0.1
                    gone = low[~survive]
                    tally.add_total("A", ab[gone])
                    tally.add_total("lost", w[gone])  # weight removed by roulette (zero in expectation)
                    alive[gone] = False
        if not alive.all():
            keep = np.nonzero(alive)[0]
            x, y, z, ux, uy, uz, w, scat, ab = (a[keep] for a in (x, y, z, ux, uy, uz, w, scat, ab))


def _worker(args):
    n, sa, ss, g, eta, d, edges_R, edges_T, seed, implicit, batch = args
    rng = np.random.default_rng(seed)
    t = Tally(edges_R, edges_T)
    done = 0
    while done < n:
        b = min(batch, n - done)
        run_batch(b, sa, ss, g, eta, d, t, rng, implicit)
        done += b
    return t


def transport(n, sa, ss, g, eta, d, edges_R, edges_T, seed=12345, implicit=False, workers=2, batch=50_000):
    """n photons in `workers` processes; returns the merged Tally."""
    seeds = np.random.SeedSequence(seed).spawn(workers)
    parts = [n // workers + (1 if i < n % workers else 0) for i in range(workers)]
    jobs = [(parts[i], sa, ss, g, eta, d, edges_R, edges_T, seeds[i], implicit, batch) for i in range(workers)]
    if workers > 1:
        import multiprocessing as mp

        with mp.get_context("fork").Pool(workers) as pool:
            res = pool.map(_worker, jobs)
    else:
        res = [_worker(jobs[0])]
    t = res[0]
    for o in res[1:]:
        t.merge(o)
    return t


def ballistic(sa, ss, eta, d):
    """Unscattered beam, summed over its internal bounces: (top, bottom) per unit incident power."""
    rsp = ((eta - 1.0) / (eta + 1.0)) ** 2
    a = math.exp(-(sa + ss) * d)
    geo = 1.0 / (1.0 - (rsp * a) ** 2)
    return (1 - rsp) ** 2 * rsp * a * a * geo, (1 - rsp) ** 2 * a * geo


# ----------------------------------------------------------------------------------------------
# lucent
# ----------------------------------------------------------------------------------------------
def read_csv(path):
    meta, rows = {}, []
    for line in open(path):
        line = line.strip()
        if line.startswith("#"):
            for tok in line[1:].split():
                if "=" in tok:
                    k, v = tok.split("=", 1)
                    meta[k] = v
        elif line and not line.startswith("r_mm"):
            rows.append([float(v) for v in line.split(",")])
    a = np.array(rows)
    vec = lambda k: np.array([float(v) for v in meta[k].split(",")])
    tot = {k: vec(k) for k in ("diffuse_reflectance", "diffuse_reflectance_se", "transmittance",
                               "transmittance_se", "absorbed", "absorbed_se", "specular_reflectance")}
    edges = np.concatenate([a[:, 7], a[-1:, 8]])
    return {"meta": meta, "tot": tot, "r": a[:, 0], "val": a[:, 1:4], "se": a[:, 4:7], "edges": edges}


def run_lucent(lucent, work, case, side, photons, seed=1):
    label, eta, g, sa, ss, d = case[:6]
    mat = os.path.join(work, f"case{label}.json")
    with open(mat, "w") as f:
        json.dump({"format": "lucent-material", "version": 1, "name": f"case{label}", "ior": eta,
                   "sigma_a": [sa] * 3, "sigma_s": [ss] * 3, "g": [g] * 3}, f)
    out = os.path.join(work, f"case{label}_{side}")
    csv = os.path.join(work, f"case{label}_{side}.csv")
    cmd = [lucent, "simulate", "--material", mat, "--thickness-mm", repr(d), "--photons", str(photons),
           "--seed", str(seed), "--profile-only", "--exitance-csv", csv, "-o", out, "--force", "-q"]
    if side == "transmitted":
        cmd += ["--side", "transmitted"]
    t0 = time.time()
    subprocess.run(cmd, check=True)
    wall = time.time() - t0
    return read_csv(csv), wall, cmd


def combine_channels(val, se):
    """Mean of the three channels and its SE; chi^2 of the channels about it (2 dof)."""
    m = val.mean(axis=-1)
    s = np.sqrt((se ** 2).sum(axis=-1)) / val.shape[-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        chi = (((val - m[..., None]) / np.where(se > 0, se, np.nan)) ** 2).sum(axis=-1)
    return m, s, chi


# ----------------------------------------------------------------------------------------------
# Comparison
# ----------------------------------------------------------------------------------------------
def compare_bins(r, lv, ls, mv, ms):
    with np.errstate(divide="ignore", invalid="ignore"):
        both = (lv > 5 * ls) & (mv > 5 * ms) & (ls > 0) & (ms > 0)
        cse = np.sqrt(ls ** 2 + ms ** 2)
        z = (lv - mv) / cse
        rel = (lv - mv) / mv
        relse = cse / mv
    i = np.nonzero(both)[0]
    out = {"n": int(i.size)}
    if i.size:
        out["frac2"] = float(np.mean(np.abs(z[i]) < 2))
        j = i[np.argmax(np.abs(z[i]))]
        out["worst_z"] = (float(z[j]), float(r[j]))
        out["chi2dof"] = float(np.mean(z[i] ** 2))
        p = i[relse[i] < 0.02]
        out["n_prec"] = int(p.size)
        if p.size:
            q = p[np.argmax(np.abs(rel[p]))]
            out["worst_rel"] = (float(rel[q]), float(r[q]), float(z[q]))
        out["rmax"] = float(r[i].max())
    return out


def bands(edges, lv, ls, mv, ms, cuts):
    """Integrated exitance (annulus-area weighted) in radius bands: lucent/mine ratio and z."""
    area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    rc = 0.5 * (edges[1:] + edges[:-1])
    res = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        sel = (rc >= a) & (rc < b)
        if not sel.any():
            continue
        L, M = (lv[sel] * area[sel]).sum(), (mv[sel] * area[sel]).sum()
        # bins of one photon set are (weakly, negatively) correlated; the quadrature sum is close
        sL = math.sqrt(((ls[sel] * area[sel]) ** 2).sum())
        sM = math.sqrt(((ms[sel] * area[sel]) ** 2).sum())
        if M <= 0 or L <= 0:
            continue
        res.append((a, b, L, M, (L - M) / math.hypot(sL, sM), L / M - 1))
    return res


def fmt_pm(m, s, digits=5):
    return f"{m:.{digits}f} ± {s:.{digits}f}"


def self_test(args):
    """Check the independent MC alone: van de Hulst's slab and energy conservation."""
    print("self test: eta 1, g 0.75, a 0.9, tau 2 (van de Hulst Rd 0.09739, T 0.66096)")
    e = np.array([0.0, 1e9])
    for implicit in (False, True):
        t0 = time.time()
        t = transport(200_000, 1.0, 9.0, 0.75, 1.0, 0.2, e, e, seed=7, implicit=implicit)
        tt = t.totals()
        T = tt["T_scat"][0] + tt["T_ball"][0]
        sT = math.hypot(tt["T_scat"][1], tt["T_ball"][1])
        tot = sum(tt[k][0] for k in ("R_diff", "R_ball", "T_scat", "T_ball", "A")) + tt["lost"][0]
        print(f"  {'implicit' if implicit else 'analog  '}: Rd {fmt_pm(*tt['R_diff'])} "
              f"(z {(tt['R_diff'][0]-0.09739)/tt['R_diff'][1]:+.2f}), T {fmt_pm(T, sT)} "
              f"(z {(T-0.66096)/sT:+.2f}), A {fmt_pm(*tt['A'])}, R+T+A+roulette {tot:.6f}, "
              f"{time.time()-t0:.1f} s")
    for c in CASES[1:]:
        label, eta, g, sa, ss, d = c[:6]
        t = transport(50_000, sa, ss, g, eta, d, e, e, seed=8)
        tt = t.totals()
        rsp = ((eta - 1) / (eta + 1)) ** 2
        tot = sum(tt[k][0] for k in ("R_diff", "R_ball", "T_scat", "T_ball", "A")) + rsp
        bt, bb = ballistic(sa, ss, eta, d)
        print(f"  case {label}: Rsp+R+T+A {tot:.6f}; ballistic top {fmt_pm(*tt['R_ball'])} (exact {bt:.5f}), "
              f"bottom {fmt_pm(*tt['T_ball'])} (exact {bb:.5f})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lucent", default=os.path.join(ROOT, "build", "ci", "cli", "lucent"))
    ap.add_argument("lucent_pos", nargs="?", help="the lucent binary (same as --lucent)")
    ap.add_argument("--scale", type=float, default=1.0, help="multiply every photon count")
    ap.add_argument("--cases", default="1,2,3,4,5,6")
    ap.add_argument("--implicit", action="store_true", help="implicit capture + roulette (default analog)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--self-test", action="store_true")
    ap.add_argument("--out", default=os.path.join(HERE, "slab_mc_check.md"))
    args = ap.parse_args()
    if args.lucent_pos:
        args.lucent = args.lucent_pos
    if args.self_test:
        self_test(args)
        return
    want = {int(c) for c in args.cases.split(",")}
    work = tempfile.mkdtemp(prefix="lucent-slabmc-")
    rows, details, cmds = [], [], []
    for case in CASES:
        label, eta, g, sa, ss, d, nmine, nluc = case
        if label not in want:
            continue
        nmine, nluc = int(nmine * args.scale), int(nluc * args.scale)
        Lr, wr, cr = run_lucent(args.lucent, work, case, "reflected", nluc)
        Lt, wt, ct = run_lucent(args.lucent, work, case, "transmitted", nluc)
        cmds += [" ".join(cr), " ".join(ct)]
        t0 = time.time()
        mine = transport(nmine, sa, ss, g, eta, d, Lr["edges"], Lt["edges"], seed=1000 + label,
                         implicit=args.implicit, workers=args.workers)
        wm = time.time() - t0
        tt = mine.totals()
        bt, bb = ballistic(sa, ss, eta, d)
        rsp = ((eta - 1) / (eta + 1)) ** 2
        # lucent totals, channel mean
        lt = {}
        for k in ("diffuse_reflectance", "transmittance", "absorbed"):
            m, s, chi = combine_channels(Lr["tot"][k], Lr["tot"][k + "_se"])
            lt[k] = (float(m), float(s), float(chi))
        my_T = (tt["T_scat"][0] + tt["T_ball"][0], math.hypot(tt["T_scat"][1], tt["T_ball"][1]))
        my_R = tt["R_diff"]
        my_Rall = (tt["R_diff"][0] + tt["R_ball"][0], math.hypot(tt["R_diff"][1], tt["R_ball"][1]))
        energy = rsp + my_Rall[0] + my_T[0] + tt["A"][0] + tt["lost"][0]
        case_rows = []
        for name, lk, mv in (("diffuse R", "diffuse_reflectance", my_R), ("T (all)", "transmittance", my_T),
                             ("A", "absorbed", tt["A"])):
            L = lt[lk]
            case_rows.append((name, L, mv, (L[0] - mv[0]) / math.hypot(L[1], mv[1])))
        if bt > 1e-4:  # where the unscattered top exit is not negligible, the other convention too
            L = lt["diffuse_reflectance"]
            case_rows.insert(1, ("diffuse R incl. unscattered top exit", L, my_Rall,
                                 (L[0] - my_Rall[0]) / math.hypot(L[1], my_Rall[1])))
        # bins
        binres = {}
        bandres = {}
        for side, Lc, key in (("R", Lr, "R"), ("T", Lt, "T")):
            lv, ls, lchi = combine_channels(Lc["val"], Lc["se"])
            mv, ms = mine.radial(key)
            binres[side] = compare_bins(Lc["r"], lv, ls, mv, ms)
            binres[side]["lucent_sum"] = float((lv * np.pi * np.diff(Lc["edges"] ** 2)).sum())
            binres[side]["mine_sum"] = float((mv * np.pi * np.diff(Lc["edges"] ** 2)).sum())
            ok = np.isfinite(lchi) & (Lc["val"].min(axis=1) > 5 * Lc["se"].max(axis=1))
            binres[side]["lucent_chan_chi2dof"] = float(lchi[ok].mean() / 2) if ok.any() else float("nan")
            bandres[side] = bands(Lc["edges"], lv, ls, mv, ms, [0, 0.05, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100.001])
        rows.append({"case": case, "tot": case_rows, "bins": binres, "bands": bandres,
                     "walls": (wr, wt, wm), "n": (nluc, nmine), "energy": energy,
                     "ball": (tt["R_ball"], tt["T_ball"], bt, bb), "mean_int": mine.interactions / mine.n,
                     "lucent_chi": {k: lt[k][2] / 2 for k in lt}})
        print(f"case {label} done: lucent {wr:.1f}+{wt:.1f} s, mine {wm:.1f} s", flush=True)
    write_md(args, rows, cmds)


def write_md(args, rows, cmds):
    L = []
    P = L.append
    P("# Slab Monte Carlo: lucent simulate against an independent implementation")
    P("")
    P("Made by `python3 notebooks_data/bench/slab_mc_check.py` " + (f"--scale {args.scale} " if args.scale != 1 else "")
      + ("--implicit " if args.implicit else "") + f"(cases {args.cases}). The independent Monte Carlo is in the "
      "script (vectorised numpy, written from the physics with MCML's conventions, not from lucent's source): "
      "pencil beam at normal incidence, specular part removed, exponential free paths, Henyey-Greenstein "
      "scattering, " + ("implicit capture with Russian roulette" if args.implicit else "analog absorption")
      + ", unpolarised Fresnel at both faces with a stochastic boundary (reflect with probability R, else the "
      "whole weight escapes), exitance binned in lucent's own annuli. lucent's three channels carry the same "
      "coefficients, so each lucent number is the mean of three independent estimates (its SE is the "
      "quadrature mean of the three reported SEs). z = (lucent - mine) / combined SE.")
    P("")
    P("## Cases, photon counts, wall times (2-core VM)")
    P("")
    P("| case | eta | g | sigma_a | sigma_s | d mm | lucent photons (per channel x 3) | lucent wall R + T s | mine photons | mine wall s | mine interactions / photon | mine Rsp+R+T+A |")
    P("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        label, eta, g, sa, ss, d = r["case"][:6]
        P(f"| {label} | {eta} | {g} | {sa} | {ss} | {d} | {r['n'][0]:,} x 3 | {r['walls'][0]:.1f} + {r['walls'][1]:.1f} | "
          f"{r['n'][1]:,} | {r['walls'][2]:.1f} | {r['mean_int']:.1f} | {r['energy']:.5f} |")
    P("")
    P("## Totals")
    P("")
    P("`T (all)` includes the unscattered beam (lucent's `transmittance` does, and its radial bins do not). "
      "lucent chan chi2/dof: spread of lucent's three channels about their mean in units of their own SEs "
      "(about 1 when lucent's SEs are right).")
    P("")
    P("| case | quantity | lucent | mine | z | lucent chan chi2/dof |")
    P("|---|---|---|---|---|---|")
    keymap = {"diffuse R": "diffuse_reflectance", "T (all)": "transmittance", "A": "absorbed",
              "diffuse R incl. unscattered top exit": "diffuse_reflectance"}
    for r in rows:
        for name, Lv, Mv, z in r["tot"]:
            P(f"| {r['case'][0]} | {name} | {fmt_pm(Lv[0], Lv[1])} | {fmt_pm(Mv[0], Mv[1])} | {z:+.2f} | "
              f"{r['lucent_chi'][keymap[name]]:.2f} |")
        Rb, Tb, bt, bb = r["ball"]
        P(f"| {r['case'][0]} | unscattered T (mine; exact {bb:.5f}) | - | {fmt_pm(*Tb)} | - | - |")
        if bt > 0:
            P(f"| {r['case'][0]} | unscattered out of the top (mine; exact {bt:.5f}; not in my diffuse R nor in either R bins) | - | {fmt_pm(*Rb)} | - | - |")
    P("")
    chis = {k: [r["lucent_chi"][k] for r in rows] for k in rows[0]["lucent_chi"]} if rows else {}
    P("lucent's reported SEs against the spread of its three channels, all cases together (2 dof a case): "
      + ", ".join(f"{k} chi2/dof {np.mean(v):.2f} ({2 * len(v)} dof)" for k, v in chis.items()) + ".")
    P("")
    P("## Radial bins")
    P("")
    P("Bins where both have signal > 5 SE. `within 2 SE`: fraction with |z| < 2 (0.95 expected). "
      "`worst rel`: largest |lucent/mine - 1| among those bins with combined relative SE < 2% (its radius, z). "
      "`sum`: the bins' integral (lucent / mine).")
    P("")
    P("| case | side | bins | within 2 SE | mean z^2 | worst z (r mm) | bins < 2% SE | worst rel (r mm, z) | sum lucent / mine | lucent chan chi2/dof |")
    P("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        for side in ("R", "T"):
            b = r["bins"][side]
            if not b["n"]:
                P(f"| {r['case'][0]} | {side} | 0 | | | | | | | |")
                continue
            wr = b.get("worst_rel")
            wrs = f"{wr[0]*100:+.2f}% ({wr[1]:.3g}, {wr[2]:+.1f})" if wr else "-"
            P(f"| {r['case'][0]} | {side} | {b['n']} | {b['frac2']:.3f} | {b['chi2dof']:.2f} | "
              f"{b['worst_z'][0]:+.2f} ({b['worst_z'][1]:.3g}) | {b['n_prec']} | {wrs} | "
              f"{b['lucent_sum']:.5f} / {b['mine_sum']:.5f} | {b['lucent_chan_chi2dof']:.2f} |")
    P("")
    P("## Radial bands (integrated exitance in a band of radii, lucent / mine - 1, z)")
    P("")
    P("A systematic difference too small for single bins shows here.")
    P("")
    P("| case | side | " + " | ".join(["band mm: rel (z)"] * 1) + " |")
    P("|---|---|---|")
    for r in rows:
        for side in ("R", "T"):
            cells = [f"{a:g}-{b:g}: {rel*100:+.2f}% ({z:+.1f})" for a, b, Lb, Mb, z, rel in r["bands"][side]]
            P(f"| {r['case'][0]} | {side} | " + "; ".join(cells) + " |")
    P("")
    P("## Command lines")
    P("")
    P("```")
    for c in cmds:
        P(c)
    P("```")
    P("")
    P("<!-- conclusion -->")
    text = "\n".join(L) + "\n"
    # keep a hand-written conclusion from an earlier run
    if os.path.exists(args.out):
        old = open(args.out).read()
        if "<!-- conclusion -->" in old:
            text = text.replace("<!-- conclusion -->\n", "<!-- conclusion -->" + old.split("<!-- conclusion -->", 1)[1])
    with open(args.out, "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
