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


# The direction inside tamp (docs/layout.md), bottom to top: each room (a folder) or loose module
# imports only from the layers below it (or its own). Measured, every import counted, function
# level too: the bottom three import nothing of tamp.
TAMP_LAYERS = (
    ("episode_report", "modes", "obstacles", "outcome", "rerun_log", "sweep"),
    ("scene",),
    ("sim",),
    ("arm", "slots", "video", "world"),
    ("camera",),
    ("geo",),
    ("loop",),
    ("bench",),
    ("api", "cli"),
)


def _tamp_path(name: str) -> str:
    return f"tamp/{name}" if (ROOT / "tamp" / name).is_dir() else f"tamp/{name}.py"


# rooms inside a package (a folder, or one of tamp's loose modules) -> modules (dotted prefixes)
# they must never import. Inside tamp: `TAMP_LAYERS`; inside task: the crisp side and the
# domains never reach into the optimiser, and the domains (soft, torch) build on the crisp side,
# never the other way round.
OPTIMISER = ("task.planner", "task.optimize", "task.rollout", "task.decode", "task.beliefs")
ROOM_FORBIDDEN = {
    **{
        _tamp_path(name): tuple(
            f"tamp.{above}" for later in TAMP_LAYERS[k + 1 :] for above in later
        )
        for k, layer in enumerate(TAMP_LAYERS)
        for name in layer
    },
    "task/symbolic": (*OPTIMISER, "task.domains", "torch"),
    "task/domains": OPTIMISER,
}
ROOMS = {
    "motion": ("pick_place", "sphere_check"),
    "tamp": ("arm", "bench", "camera", "cli", "geo", "loop", "sim", "world"),
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


CRISP = sorted(  # every module of the crisp side, its sub-rooms' too (pddl_io/, proofs/, ...)
    ".".join(p.relative_to(ROOT).with_suffix("").parts)
    for p in (ROOT / "task" / "symbolic").rglob("*.py")
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


def test_every_room_and_loose_module_of_tamp_has_a_layer():
    layered = {name for layer in TAMP_LAYERS for name in layer}
    found = {p.stem for p in (ROOT / "tamp").iterdir() if p.suffix == ".py" or p.is_dir()}
    found -= {"__init__", "__pycache__"}
    assert sorted(found - layered) == [] and sorted(layered - found) == []


@pytest.mark.parametrize("room", sorted(ROOM_FORBIDDEN))
def test_rooms_respect_their_import_direction(room):
    top = ROOT / room
    bad = {
        f"{path.relative_to(ROOT)} imports {name}"
        for path in ([top] if top.is_file() else top.rglob("*.py"))
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


# ---- the import graph of the five packages: private names and circles


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


OURS = {_module_name(path): path for package in PACKAGES for path in (ROOT / package).rglob("*.py")}


def _edges(path: Path) -> dict[str, set[str]]:
    """Every module of ours that ``path`` imports, at any level (module, function, TYPE_CHECKING)
    -> the names it takes there (``from a.b import c``: ``a.b.c`` when that is a module, else
    ``a.b`` taking ``c``; ``import a.b``: ``a.b``)."""
    out: dict[str, set[str]] = {}
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in OURS:
                    out.setdefault(alias.name, set())
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path.relative_to(ROOT)}: a relative import"
            for alias in node.names:
                child = f"{node.module}.{alias.name}"
                if child in OURS:
                    out.setdefault(child, set())
                elif node.module in OURS:
                    out.setdefault(node.module, set()).add(alias.name)
    return out


def _packages_run(me: str, path: Path) -> set[str]:
    """The packages of ours whose ``__init__`` an import in ``path`` runs first (``from a.b.c
    import x`` runs ``a`` and ``a.b``), less ``me``'s own packages (already run before ``me``)."""
    mine = _ancestors(me)
    return {p for target in _edges(path) for p in _ancestors(target) if p in OURS} - mine


def _ancestors(name: str) -> set[str]:
    parts = name.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts))}


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _private_attributes(path: Path) -> set[tuple[str, str]]:
    """(module, name) of every ``module._name`` read in ``path`` through an imported module of
    ours (``from task.symbolic import strips`` ... ``strips._atom``)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    bound = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname and alias.name in OURS:
                    bound[alias.asname] = alias.name
                elif alias.name.split(".")[0] in PACKAGES:
                    bound[alias.name.split(".")[0]] = alias.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom) and node.module:
            for alias in node.names:
                if f"{node.module}.{alias.name}" in OURS:
                    bound[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr):
            chain, value = [], node.value
            while isinstance(value, ast.Attribute):
                chain.append(value.attr)
                value = value.value
            if isinstance(value, ast.Name) and value.id in bound:
                found.add((".".join([bound[value.id], *reversed(chain)]), node.attr))
    return found


@pytest.mark.parametrize("package", PACKAGES)
def test_no_module_takes_a_private_name_from_another(package):
    """A name starting with ``_`` belongs to its module: another module that needs it is a sign
    that the name is the module's API (make it public) or that the two hold one concept."""
    bad = set()
    for path in (ROOT / package).rglob("*.py"):
        me = _module_name(path)
        taken = {(m, n) for m, names in _edges(path).items() for n in names}
        for module, name in taken | _private_attributes(path):
            if module != me and _private(name):
                bad.add(f"{path.relative_to(ROOT)} takes {name} from {module}")
    assert not bad, sorted(bad)


