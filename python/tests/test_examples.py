"""The examples run as written: the paper's Fig. 6 from Python."""
import os
import re
import runpy
import sys

import numpy as np
import pytest

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")


def test_fig6_zigzag_example(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    out = tmp_path / "fig6.png"
    monkeypatch.setattr(sys, "argv", ["fig6_zigzag.py", str(out)])
    scope = runpy.run_path(os.path.join(EXAMPLES, "fig6_zigzag.py"), run_name="__main__")
    assert out.stat().st_size > 10_000
    # exact runs: the averaged single-run coefficients replay the manoeuvre (NOTES.md §7)
    original, replayed = scope["original"], scope["replayed"]
    assert np.degrees(np.abs(replayed["ψ"] - original["ψ"])).max() < 0.1


NOTEBOOKS = os.path.join(EXAMPLES, "notebooks")


@pytest.mark.parametrize("name", ["ship", "generic"])
def test_notebook_examples_run(name, monkeypatch):
    """The notebook-style examples (Jupytext percent format) run top to bottom as scripts."""
    pytest.importorskip("matplotlib")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    scope = runpy.run_path(os.path.join(NOTEBOOKS, f"{name}.py"), run_name="__main__")
    if name == "ship":
        # the turning circle no run covered, against the true ship's (a polynomial fitted to
        # zigzags extrapolates roughly: the notebook says so)
        assert abs(scope["d_found"] / scope["d_true"] - 1) < 0.15
    if name == "generic":
        z = scope["found"].model.coefficients("z_dot").set_index("term")["value"]
        assert sorted(z.index) == ["x*y", "z"] and z["z"] == pytest.approx(-8 / 3, rel=0.02)
        assert sorted(scope["fitted"].coefficients.index) == ["x*y", "z"]


def test_fleet_notebook_runs():
    """The Dask notebook, as its own process (its workers are processes too)."""
    pytest.importorskip("dask.distributed")
    import subprocess

    done = subprocess.run(
        [sys.executable, os.path.join(NOTEBOOKS, "fleet.py")], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr[-2000:]
    for eq in ("u_dot", "v_dot", "r_dot"):
        assert f"{eq} same terms: True" in done.stdout, done.stdout


def test_package_readme_examples_run():
    """The Python blocks of the package's README run as written, in order."""
    text = open(os.path.join(EXAMPLES, "..", "README.md"), encoding="utf-8").read()
    blocks = [b.split("```", 1)[0] for b in text.split("```python\n")[1:]]
    assert len(blocks) >= 2
    scope: dict = {}
    for block in blocks:
        exec(compile(block, "python/README.md", "exec"), scope)


ROOT = os.path.join(EXAMPLES, "..", "..")


def _pages_with_python():
    """README.md and every page of the guide under docs/ that holds a Python block."""
    pages = ["README.md"]
    for folder, _, files in sorted(os.walk(os.path.join(ROOT, "docs"))):
        pages += [os.path.relpath(os.path.join(folder, f), ROOT) for f in sorted(files) if f.endswith(".md")]
    return [p for p in pages if "```python" in open(os.path.join(ROOT, p), encoding="utf-8").read()]


def test_the_guide_has_python_blocks():
    assert "README.md" in _pages_with_python() and len(_pages_with_python()) >= 2


@pytest.mark.parametrize("page", _pages_with_python())
def test_python_blocks_of_readme_and_the_guide_run(page, tmp_path, monkeypatch):
    """The Python blocks of README.md and of each page of the guide run as written, in order,
    in one scope per page (a block after `<!-- readme-test: skip: why -->` is a fragment and
    is left out); every file a block saves is there afterwards."""
    pytest.importorskip("matplotlib")
    pytest.importorskip("sklearn")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(tmp_path)  # what the blocks write lands here
    lines = open(os.path.join(ROOT, page), encoding="utf-8").read().splitlines()
    blocks, k = [], 0
    while k < len(lines):
        if lines[k].strip() == "```python":
            end = lines.index("```", k + 1)
            if "readme-test: skip" not in lines[k - 1]:
                blocks.append((k + 1, "\n".join(lines[k + 1:end])))
            k = end
        k += 1
    assert blocks, page
    scope: dict = {}
    for line, block in blocks:
        exec(compile("\n" * line + block, page, "exec"), scope)
    for _, block in blocks:
        for saved in re.findall(r'\.save\("([^"]+)"\)', block):
            assert (tmp_path / saved).exists(), saved
