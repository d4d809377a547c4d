"""Every script in ``examples/`` runs as is (a fresh process, the repository root as working
directory) and exits 0; each asserts its own outcome (a valid plan, the goal reached, the
gradient check passed), so an example that stops working fails here. One torch thread each,
as on a loaded 2-core machine."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
# the examples that start a simulator (marked sim); the others plan only
SIMULATED = {"episode_both_simulators", "score_my_plan", "plan_from_images", "custom_scene"}


def _scripts() -> list:
    return [
        pytest.param(p, id=p.stem, marks=[pytest.mark.sim] if p.stem in SIMULATED else [])
        for p in sorted(EXAMPLES.glob("*.py"))
    ]


def test_there_are_examples_and_each_says_what_it_shows():
    scripts = sorted(EXAMPLES.glob("*.py"))
    assert len(scripts) >= 6
    for path in scripts:
        text = path.read_text()
        assert text.startswith('"""'), f"{path.name} has no module docstring"
        assert f"python examples/{path.name}" in text, f"{path.name} does not say how to run it"
    assert {p.stem for p in scripts} >= SIMULATED


@pytest.mark.parametrize("script", _scripts())
def test_example_runs_as_is(script: Path):
    env = os.environ | {"OMP_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, str(script)], cwd=ROOT, env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, (
        f"{script.name} failed:\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}"
    )