def _circles(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(component)
    return found


def test_circles_are_found_with_their_files():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": {"e"}}
    assert _circles(graph) == [{"a", "b", "c"}]


def test_no_import_circles():
    """No module of the five packages imports, directly or through others, one that imports it
    back: every import counts, also one inside a function (a lazy import that dodges a circle is
    still the circle), and so does the package ``__init__`` an import of a submodule runs first."""
    graph = {me: (set(_edges(path)) | _packages_run(me, path)) - {me} for me, path in OURS.items()}
    bad = [
        " <-> ".join(sorted(str(OURS[m].relative_to(ROOT)) for m in circle))
        for circle in _circles(graph)
    ]
    assert not bad, bad


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


# Module-level tuples, lists, sets or frozensets of the same string values that may stand in two
# modules: coincidences of names, not a mode defined twice (a mode is one `enum.StrEnum` in the
# module that owns it). Keyed by the sorted values; each names why it may repeat.
SAME_STRINGS_ALLOWED = {
    # Logistics' and Sokoban's goal losses: each domain lists its own, and two agree
    ("atoms", "potential"),
    # the canonical problems' names: `tamp.cli.bench.options.TAMP_PROBLEMS` names them without
    # importing their generators, `tests/tamp/bench/test_tamp_bench.py` keeps the two equal
    ("blocked", "hanoi", "nonmonotonic", "packed", "sorting", "tall"),
    # file names a PDDL folder's domain may have: the suites' and the peers' readers
    ("domain.pddl", "generated_domain.pddl"),
    # the Panda's finger links: the MuJoCo model's bodies and the sphere model's links
    ("panda_leftfinger", "panda_rightfinger"),
    # Blocksworld's operators: the crisp side (`task.symbolic.validate`) must not import the
    # domains (`ROOM_FORBIDDEN`), which name them again for their PDDL
    ("pick-up", "put-down", "stack", "unstack"),
}


def _string_collections(path: Path) -> list[tuple[str, tuple[str, ...]]]:
    """``(name, sorted values)`` of each module-level assignment in ``path`` of a tuple, list,
    set or frozenset (``frozenset(...)`` too) of two or more string constants."""
    found = []
    for node in ast.parse(path.read_text(), filename=str(path)).body:
        if not isinstance(node, ast.Assign | ast.AnnAssign) or node.value is None:
            continue
        value = node.value
        if isinstance(value, ast.Call) and getattr(value.func, "id", "") in ("frozenset", "set"):
            value = value.args[0] if value.args else value
        if not isinstance(value, ast.Tuple | ast.List | ast.Set) or len(value.elts) < 2:
            continue
        if all(isinstance(e, ast.Constant) and isinstance(e.value, str) for e in value.elts):
            target = node.targets[0] if isinstance(node, ast.Assign) else node.target
            if getattr(target, "id", "") != "__all__":
                found.append(
                    (getattr(target, "id", "?"), tuple(sorted(e.value for e in value.elts)))
                )
    return found


def test_no_mode_is_defined_twice():
    where: dict[tuple[str, ...], list[str]] = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            for name, values in _string_collections(path):
                where.setdefault(values, []).append(f"{path.relative_to(ROOT)}:{name}")
    twice = {v: w for v, w in where.items() if len(w) > 1 and v not in SAME_STRINGS_ALLOWED}
    assert not twice, "the same strings defined in two places (one StrEnum instead): " + "; ".join(
        f"{values} in {', '.join(w)}" for values, w in sorted(twice.items())
    )
    stale = SAME_STRINGS_ALLOWED - {v for v, w in where.items() if len(w) > 1}
    assert not stale, f"allowed repeats that no longer repeat: {sorted(stale)}"


# --- signatures: concepts, not wide parameter lists ----------------------------------------------

MAX_PARAMETERS = 7  # per function, self / cls not counted, *args and **kwargs one each
MAX_POSITIONAL = 7  # per call, starred arguments not counted

# The functions still over `MAX_PARAMETERS` ("path:qualname": parameters) and the calls still over
# `MAX_POSITIONAL` ("path:callee": the most positional arguments of its calls in that file).
# These lists only shrink: a new entry or a grown count fails, and so does an entry that shrank or
# went (lower or drop it). Regenerate both literals with `python tests/test_layout.py`.
WIDE_FUNCTIONS = {
    "tamp/api/episodes.py:_run_scene": 8,
    "tamp/api/episodes.py:execute_plan": 8,
    "tamp/api/episodes.py:run": 8,
    "tamp/bench/executability.py:run_given": 10,
    "tamp/bench/motion.py:run": 8,
    "tamp/bench/planning.py:run": 8,
    "tamp/bench/vision/perception.py:run": 10,
    "tamp/camera/dataset.py:generate": 8,
    "tamp/camera/image_pair.py:plan_from_images": 8,
    "tamp/camera/latplan.py:generate": 10,
    "tamp/geo/check.py:Tools.__init__": 9,
    "tamp/geo/check.py:check_move": 8,
    "tamp/geo/episode.py:_act": 8,
    "tamp/geo/ours/pack.py:pack_sampled": 8,
    "tamp/loop/episode.py:Episode.__init__": 8,
    "task/planner/loop.py:plan_batch": 8,
    "task/rollout.py:rollout": 8,
}
WIDE_CALLS = {
    "robots/pybullet_loader.py:p.createConstraint": 8,
    "tamp/api/episodes.py:_run_scene": 8,
    "tamp/api/images.py:plan_from_images": 8,
    "tamp/cli/bench/arm.py:bench.run_given": 10,
    "tamp/cli/bench/arm.py:motion.run": 8,
    "tamp/cli/bench/planning.py:planning.run": 8,
    "tamp/cli/images.py:plan_from_images": 8,
    "tamp/geo/episode.py:_act": 8,
    "tamp/video.py:cv2.putText": 8,
}


def _parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = node.args
    names = [x.arg for x in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
    if names and names[0] in ("self", "cls"):
        names = names[1:]
    return len(names) + (a.vararg is not None) + (a.kwarg is not None)


def _wide(path: Path, root: Path = ROOT) -> tuple[dict[str, int], dict[str, int]]:
    """``path``'s functions over `MAX_PARAMETERS` and its calls over `MAX_POSITIONAL`, keyed as
    `WIDE_FUNCTIONS` and `WIDE_CALLS` are (the path relative to ``root``)."""
    rel = path.relative_to(root).as_posix()
    functions: dict[str, int] = {}
    calls: dict[str, int] = {}

    def visit(node: ast.AST, scope: tuple[str, ...]) -> None:
        for child in ast.iter_child_nodes(node):
            inner = scope
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                inner = (*scope, child.name)
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                n = _parameters(child)
                if n > MAX_PARAMETERS:
                    key = f"{rel}:{'.'.join(inner)}"
                    functions[key] = max(n, functions.get(key, 0))
            if isinstance(child, ast.Call):
                n = sum(not isinstance(x, ast.Starred) for x in child.args)
                if n > MAX_POSITIONAL:
                    key = f"{rel}:{ast.unparse(child.func)}"
                    calls[key] = max(n, calls.get(key, 0))
            visit(child, inner)

    visit(ast.parse(path.read_text(), filename=str(path)), ())
    return functions, calls


def _all_wide() -> tuple[dict[str, int], dict[str, int]]:
    functions: dict[str, int] = {}
    calls: dict[str, int] = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            f, c = _wide(path)
            functions |= f
            calls |= c
    return functions, calls


def _shrinks_only(found: dict[str, int], allowed: dict[str, int], what: str) -> list[str]:
    bad = [
        f"{key}: {n} {what} (a new one: take a config or a concept instead)"
        for key, n in found.items()
        if key not in allowed
    ]
    bad += [
        f"{key}: {found[key]} {what}, {allowed[key]} allowed"
        for key in found.keys() & allowed.keys()
        if found[key] > allowed[key]
    ]
    bad += [
        f"{key}: {found.get(key, 0)} {what} now; lower or drop its entry (the list only shrinks)"
        for key, n in allowed.items()
        if found.get(key, 0) < n
    ]
    return sorted(bad)


def test_no_function_takes_more_than_seven_parameters():
    """Parameters that travel together form a concept (a frozen config, a request, the tools a
    caller holds): no function of the five packages takes more than `MAX_PARAMETERS`, except
    those of `WIDE_FUNCTIONS`, a list that only shrinks."""
    found, _ = _all_wide()
    assert not _shrinks_only(found, WIDE_FUNCTIONS, "parameters"), _shrinks_only(
        found, WIDE_FUNCTIONS, "parameters"
    )


def test_no_call_passes_more_than_seven_positional_arguments():
    """Callers name what they pass: no call in the five packages passes more than
    `MAX_POSITIONAL` positional arguments (a run of Nones reads as nothing), except those of
    `WIDE_CALLS`, a list that only shrinks."""
    _, found = _all_wide()
    bad = _shrinks_only(found, WIDE_CALLS, "positional arguments")
    assert not bad, bad


def test_the_signature_check_finds_wide_functions_and_calls(tmp_path):
    """The check itself: eight parameters (self not counted) and eight positional arguments
    are found, seven are not."""
    code = (
        "class K:\n"
        "    def wide(self, a, b, c, d, e, f, g, h): pass\n"
        "    def fits(self, a, b, c, d, e, f, g): pass\n"
        "def outer(*args, **kwargs):\n"
        "    def inner(a, b, c, d, e, f, *rest, **more): pass\n"
        "    K().fits(1, 2, 3, 4, 5, 6, 7)\n"
        "    K().wide(1, 2, 3, 4, 5, 6, 7, 8)\n"
    )
    (tmp_path / "pkg").mkdir()
    path = tmp_path / "pkg" / "m.py"
    path.write_text(code)
    functions, calls = _wide(path, tmp_path)
    assert functions == {"pkg/m.py:K.wide": 8, "pkg/m.py:outer.inner": 8}
    assert calls == {"pkg/m.py:K().wide": 8}
    assert _shrinks_only({"a": 9}, {"a": 8}, "p") and _shrinks_only({"a": 8}, {}, "p")
    assert _shrinks_only({}, {"a": 8}, "p") and not _shrinks_only({"a": 8}, {"a": 8}, "p")


def _literal(found: dict[str, int]) -> str:
    return "".join(f'    "{key}": {n},\n' for key, n in sorted(found.items()))


if __name__ == "__main__":  # regenerate `WIDE_FUNCTIONS` and `WIDE_CALLS` in this file
    functions, calls = _all_wide()
    me = Path(__file__)
    text = me.read_text()
    for name, found in (("WIDE_FUNCTIONS", functions), ("WIDE_CALLS", calls)):
        start = text.index(f"{name} = {{\n") + len(f"{name} = {{\n")
        end = text.index("}\n", start)
        text = text[:start] + _literal(found) + text[end:]
    me.write_text(text)
