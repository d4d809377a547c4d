"""Package boundaries from STYLE.md: who may import what, and that the packages are ours."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("tamp", "task", "motion", "perception", "robots")
SIMULATORS = {"pybullet", "pybullet_data", "mujoco"}
MOTION_LIBS = {"pytorch_kinematics", "ruckig"}

# package -> top-level modules it must never import
FORBIDDEN = {
    "task": SIMULATORS | MOTION_LIBS | {"cv2", "tamp", "motion", "perception", "robots"},
    "perception": SIMULATORS | MOTION_LIBS | {"tamp", "motion", "robots", "task"},
    "robots": MOTION_LIBS | {"tamp", "task", "motion", "perception", "torch"},
    "motion": SIMULATORS | {"tamp", "task", "perception"},
    "tamp": set(),
}


# the one exception family (task.errors.TampError) is shared by every package
SHARED = {"task.errors"}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    found = set()
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        found |= {n.split(".")[0] for n in names if n not in SHARED}
    return found


@pytest.mark.parametrize("package", PACKAGES)
def test_package_respects_its_import_boundary(package):
    bad = {
        f"{path.relative_to(ROOT)} imports {name}"
        for path in (ROOT / package).rglob("*.py")
        for name in _imports(path) & FORBIDDEN[package]
    }
    assert not bad, sorted(bad)


@pytest.mark.parametrize("package", PACKAGES)
def test_top_level_package_resolves_to_this_repository(package):
    module = __import__(package)
    assert Path(module.__file__).resolve().parent == ROOT / package


def test_import_task_stays_light():
    code = "import sys, task; print(sorted(m for m in ('torch', 'pddl') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
