"""The command line parses and prints: the argparse namespace stops at the edge.

No module outside `tamp.cli` imports argparse or takes a namespace. Inside it, only the parser,
`tamp.cli.main`, each converted command's edge function (`EDGES`: the namespace turned once into
typed settings) and the helpers those edges call (`EDGE_HELPERS`) take one; the commands not
converted yet are `NOT_YET`, a list that only shrinks. A function "takes a namespace" when a
parameter is annotated ``argparse.Namespace`` or is named ``args`` (the house name for it).
"""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import pytest

from tamp.cli import build_parser

ROOT = Path(__file__).resolve().parents[3]
PACKAGES = ("tamp", "task", "motion", "perception", "robots")
CLI = "tamp/cli"

# command -> its edge, the one function that reads the namespace ("path:function")
EDGES = {
    "run": "tamp/cli/settings/run.py:run_settings",
    "demo": "tamp/cli/settings/run.py:run_settings",
    "plan": "tamp/cli/settings/plan.py:plan_settings",
    "example": "tamp/cli/settings/plan.py:example_settings",
    "validate": "tamp/cli/settings/plan.py:validate_settings",
    "bench motion": "tamp/cli/settings/motion.py:motion_settings",
}

# what the edges call to read and refuse options (each called from an edge, or by a command
# of `NOT_YET`, never below an edge)
EDGE_HELPERS = {
    "tamp/cli/options.py:planner_overrides",
    "tamp/cli/options.py:planner_config",
    "tamp/cli/options.py:check_workcell",
    "tamp/cli/recorded.py:loop_config",
    "tamp/cli/recorded.py:scene_run",
    "tamp/cli/recorded.py:_problem_run",
    "tamp/cli/settings/run.py:_output",
    "tamp/cli/settings/run.py:_refuse_inputs",
    "tamp/cli/settings/run.py:_refuse_for_geo",
    "tamp/cli/settings/run.py:_with_geo",
}

# the parser's handlers: the namespace in, the edge's settings to the command
PARSER = {
    "tamp/cli/parsers/handlers.py:at_edge.handler",
    "tamp/cli/parsers/handlers.py:lazy.handler",
}

# commands whose namespace still travels below their entry: a list that only shrinks
NOT_YET = {
    "tamp/cli/bench/arm.py:executability_command",
    "tamp/cli/bench/checker.py:checker_config",
    "tamp/cli/bench/checker.py:checker_command",
    "tamp/cli/bench/geo.py:tamp_command",
    "tamp/cli/bench/geo.py:_write",
    "tamp/cli/bench/planning.py:_run",
    "tamp/cli/bench/planning.py:planbench_command",
    "tamp/cli/bench/planning.py:pddl_command",
    "tamp/cli/bench/planning.py:random_command",
    "tamp/cli/bench/record.py:record_command",
    "tamp/cli/bench/vision.py:perception_command",
    "tamp/cli/bench/vision.py:latplan_command",
    "tamp/cli/bench/vision.py:poses_command",
    "tamp/cli/bench/vision.py:segmentation_command",
    "tamp/cli/images.py:_checkpoint",
    "tamp/cli/images.py:images_command",
    "tamp/cli/perception.py:dataset_command",
    "tamp/cli/perception.py:_latplan_dataset",
    "tamp/cli/perception.py:train_command",
    "tamp/cli/perception.py:eval_command",
    "tamp/cli/recorded.py:_planner",
    "tamp/cli/recorded.py:images_config",
    "tamp/cli/recorded.py:given_config",
    "tamp/cli/recorded.py:executability_config",
    "tamp/cli/recorded.py:tamp_bench_config",
    "tamp/cli/recorded.py:planning_config",
    "tamp/cli/recorded.py:perception_bench_config",
    "tamp/cli/recorded.py:latplan_config",
    "tamp/cli/recorded.py:poses_config",
    "tamp/cli/recorded.py:segmentation_config",
    "tamp/cli/recorded.py:dataset_config",
    "tamp/cli/recorded.py:train_config",
    "tamp/cli/recorded.py:eval_config",
}


def _takes_namespace(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    a = node.args
    for arg in (*a.posonlyargs, *a.args, *a.kwonlyargs):
        annotation = ast.unparse(arg.annotation) if arg.annotation is not None else ""
        if arg.arg == "args" or "Namespace" in annotation:
            return True
    return False


def namespace_takers(path: Path, root: Path = ROOT) -> set[str]:
    """``path``'s functions that take a namespace, as ``"path:outer.inner"``."""
    rel = path.relative_to(root).as_posix()
    found = set()

    def visit(node: ast.AST, scope: tuple[str, ...]) -> None:
        for child in ast.iter_child_nodes(node):
            inner = scope
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                inner = (*scope, child.name)
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef) and _takes_namespace(
                child
            ):
                found.add(f"{rel}:{'.'.join(inner)}")
            visit(child, inner)

    visit(ast.parse(path.read_text(), filename=str(path)), ())
    return found


