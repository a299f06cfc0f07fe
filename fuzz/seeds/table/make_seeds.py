#!/usr/bin/env python3
"""Small, valid transport tables as the table fuzzer's seeds (the shipped tables are too large for
libFuzzer's inputs). Written from the format's description in materials/src/transport_table.cpp's
writer: one JSON header line, then the payload. Run from this folder: python3 make_seeds.py"""
import json, struct, zlib

def table(name, kind="table", phi_bins=1, slices=1, slab=None, partial_groups=None):
    u = [0.0, 0.5, 0.9]
    grid = {"u": u, "rho_min": 0.1, "rho_max": 10.0, "rho_per_decade": 2, "phi_bins": phi_bins}
    rho_bins = 4  # round(log10(100) * 2)
    n = len(u) * phi_bins * rho_bins
    payload = b""
    if kind == "table":
        for s in range(slices):
            for q in range(2):
                payload += struct.pack("<%df" % n, *[0.5 / (1 + i) for i in range(n)])
                payload += bytes([200 - (i % 40) for i in range(n)])
            payload += struct.pack("<3d", 0.0, 0.3, 0.6) + struct.pack("<3d", 0.0, 1e-3, 1e-3)
    else:
        for _ in partial_groups:
            for q in range(2):
                payload += struct.pack("<%dd" % n, *[0.25 / (1 + i) for i in range(n)])
            payload += struct.pack("<3d", 0.0, 0.3, 0.6)
    h = {"format": "lucent-transport-table", "version": 1, "kind": kind, "grid": grid,
         "slices": [{"eta": 1.0 + 0.3 * s, "g": 0.0, "photons": 1000, "incidence_deg": 0.0}
                    for s in range(slices)],
         "groups": 2, "seed": 1, "max_path": 1000.0, "generator": "fuzz seed",
         "payload_bytes": len(payload), "crc32": zlib.crc32(payload)}
    if slab:
        h["slab"] = {"thickness_s": slab[0], "side": slab[1]}
    if partial_groups is not None:
        h["shard"] = "1/2"
        h["partial_groups"] = partial_groups
    with open(name, "wb") as f:
        f.write(json.dumps(h).encode() + b"\n" + payload)

table("small.lut")
table("two_slices_phi.lut", phi_bins=3, slices=2)
table("slab_transmitted.lut", slab=(2.0, "transmitted"))
table("partial.lut", kind="partial", partial_groups=[[0, 0], [0, 1]])
