"""The Python module's calling overhead (issue 38): lucent.profile on 10^6 radii against the same
evaluations in C++ (bench_models' BM_RadialProfile), each the fastest of 5 runs, the Python block
run before and after the C++ one and the faster kept (this VM's speed wanders by 1.5x from minute
to minute; a turn-by-turn comparison, one Python call after each benchmark process, gave 1.5x
here while back-to-back blocks give 1.0x, with the same shares of the same functions in perf:
the figure is a VM's, take it with that), and lucent.fit of the bundled
capture's profile against `lucent fit` on the same profile.json (the CLI's wall time includes its
process start). Writes python_overhead.csv.

Usage (from the repository root, a built tree):
  PYTHONPATH=build/ci/python /usr/bin/python3 notebooks_data/bench/python_overhead.py build/ci \
      > notebooks_data/bench/python_overhead.csv
"""
import csv
import io
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import lucent

build = sys.argv[1] if len(sys.argv) > 1 else "build/ci"
REPEATS = 5


def median_time(call):
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def cpp_times():
    out = subprocess.run([os.path.join(build, "tests/benchmarks/bench_models"),
                          "--benchmark_filter=RadialProfile", "--benchmark_repetitions=5",
                          "--benchmark_format=csv"], check=True, capture_output=True,
                         text=True).stdout
    best = {}
    for row in csv.DictReader(io.StringIO(out[out.index("name,"):])):
        if row["name"].endswith(("_mean", "_median", "_stddev", "_cv")):
            continue
        t = float(row["real_time"]) / 1000  # ms -> s
        best[row["label"]] = min(best.get(row["label"], float("inf")), t)
    return best


def python_times():
    best = {}
    for model in ("dipole", "tabulated"):
        for _ in range(5):
            start = time.perf_counter()
            lucent.profile(marble, radii, model=model)
            best[model] = min(best.get(model, float("inf")), time.perf_counter() - start)
    return best


rows = []
marble = lucent.Material.load("marble")
radii = 0.01 * 5000.0 ** (np.arange(1_000_000) / 999_999)
before = python_times()
cpp = cpp_times()
after = python_times()
for model in cpp:
    py = min(before[model], after[model])
    rows.append(("profile 1e6 radii (fastest of 5)", model, py, cpp[model], py / cpp[model],
                 "bench_models BM_RadialProfile"))

source = os.environ.get("LUCENT_SOURCE_DIR", ".")
capture = os.path.join(source, "notebooks_data/captures/marble_0deg/capture.json")
with tempfile.TemporaryDirectory() as tmp:
    subprocess.run([os.path.join(build, "cli/lucent"), "acquire", capture, "-o",
                    os.path.join(tmp, "acq"), "-q"], check=True, capture_output=True)
    profile_json = os.path.join(tmp, "acq", "profile.json")
    profile = lucent.Profile.load(profile_json)
    py = median_time(lambda: lucent.fit([profile]))
    cli = median_time(lambda: subprocess.run(
        [os.path.join(build, "cli/lucent"), "fit", profile_json, "-o",
         os.path.join(tmp, "m.json"), "-q"], check=True, capture_output=True))
    rows.append(("radial fit, marble_0deg (medians of 5)", "auto (tabulated)", py, cli, py / cli,
                 "lucent fit, whole command"))

writer = csv.writer(sys.stdout)
writer.writerow(["case", "model", "python_s", "cpp_s", "ratio", "cpp_measured_by"])
for case, model, py, c, ratio, how in rows:
    writer.writerow([case, model, f"{py:.4f}", f"{c:.4f}", f"{ratio:.3f}", how])
