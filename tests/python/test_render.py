"""lucent.render against `lucent render`: the same flags, the same image."""
import os
import subprocess

import numpy as np
import pytest

import lucent

LUCENT = os.environ.get("LUCENT_BINARY", "lucent")


def cli_render(path, *flags):
    subprocess.run([LUCENT, "render", *flags, "-o", str(path), "--budget", "none"], check=True,
                   capture_output=True)
    return lucent.read_image(str(path))


@pytest.mark.parametrize("technique,extra", [
    ("reference", ["--reference-samples-pixel", "8"]),
    ("maps", ["--maps-directions", "4", "--maps-frames", "2", "--maps-radiance-map", "32",
              "--maps-light-map", "64", "--maps-samples", "8"]),
])
def test_render_gives_the_clis_image(tmp_path, technique, extra):
    flags = ["--material", "potato", "--mesh", "sphere", "--technique", technique,
             "--size", "32x24", "--specular", "off", *extra]
    expected = cli_render(tmp_path / "cli.exr", *flags)
    keywords = {}
    for i in range(2, len(flags), 2):
        keywords[flags[i][2:].replace("-", "_")] = flags[i + 1]
    got = lucent.render("potato", **keywords)
    assert got.shape == (24, 32, 3) and got.dtype == np.float32
    assert np.all(np.isfinite(got)) and got.mean() > 0
    # The reference is deterministic for its seed, the maps for their settings on one GL driver;
    # lucent writes 32-bit float EXRs, so the two images are equal to the bit.
    np.testing.assert_array_equal(got, expected)


def test_render_refuses_what_the_cli_refuses():
    with pytest.raises(lucent.Error, match="not an option of lucent.render"):
        lucent.render("marble", not_a_flag=3)
    with pytest.raises(lucent.Error, match="--technique"):
        lucent.render("marble", technique="nope", size="16x16")
    with pytest.raises(lucent.Error, match="unknown material"):
        lucent.render("nosuch", size="16x16")