def _imports_argparse(path: Path) -> bool:
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import) and any(a.name == "argparse" for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module == "argparse":
            return True
    return False


def _sources(package: str):
    return sorted((ROOT / package).rglob("*.py"))


@pytest.mark.parametrize("package", PACKAGES)
def test_nothing_outside_the_cli_imports_argparse_or_takes_a_namespace(package):
    bad = []
    for path in _sources(package):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith(CLI + "/"):
            continue
        if _imports_argparse(path):
            bad.append(f"{rel}: imports argparse")
        tree = ast.parse(path.read_text(), filename=str(path))
        bad += [
            f"{rel}:{node.name}: takes a Namespace"
            for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
            and any(
                arg.annotation is not None and "Namespace" in ast.unparse(arg.annotation)
                for arg in (*node.args.posonlyargs, *node.args.args, *node.args.kwonlyargs)
            )
        ]
    assert not bad, bad


def test_inside_the_cli_only_the_edges_take_a_namespace():
    """Below a command's edge its work and its recorded configuration take typed settings;
    a new function taking the namespace is refused, and an entry of `NOT_YET` (or of the edges'
    helpers) that no longer takes it must be dropped (the list only shrinks)."""
    found = set().union(*(namespace_takers(p) for p in _sources(CLI)))
    allowed = set(EDGES.values()) | EDGE_HELPERS | PARSER | NOT_YET
    new = sorted(found - allowed)
    gone = sorted(allowed - found)
    assert not new, f"take the command's typed settings, not the namespace: {new}"
    assert not gone, f"no longer take a namespace: drop their entries: {gone}"


def test_the_check_finds_a_namespace_parameter(tmp_path):
    """The check itself: ``args`` or an ``argparse.Namespace`` annotation is found, at any
    depth; other parameters are not."""
    (tmp_path / "pkg").mkdir()
    path = tmp_path / "pkg" / "m.py"
    path.write_text(
        "import argparse\n"
        "def a(args): pass\n"
        "def b(opts: argparse.Namespace): pass\n"
        "def c(settings, *args): pass\n"
        "def outer():\n"
        "    def inner(args): pass\n"
    )
    assert namespace_takers(path, tmp_path) == {"pkg/m.py:a", "pkg/m.py:b", "pkg/m.py:outer.inner"}
    assert _imports_argparse(path)


def _dotted(entry: str) -> tuple[str, str]:
    """An `EDGES` entry as (module, function)."""
    path, name = entry.split(":")
    return path.removesuffix(".py").replace("/", "."), name


@pytest.mark.parametrize("command", sorted(EDGES))
def test_a_converted_command_runs_on_its_edges_settings(command):
    """The parser binds each converted command's handler and recorded configuration through
    its named edge (`tamp.cli.parsers.handlers.at_edge`), so the handler receives typed settings."""
    parser = build_parser()
    for word in command.split():
        parser = next(a for a in parser._actions if isinstance(a.choices, dict)).choices[word]
    edge = ".".join(_dotted(EDGES[command]))
    for bound in ("func", "recorded"):
        assert parser.get_default(bound).__qualname__.endswith(f"({edge})"), (command, bound)


def _namespaces(value, seen=()) -> list:
    """The argparse namespaces anywhere inside ``value`` (dataclass fields, tuples, dicts)."""
    import argparse

    if isinstance(value, argparse.Namespace):
        return [value]
    if id(value) in seen:
        return []
    seen = (*seen, id(value))
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        inner = [getattr(value, f.name) for f in dataclasses.fields(value)]
    elif isinstance(value, dict):
        inner = list(value.values())
    elif isinstance(value, list | tuple):
        inner = list(value)
    else:
        return []
    return [n for v in inner for n in _namespaces(v, seen)]


@pytest.mark.parametrize(
    "argv",
    [
        ["run"],
        ["run", "--scene", "tray", "--goal", "(in a tray)", "--time-limit", "30"],
        ["demo"],
        ["plan", "d.pddl", "p.pddl", "--scene", "shelf", "--motion-aware", "--horizon", "4"],
        ["example", "--restarts", "3"],
        ["validate", "d.pddl", "p.pddl", "p.plan", "--json"],
        ["bench", "motion", "--blocks", "4,5", "--n", "2", "--observe", "camera"],
    ],
)
def test_the_edge_builds_typed_settings_with_no_namespace_inside(argv):
    """What the edge hands the command is frozen and holds no namespace."""
    from importlib import import_module

    command = " ".join(argv[:2]) if argv[0] == "bench" else argv[0]
    module, name = _dotted(EDGES[command])
    settings = getattr(import_module(module), name)(build_parser().parse_args(argv))
    assert dataclasses.is_dataclass(settings)
    assert type(settings).__dataclass_params__.frozen
    assert not _namespaces(settings)
