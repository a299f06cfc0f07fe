"""lucent's Python module against the CLI and against itself: models, materials, errors.

Run by ctest (tests/python/CMakeLists.txt) with PYTHONPATH at the build tree's module and
LUCENT_BINARY the CLI built beside it.
"""
import csv
import io
import json
import os
import subprocess

import numpy as np
import pytest

import lucent

LUCENT = os.environ.get("LUCENT_BINARY", "lucent")


def cli(*args):
    return subprocess.run([LUCENT, *args], check=True, capture_output=True, text=True).stdout


def cli_profile(material, radii, model, quantity="exitance"):
    text = cli("profile", "--material", material, "--r", ",".join(repr(r) for r in radii),
               "--model", model, "--quantity", quantity, "--total")
    lines = text.splitlines()
    total = [float(v) for v in lines[1].split("=")[1].split(",")]
    rows = list(csv.DictReader(io.StringIO("\n".join(lines[2:]))))
    values = np.array([[float(r["R_r"]), float(r["R_g"]), float(r["R_b"])] for r in rows])
    return values, total


@pytest.mark.parametrize("material", ["marble", "skin1", "ketchup"])
@pytest.mark.parametrize("model", ["dipole", "ddipole", "tabulated"])
def test_profile_and_total_are_the_clis_numbers(material, model):
    radii = [0.05, 0.3, 1.0, 2.5, 7.0, 20.0]
    m = lucent.Material.load(material)
    for quantity in ("exitance", "radiance"):
        expected, total = cli_profile(material, radii, model, quantity)
        got = lucent.profile(m, np.array(radii), model=model, quantity=quantity)
        assert got.shape == (len(radii), 3)
        # The CLI writes 17 significant digits: the same doubles.
        np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(lucent.total_reflectance(m, model), total)


def test_profile_keeps_the_shape_of_its_radii():
    m = lucent.Material.load("potato")
    r = np.linspace(0.1, 5, 12).reshape(3, 4)
    got = lucent.profile(m, r)
    assert got.shape == (3, 4, 3)
    np.testing.assert_array_equal(got.reshape(12, 3), lucent.profile(m, r.ravel()))


def test_bssrdf_over_configurations_is_the_clis(tmp_path):
    rng = np.random.default_rng(4)
    rows = []
    for _ in range(5):
        w = rng.normal(size=3)
        w[2] = abs(w[2]) + 0.3
        w /= np.linalg.norm(w)
        rows.append([0, 0, 0, 0, 0, 1, *w, *rng.uniform(-3, 3, 2), 0, 0, 0, 1])
    configs = np.array(rows, dtype=float)
    path = tmp_path / "configs.csv"
    header = ("xi_x,xi_y,xi_z,ni_x,ni_y,ni_z,wi_x,wi_y,wi_z,xo_x,xo_y,xo_z,no_x,no_y,no_z")
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows))
    out = cli("profile", "--material", "skin1", "--model", "ddipole", "--configs", str(path))
    table = list(csv.DictReader(io.StringIO(out)))
    expected = np.array([[float(t["Sd_r"]), float(t["Sd_g"]), float(t["Sd_b"])] for t in table])
    got = lucent.bssrdf(lucent.Material.load("skin1"), configs, model="ddipole")
    np.testing.assert_array_equal(got, expected)


def test_material_round_trips_through_its_file(tmp_path):
    m = lucent.Material("wax", 1.45, [0.01, 0.02, 0.04], [1.1, 1.3, 1.6])
    path = tmp_path / "wax.json"
    m.save(path)
    back = lucent.Material.load(str(path))
    assert back.name == "wax" and back.ior == 1.45
    assert back.sigma_a == [0.01, 0.02, 0.04]
    assert back.sigma_s_reduced == [1.1, 1.3, 1.6]
    assert json.loads(path.read_text())["format"] == "lucent-material"
    assert back.to_json()["sigma_a"] == [0.01, 0.02, 0.04]


def test_bad_input_raises_the_one_line_error():
    with pytest.raises(lucent.Error, match="sigma_a"):
        lucent.Material("bad", 1.3, [0.01, -1, 0.02], [1, 1, 1])
    with pytest.raises(lucent.Error, match="sigma_a: expected three numbers"):
        lucent.Material("bad", 1.3, [0.01, 0.02], [1, 1, 1])
    with pytest.raises(lucent.Error, match="unknown material 'nosuch'"):
        lucent.Material.load("nosuch")
    m = lucent.Material.load("marble")
    with pytest.raises(ValueError, match="model: expected"):
        lucent.profile(m, [1.0], model="foo")
    with pytest.raises(lucent.Error, match="r_mm: expected finite radii"):
        lucent.profile(m, [1.0, float("nan")])
    with pytest.raises(lucent.Error, match="quantity"):
        lucent.profile(m, [1.0], quantity="flux")


def test_fresnel_and_the_albedo_inversion():
    cos_i = np.array([1.0, 0.5, 0.1])
    r = lucent.fresnel_reflectance(cos_i, 1.5)
    assert r[0] == pytest.approx(0.04, abs=1e-12)  # ((1.5 - 1) / (1.5 + 1))^2
    assert np.all(np.diff(r) > 0)
    # alpha' from the standard dipole's total reflectance inverts the total of a material.
    m = lucent.Material("x", 1.3, [0.02, 0.05, 0.2], [1.0, 1.0, 1.0])
    total = np.array(lucent.total_reflectance(m, "dipole"))
    alpha = lucent.reduced_albedo_from_total_reflectance(total, 1.3)
    np.testing.assert_allclose(alpha, 1 / np.array([1.02, 1.05, 1.2]), rtol=1e-10)
    sigma_a, sigma_s = lucent.coefficients_from_diffuse_colour(0.5, 2.0, 1.3)
    assert sigma_a > 0 and sigma_s > sigma_a
