"""lucent.acquire and lucent.fit against `lucent acquire` and `lucent fit` on the bundled captures,
and fits of profiles made from arrays.
"""
import json
import os
import subprocess
import threading
import time

import numpy as np
import pytest

import lucent

LUCENT = os.environ.get("LUCENT_BINARY", "lucent")
SOURCE = os.environ.get("LUCENT_SOURCE_DIR", ".")


def capture(name):
    return os.path.join(SOURCE, "notebooks_data", "captures", name, "capture.json")


def without_paths(material, paths):
    """The material file with the inputs' paths and the solve's time taken out of provenance."""
    text = json.dumps(material)
    for p in paths:
        text = text.replace(p, "INPUT")
    doc = json.loads(text)
    doc["provenance"]["fit"].pop("time_ms", None)
    return doc


@pytest.mark.parametrize("name", ["marble_0deg", "marble_45deg"])
def test_acquire_and_fit_give_the_clis_material(name, tmp_path):
    out = tmp_path / "acq"
    subprocess.run([LUCENT, "acquire", capture(name), "-o", str(out), "-q"], check=True)
    subprocess.run([LUCENT, "fit", str(out / "profile.json"), "-o", str(tmp_path / "cli.json"),
                    "--name", name, "-q"], check=True, capture_output=True)
    profile = lucent.acquire(capture(name))
    assert profile.source == capture(name)
    result = lucent.fit([profile], name=name)
    result.material.save(tmp_path / "py.json")
    cli_doc = json.loads((tmp_path / "cli.json").read_text())
    py_doc = json.loads((tmp_path / "py.json").read_text())
    assert without_paths(py_doc, [capture(name)]) == without_paths(cli_doc, [str(out / "profile.json")])
    # The numbers the result carries are the material's.
    assert list(result.sigma_a) == cli_doc["sigma_a"]
    assert list(result.sigma_s_reduced) == cli_doc["sigma_s_reduced"]
    sd = np.sqrt(np.array(result.sd_stat_sigma_a) ** 2 + np.array(result.sd_sys_sigma_a) ** 2)
    np.testing.assert_allclose(result.sd_sigma_a, sd, rtol=1e-12)
    assert result.converged
    assert result.report["chosen"]["model"] == result.model


def test_a_profile_from_arrays_fits_back_to_its_material():
    truth = lucent.Material("truth", 1.3, [0.01, 0.03, 0.08], [1.2, 1.0, 0.8])
    r = np.linspace(0.5, 20, 60)
    value = lucent.profile(truth, r, model="dipole", quantity="exitance")
    profile = lucent.Profile(r, value, 0.01 * value, ior=1.3, quantity="exitance")
    result = lucent.fit([profile], model="dipole", exclude_radius_mm=0)
    np.testing.assert_allclose(result.sigma_a, truth.sigma_a, rtol=1e-5)
    np.testing.assert_allclose(result.sigma_s_reduced, truth.sigma_s_reduced, rtol=1e-5)
    assert result.model == "dipole" and result.material.model == "dipole"
    # One column for all three channels is the same profile.
    single = lucent.Profile(r, value[:, 0], 0.01 * value[:, 0], ior=1.3, quantity="exitance")
    np.testing.assert_array_equal(single.value[:, 2], value[:, 0])


def test_bad_profiles_and_options_raise_the_one_line_error():
    r = np.linspace(0.5, 5, 10)
    with pytest.raises(lucent.Error, match="r_mm: expected finite, increasing radii"):
        lucent.Profile(r[::-1], np.ones(10))
    with pytest.raises(lucent.Error, match="standard_error: row 3"):
        se = np.full(10, 0.1)
        se[3] = 0
        lucent.Profile(r, np.ones(10), se)
    with pytest.raises(lucent.Error, match=r"value: expected 10 values"):
        lucent.Profile(r, np.ones(9))
    good = lucent.Profile(r, np.exp(-r), ior=1.3, quantity="exitance")
    assert "5%" in good.notes[0]
    with pytest.raises(lucent.Error, match="ior: required with arrays"):
        lucent.fit([lucent.Profile(r, np.exp(-r), quantity="exitance")])
    with pytest.raises(lucent.Error, match="quality: expected fast, balanced or accurate"):
        lucent.fit([good], quality="best")
    with pytest.raises(lucent.Error, match="profiles: expected at least one"):
        lucent.fit([])
    with pytest.raises(lucent.Error, match="capture.json"):
        lucent.acquire(os.path.join(SOURCE, "no", "capture.json"))


def test_progress_is_told_each_stage_in_order():
    stages = []
    lucent.fit([lucent.acquire(capture("marble_0deg"))],
               progress=lambda stage, done: stages.append((stage, done)))
    assert len(stages) >= 3
    done = [d for _, d in stages]
    assert done == sorted(done) and 0 <= done[0] and done[-1] <= 1


def test_the_fit_lets_other_python_threads_run():
    profile = lucent.acquire(capture("marble_45deg"))
    finished = threading.Event()
    result = {}

    def work():
        result["fit"] = lucent.fit([profile])
        finished.set()

    thread = threading.Thread(target=work)
    count = 0
    start = time.monotonic()
    thread.start()
    while not finished.is_set():
        count += 1
    thread.join()
    elapsed = time.monotonic() - start
    # With the GIL held the whole fit (seconds), this loop would have stood still; it runs at
    # millions a second with the GIL free.
    assert elapsed > 0.2
    assert count > 10000 * elapsed
    assert result["fit"].converged
