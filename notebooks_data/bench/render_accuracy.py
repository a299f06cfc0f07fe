#!/usr/bin/env python3
"""render_accuracy.csv (from render_accuracy.sh) -> render_accuracy.md: per setting, mesh, material
and model, the radiance maps' error against the converged CPU reference after the last frame, and
the first snapshot frame within 2% (relative RMSE) of the converged maps image."""
import csv
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
rows = list(csv.DictReader(open(os.path.join(here, "render_accuracy.csv"))))
cases = {}
for r in rows:
    key = (r["setting"], r["mesh"], r["material"], r["model"])
    cases.setdefault(key, []).append(r)

settings = {
    "light": "K 8, W_s = W_l 256, N 32, M 256, 64 frames (targets: RMSE 8%, channel means 3%; "
             "ketchup 10%)",
    "default": "the defaults K 16, W 512, N 50, M 1000, run to 32 frames (targets: RMSE 5%, "
               "channel means 2%)",
}
out = ["# The radiance maps against a converged CPU reference", "",
       "Made by `notebooks_data/bench/render_accuracy.sh` (then this script): 64 px, a directional "
       "(1,0.5,0.5) and a point light (-60,60,80), 100 mm objects, subsurface term only "
       "(`--specular off`, the lobe is the same in both). Reference: probes, 8192 per pixel "
       "(its own noise ~0.3% relative RMSE on the sphere, ~0.8% on dragon:4). Machine: the "
       "2-core llvmpipe VM (no GPU). RMSE = relative RMSE over the object's pixels; means = the "
       "channels' mean ratios to the reference; frames to 2% = first snapshot (1, 2, 4, 8, ...) "
       "within 2% relative RMSE of the last frame's image.", ""]
for setting, text in settings.items():
    keys = [k for k in cases if k[0] == setting]
    if not keys:
        continue
    out += [f"## {setting}: {text}", "",
            "| mesh | material | model | RMSE | means R, G, B | frames to 2% | seconds |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    for key in keys:
        snaps = sorted(cases[key], key=lambda r: int(r["frames"]))
        last = snaps[-1]
        within = [int(r["frames"]) for r in snaps if float(r["rmse_vs_final"]) <= 0.02]
        means = ", ".join(f"{float(last[c]):.3f}" for c in ("mean_ratio_r", "mean_ratio_g",
                                                            "mean_ratio_b"))
        out.append(f"| {key[1]} | {key[2]} | {key[3]} | {float(last['relative_rmse']):.4f} | "
                   f"{means} | {within[0] if within else '-'} | {last['seconds']} |")
    out.append("")
open(os.path.join(here, "render_accuracy.md"), "w").write("\n".join(out) + "\n")
print("\n".join(out))
