"""The notebooks in notebooks/, run headless: each notebook's code cells in order in one namespace
(no Jupyter needed), with LUCENT_NOTEBOOK_OUT at a temporary folder for their figures; and none of
them may carry outputs in the repository.

Run by ctest (tests/python/CMakeLists.txt) with PYTHONPATH at the build tree's module and
LUCENT_SOURCE_DIR the repository root (default: this file's repository).
"""
import json
import os
import pathlib
import time
import traceback

import pytest

ROOT = pathlib.Path(os.environ.get("LUCENT_SOURCE_DIR")
                    or pathlib.Path(__file__).resolve().parents[2]).resolve()
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))


def load(path):
    with open(path, encoding="utf-8") as f:
        nb = json.load(f)
    assert nb.get("nbformat") == 4, f"{path.name}: not an nbformat 4 notebook"
    return nb


def source(cell):
    text = cell.get("source", "")
    return "".join(text) if isinstance(text, list) else text


def test_there_are_notebooks():
    assert NOTEBOOKS, f"no notebooks in {ROOT / 'notebooks'}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_has_no_outputs_committed(path):
    for index, cell in enumerate(load(path)["cells"]):
        if cell["cell_type"] != "code":
            continue
        assert cell.get("outputs") == [], f"{path.name}: cell {index} has outputs committed"
        assert cell.get("execution_count") is None, f"{path.name}: cell {index} has an execution count"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path, tmp_path, monkeypatch):
    pytest.importorskip("numpy")
    pytest.importorskip("matplotlib")
    out = tmp_path / "figures"
    monkeypatch.setenv("LUCENT_NOTEBOOK_OUT", str(out))
    monkeypatch.setenv("LUCENT_SOURCE_DIR", str(ROOT))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    # A notebook runs from its own folder (relative paths there mean what they mean in Jupyter).
    monkeypatch.chdir(path.parent)
    namespace = {"__name__": "__main__", "__file__": str(path)}
    start = time.monotonic()
    for index, cell in enumerate(load(path)["cells"]):
        if cell["cell_type"] != "code":
            continue
        text = source(cell)
        try:
            exec(compile(text, f"{path.name}[cell {index}]", "exec"), namespace)
        except Exception as error:  # noqa: BLE001 - report which cell failed and how
            pytest.fail(f"{path.name}: code cell {index} failed: {type(error).__name__}: {error}\n"
                        + "".join(traceback.format_exception(error)[-6:]), pytrace=False)
    elapsed = time.monotonic() - start
    figures = sorted(p.name for p in out.glob("*.png")) if out.is_dir() else []
    assert figures, f"{path.name}: saved no figure under LUCENT_NOTEBOOK_OUT"
    print(f"{path.name}: {elapsed:.1f} s, figures {figures}")
    try:
        import matplotlib.pyplot as plt
        plt.close("all")
    except ImportError:
        pass
