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


# rooms inside a package -> modules (dotted prefixes) they must never import. The direction
# inside tamp: cli -> bench -> loop -> camera -> sim; inside task: the crisp side and the domains
# never reach into the optimiser, and the domains (soft, torch) build on the crisp side, never
# the other way round.
OPTIMISER = ("task.planner", "task.optimize", "task.rollout", "task.decode", "task.beliefs")
ROOM_FORBIDDEN = {
    "tamp/sim": ("tamp.loop", "tamp.camera", "tamp.bench", "tamp.cli"),
    "tamp/camera": ("tamp.loop", "tamp.bench", "tamp.cli"),
    "tamp/loop": ("tamp.bench", "tamp.cli"),
    "tamp/bench": ("tamp.cli",),
    "tamp/world": ("tamp.loop", "tamp.camera", "tamp.bench", "tamp.cli"),
    "tamp/geo": ("tamp.bench", "tamp.cli"),
    "task/symbolic": (*OPTIMISER, "task.domains", "torch"),
    "task/domains": OPTIMISER,
}
ROOMS = {
    "motion": ("pick_place",),
    "tamp": ("bench", "camera", "cli", "loop", "sim", "world"),
    "task": ("data", "domains", "planner", "symbolic"),
}


def _modules(path: Path) -> set[str]:
    """Every module ``path`` imports, dotted (``from a.b import c`` gives ``a.b`` and ``a.b.c``)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found |= {node.module} | {f"{node.module}.{a.name}" for a in node.names}
    return found


def _imports(path: Path) -> set[str]:
    return {n.split(".")[0] for n in _modules(path) if n not in SHARED and not _shared_child(n)}


def _shared_child(name: str) -> bool:
    return any(name.startswith(s + ".") for s in SHARED)


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


CRISP = sorted(
    f"task.symbolic.{p.stem}"
    for p in (ROOT / "task" / "symbolic").glob("*.py")
    if p.name != "__init__.py"
)
LOADED = """
import importlib
import sys

importlib.import_module(sys.argv[1])
print(sorted(m for m in sys.modules if m == "torch" or m.startswith("task.domains.")))
"""


@pytest.mark.parametrize("module", CRISP)
def test_the_crisp_side_loads_neither_torch_nor_a_domain(module):
    """Importing any task.symbolic module, through whatever it imports in turn, loads no torch
    and no domain module: no circle through the domains drags the soft machinery in."""
    out = subprocess.run(
        [sys.executable, "-c", LOADED, module], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert out.stdout.strip() == "[]", f"import {module} loads {out.stdout.strip()}"


@pytest.mark.parametrize("room", sorted(ROOM_FORBIDDEN))
def test_rooms_respect_their_import_direction(room):
    bad = {
        f"{path.relative_to(ROOT)} imports {name}"
        for path in (ROOT / room).rglob("*.py")
        for name in _modules(path)
        if name.startswith(ROOM_FORBIDDEN[room])
    }
    assert not bad, sorted(bad)


def test_simulator_base_imports_no_backend():
    """The factory picks a backend; the interface never imports one (no import circle)."""
    names = _modules(ROOT / "tamp" / "sim" / "base.py")
    assert not {n for n in names if n.startswith(("tamp.sim.pybullet", "tamp.sim.mujoco"))}


@pytest.mark.parametrize("package", sorted(ROOMS))
def test_rooms_are_packages_with_a_docstring(package):
    for room in ROOMS[package]:
        init = ROOT / package / room / "__init__.py"
        assert init.is_file(), init
        assert ast.get_docstring(ast.parse(init.read_text())), f"{init} says nothing of its room"


@pytest.mark.parametrize("package", PACKAGES)
def test_every_package_says_what_it_owns(package):
    doc = ast.get_docstring(ast.parse((ROOT / package / "__init__.py").read_text())) or ""
    assert len(doc.split()) > 10 and "TODO" not in doc


def test_no_flat_folder_of_many_modules():
    """More than about ten modules in one folder is a sign that rooms are missing."""
    for package in PACKAGES:
        for folder in [ROOT / package, *(p for p in (ROOT / package).rglob("*") if p.is_dir())]:
            modules = [p for p in folder.glob("*.py") if p.name != "__init__.py"]
            assert len(modules) <= 11, f"{folder.relative_to(ROOT)}: {len(modules)} modules"


def test_the_installed_packages_are_every_package_of_the_source_tree():
    """pyproject.toml lists its packages by name: a package missing there works in an editable
    install (the source tree is on the path) and is absent from a wheel."""
    import tomllib

    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    found = {
        ".".join(init.parent.relative_to(ROOT).parts)
        for top in PACKAGES
        for init in (ROOT / top).rglob("__init__.py")
    }
    assert sorted(found - listed) == [] and sorted(listed - found) == []


MUTATORS = {"append", "extend", "insert", "add", "update", "setdefault", "pop", "popitem"}
MUTATORS |= {"clear", "remove", "discard"}


def _module_state(path: Path) -> list[str]:
    """Where a function of ``path`` changes a module-level dict, list or set (a store into it,
    a deletion from it or a mutating method call), or rebinds a module name (``global``)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    containers = {
        t.id
        for node in tree.body
        if isinstance(node, ast.Assign | ast.AnnAssign)
        and isinstance(node.value, ast.Dict | ast.List | ast.Set | ast.Call)
        and not (
            isinstance(node.value, ast.Call) and _called(node.value) not in {"dict", "list", "set"}
        )
        for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
        if isinstance(t, ast.Name)
    }
    found = []
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Global):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno} global {node.names}")
            target = None
            if isinstance(node, ast.Subscript) and isinstance(node.ctx, ast.Store | ast.Del):
                target = node.value
            elif isinstance(node, ast.Call) and _mutates(node):
                target = node.func.value
            if isinstance(target, ast.Name) and target.id in containers:
                found.append(f"{path.relative_to(ROOT)}:{node.lineno} changes {target.id}")
    return found


def _mutates(call: ast.Call) -> bool:
    return isinstance(call.func, ast.Attribute) and call.func.attr in MUTATORS


def _called(call: ast.Call) -> str:
    return call.func.id if isinstance(call.func, ast.Name) else ""


def test_library_code_keeps_no_process_global_state():
    """No function of the library changes a module-level container or rebinds a module name:
    caches belong to an object the caller holds (e.g. an episode's IK solver), not to the
    process."""
    found = [
        line
        for package in PACKAGES
        for path in sorted((ROOT / package).rglob("*.py"))
        for line in _module_state(path)
    ]
    assert not found, found


def _sys_modules_writes(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    return [
        f"{path.relative_to(ROOT)}:{node.lineno}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Subscript)
        and isinstance(node.ctx, ast.Store | ast.Del)
        and ast.unparse(node.value) == "sys.modules"
    ]


def test_library_code_leaves_the_import_machinery_alone():
    """No library module stores into or deletes from ``sys.modules`` (e.g. to hide a module
    from a dependency's import): what is imported stays as Python imported it."""
    found = [
        w for p in PACKAGES for path in (ROOT / p).rglob("*.py") for w in _sys_modules_writes(path)
    ]
    assert not found, found
