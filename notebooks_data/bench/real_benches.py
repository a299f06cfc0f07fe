#!/usr/bin/env python3
"""Real benches, measured: simulate -> acquire -> fit on benches with a finite beam, lens blur and
veiling glare (the white reference through the same lens), and an oblique capture with a beam.
Prints a markdown table of the worst relative error and |z| against the truth per case.

    python3 notebooks_data/bench/real_benches.py build/ci/cli/lucent /tmp/rb > real_benches.md
"""
import json, os, subprocess, sys, time

lucent, work = sys.argv[1], sys.argv[2]
root = os.path.dirname(os.path.abspath(__file__))
library = os.path.join(root, "..", "..", "materials", "library")
cases = [
    ("skin1, 0.5 mm beam, 0.1 mm pixels", "skin1", "--beam-sigma-mm 0.5 --size 256 --pixel-mm 0.1", ""),
    ("marble, 0.5 mm beam, 2% glare, default field", "marble", "--beam-sigma-mm 0.5 --glare 0.02", ""),
    ("skin1, 0.5 mm beam, 3% glare", "skin1", "--beam-sigma-mm 0.5 --glare 0.03 --size 256 --pixel-mm 0.1", ""),
    ("skin1, 1 mm beam, 0.1 mm blur, 5% glare", "skin1",
     "--beam-sigma-mm 1 --lens-blur-mm 0.1 --glare 0.05 --size 256 --pixel-mm 0.1", ""),
    ("potato, 0.5 mm beam, 0.2 mm blur, default field", "potato", "--beam-sigma-mm 0.5 --lens-blur-mm 0.2", ""),
    ("skin1 at 45 deg (2D), 0.5 mm beam, 0.1 mm blur, 96 px of 0.25 mm", "skin1",
     "--beam-sigma-mm 0.5 --lens-blur-mm 0.1 --incidence-deg 45 --size 96 --pixel-mm 0.25", ""),
]
print("| bench (simulated, 1e6 photons, white reference through the same lens) | fit | worst error | worst abs z | fit time |")
print("| --- | --- | --- | --- | --- |")
for k, (name, material, sim, fit) in enumerate(cases):
    d = os.path.join(work, f"case{k}")
    subprocess.run(f"rm -rf {d} && mkdir -p {d}", shell=True)
    subprocess.run(f"{lucent} simulate --material {material} -o {d}/sim --photons 1000000 --seed 11 -q {sim}",
                   shell=True, check=True)
    subprocess.run(f"{lucent} acquire {d}/sim/capture.json -q -o {d}/acq", shell=True, check=True,
                   stdout=subprocess.DEVNULL)
    t0 = time.time()
    r = subprocess.run(f"{lucent} fit {d}/acq/profile.json -q -o {d}/m.json {fit}", shell=True,
                       capture_output=True, text=True)
    dt = time.time() - t0
    if r.returncode != 0:
        print(f"| {name} | refused: {r.stderr.strip()[:160]} | | | {dt:.1f} s |")
        continue
    truth = json.load(open(os.path.join(library, material + ".json")))
    m = json.load(open(f"{d}/m.json"))
    err = max(abs(m[k][c] / truth[k][c] - 1) for k in ("sigma_a", "sigma_s_reduced") for c in range(3))
    z = max(abs(m[k][c] - truth[k][c]) / m["uncertainty"][k][c]
            for k in ("sigma_a", "sigma_s_reduced") for c in range(3))
    warn = " (warned)" if "warning" in r.stderr else ""
    print(f"| {name} | converged{warn} | {100 * err:.1f}% | {z:.2f} | {dt:.1f} s |", flush=True)
