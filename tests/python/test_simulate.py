"""lucent.simulate and lucent.export_material against `lucent simulate` and `lucent export`."""
import csv
import io
import json
import os
import subprocess

import numpy as np
import pytest

import lucent

LUCENT = os.environ.get("LUCENT_BINARY", "lucent")


def test_transport_arrays_are_the_clis_exitance_table(tmp_path):
    csv_path = tmp_path / "r.csv"
    subprocess.run([LUCENT, "simulate", "--material", "potato", "-o", str(tmp_path / "sim"),
                    "--photons", "20000", "--seed", "5", "--profile-only", "--exitance-csv",
                    str(csv_path), "-q"], check=True)
    text = csv_path.read_text().splitlines()
    meta = dict(line[2:].split("=", 1) for line in text if line.startswith("# ") and "=" in line
                and " " not in line[2:].split("=", 1)[0])
    rows = list(csv.DictReader(io.StringIO("\n".join(l for l in text if not l.startswith("#")))))
    s = lucent.simulate(lucent.Material.load("potato"), photons=20000, seed=5, threads=1,
                        image=False)
    expected = np.array([[float(r[k]) for k in ("R_r", "R_g", "R_b")] for r in rows])
    np.testing.assert_array_equal(s["exitance"], expected)
    np.testing.assert_array_equal(s["r_outer_mm"], [float(r["r_outer_mm"]) for r in rows])
    np.testing.assert_array_equal(
        s["diffuse_reflectance"], [float(v) for v in meta["diffuse_reflectance"].split(",")])
    # Energy: diffuse + specular + transmitted + absorbed = 1 per photon.
    total = (s["diffuse_reflectance"] + s["specular_reflectance"] + s["transmittance"]
             + s["absorbed"])
    np.testing.assert_allclose(total, 1, atol=1e-12)


def test_a_capture_folder_acquires_and_fits(tmp_path):
    out = tmp_path / "capture"
    s = lucent.simulate(lucent.Material.load("skin1"), out, photons=20000, size=64, pixel_mm=0.1)
    assert (out / "capture.json").exists() and "capture.json" in s["files"]
    assert s["image"].shape == (64, 64, 3) and np.all(s["image"] >= 0)
    profile = lucent.acquire(str(out / "capture.json"))
    assert profile.value.shape[1] == 3 and profile.eta == pytest.approx(1.3)


def test_bad_simulation_options_raise_the_one_line_error():
    m = lucent.Material.load("marble")
    with pytest.raises(lucent.Error, match="side"):
        lucent.simulate(m, photons=100, side="top")
    with pytest.raises(lucent.Error, match="thickness_mm"):
        lucent.simulate(m, photons=100, side="transmitted")


@pytest.mark.parametrize("target,suffix", [("pbrt", ".pbrt"), ("mitsuba", ".xml"),
                                           ("materialx", ".mtlx")])
def test_export_writes_the_clis_file(tmp_path, target, suffix):
    path = tmp_path / ("skin1" + suffix)
    subprocess.run([LUCENT, "export", "--material", "skin1", "--to", target, "-o", str(path),
                    "--scene-unit", "cm", "-q"], check=True)
    e = lucent.export_material(lucent.Material.load("skin1"), target, scene_unit="cm")
    assert e["text"] == path.read_text()
    assert e["extension"] == suffix
    with pytest.raises(lucent.Error, match="--to"):
        lucent.export_material(lucent.Material.load("skin1"), "blender")
