#!/usr/bin/env python3
"""render_accuracy.csv, render_convergence.csv and render_defaults.csv (from render_accuracy.sh)
-> render_accuracy.md:
per setting, mesh, material and model, the radiance maps' error against the converged CPU
reference after the last frame, and the first snapshot frame within 2% (relative RMSE) of the
last frame's image."""
import csv
import os

here = os.path.dirname(os.path.abspath(__file__))
settings = {
    "light": "K 8, W_s = W_l 256, N 32, M 256, 64 frames (targets: RMSE 8%, channel means "
             "within 3%; ketchup 10%)",
    "default": "the defaults K 16, W_s = W_l 512, N 50, M 1000, run to 32 frames of 100 "
               "(targets: RMSE 5%, channel means within 2%; frames to 2% <= 16)",
}
out = ["# The radiance maps against a converged CPU reference", "",
       "Made by `notebooks_data/bench/render_accuracy.sh` (then `render_accuracy.py`): 64 px, a "
       "directional (1,0.5,0.5) and a point light (-60,60,80), 100 mm objects, subsurface term "
       "only (`--specular off`: the lobe is the same in both). Reference: probes, 8192 per pixel "
       "(its own noise ~0.3% relative RMSE on the sphere, ~0.8% on dragon:4). Machine: this "
       "project's 2-core VM, Mesa llvmpipe (no GPU). RMSE = relative RMSE over the object's "
       "pixels; means = the channels' mean ratios to the reference; frames to 2% = the first "
       "snapshot (1, 2, 4, 8, ...) within 2% relative RMSE of the last frame's image; seconds = "
       "the whole render on llvmpipe.", ""]
for name, title in (("accuracy", "Every model and material (accuracy)"),
                    ("convergence", "Frames to converge (no mip blur: the profile disc's default)"),
                    ("defaults", "The rest of the default settings (dragon:4 by model and material, more sphere cases)")):
    path = os.path.join(here, f"render_{name}.csv")
    if not os.path.exists(path):
        continue
    cases = {}
    for r in csv.DictReader(open(path)):
        cases.setdefault((r["setting"], r["mesh"], r["material"], r["model"]), []).append(r)
    out += [f"## {title}", ""]
    for setting, text in settings.items():
        keys = [k for k in cases if k[0] == setting]
        if not keys:
            continue
        out += [f"### {setting}: {text}", "",
                "| mesh | material | model | RMSE | means R, G, B | frames to 2% | seconds |",
                "| --- | --- | --- | --- | --- | --- | --- |"]
        for key in keys:
            snaps = sorted(cases[key], key=lambda r: int(r["frames"]))
            last = snaps[-1]
            within = [int(r["frames"]) for r in snaps if float(r["rmse_vs_final"]) <= 0.02]
            means = ", ".join(f"{float(last[c]):.3f}"
                              for c in ("mean_ratio_r", "mean_ratio_g", "mean_ratio_b"))
            out.append(f"| {key[1]} | {key[2]} | {key[3]} | {float(last['relative_rmse']):.4f} | "
                       f"{means} | {within[0] if within else '-'} | {last['seconds']} |")
        out.append("")
open(os.path.join(here, "render_accuracy.md"), "w").write("\n".join(out) + "\n")
print("\n".join(out))
