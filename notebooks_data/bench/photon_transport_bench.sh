#!/bin/bash
# The capture simulator's speed per core against MCML's (photon_transport.csv): lucent's
# bench_photon_transport (Google Benchmark, medians of 5), the three media of its comment, one and
# two threads, with and without the camera image, beside MCML 1.2 (Wang, Jacques and Zheng; the C
# code of github:bipy/MCML, gcc 12 -O3, a static buffer in FindDataLine its one fix) timed on the same
# machine and the same media (semi-infinite: one 1000 cm layer; pencil beam, normal incidence; a
# 10 x 10 grid), its photons per CPU-second given in `mcml` below (best of 2 idle runs, 2026-12-08,
# the 2-core AMD EPYC VM; MCML is not part of lucent). MCML computes no camera image: the ratio is
# given for the rows without one. Usage:
#   photon_transport_bench.sh [BUILD_DIR] > notebooks_data/bench/photon_transport.csv  (~1 min)
set -euo pipefail
B=${1:-build/ci}
"$B/tests/benchmarks/bench_photon_transport" --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_format=csv 2>/dev/null |
  python3 -c '
import csv, re, sys
mcml = {"marble": 29481, "potato": 76313, "soymilk": 50676}
print("medium,threads,image,photons_per_s,interactions_per_photon,interactions_per_s,"
      "mcml_photons_per_s,ratio_to_mcml_per_core")
for row in csv.DictReader(sys.stdin):
    if not row["name"].endswith("_median"):
        continue
    threads = int(re.search(r"threads:(\d+)", row["name"]).group(1))
    image = int(re.search(r"image:(\d)", row["name"]).group(1))
    medium = row["label"].split(",")[0]
    ref = mcml[medium.split()[0]]
    photons = float(row["items_per_second"])
    # Two threads: photons per second of wall time on both cores; per core is half.
    ratio = f"{photons / threads / ref:.2f}" if image == 0 else ""
    per_photon = float(row["interactions_per_photon"])
    per_second = float(row["interactions_per_second"])
    print(f"{medium},{threads},{image},{photons:.0f},{per_photon:.1f},{per_second:.4g},{ref},{ratio}")
'
