"""`cmake --install` puts a working lucent package under the prefix."""
import os
import subprocess
import sys

import pytest

BUILD = os.environ.get("LUCENT_BUILD_DIR")


@pytest.mark.skipif(not BUILD, reason="LUCENT_BUILD_DIR not set (ctest sets it)")
def test_the_installed_package_imports_and_works(tmp_path):
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    site = tmp_path / "lib" / "python3" / "dist-packages"
    assert (site / "lucent" / "__init__.py").exists()
    env = dict(os.environ, PYTHONPATH=str(site))
    out = subprocess.run(
        [sys.executable, "-c",
         "import lucent; print(lucent.__file__); print(lucent.library()[0]);"
         "print(lucent.profile(lucent.Material.load('marble'), [1.0])[0, 0])"],
        check=True, capture_output=True, text=True, env=env, cwd=tmp_path).stdout.split()
    assert out[0].startswith(str(site))
    assert out[1] == "apple" and float(out[2]) > 0
