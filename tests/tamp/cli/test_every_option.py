"""Every option of every ``tamp`` command either changes what the command records as its
configuration (``args.recorded``, `tamp.cli.recorded`: the ``config`` its results.json,
report.json or ``--json`` output carries, built by the same functions the run is built from) or is
refused in one line, and each takes effect in at least one combination (alone, or with the
options it needs, `NEEDS`). The parser is introspected, so a new option without a recorded
effect fails here. The recorded dicts are computed from the options only (no planning, no
simulator), so the walk is fast; test_cli.py and test_executability.py check that the handlers
write these very dicts.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from perception import CHECKPOINT
from perception import data as pdata
from tamp.cli import build_parser, main
from tamp.cli.recorded import PRESENTATION
from task.config import check_device_name
from task.errors import TampError

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "domains"

# the positional arguments and required options of each command (never read by `recorded`)
BASE = {
    "plan": ["d.pddl", "p.pddl"],
    "validate": ["d.pddl", "p.pddl", "plan.txt"],
    "plan-images": ["a.png", "b.png"],
    "bench pddl": ["--data", "folder"],
    "bench executability": ["--plans", "plans.csv"],
    "perception dataset": ["--out", "x.npz"],
    "perception train": ["--train", "a.npz", "--test", "b.npz", "--out", "m.pt"],
    "perception eval": ["data.npz"],
}
# a value for every option whose value is not a choice, a flag or a number with a default
SAMPLES = {
    "--inject": "drop:0.2",
    "--sim": "mujoco",
    "--domain": "domain.pddl",
    "--binding": str(EXAMPLES / "tray.binding.json"),
    "--checkpoint": "other.pt",
    "--plan": "plan.txt",
    "--data": "elsewhere",
    "--ray": "local",
    "--modes": "state",
    "--res": "45x30",
    "--crisp": "true,perceived",
    "--corrupt": "noise:8",
    "--time-limit": "5",
    "--lookahead-share": "0.25",
    "--tau-end": "0.5",
    "--placements": "0.02",
    "--horizon": "2",
    "--blocks": "4,5",
    "--blur": "3",
    "--kl-weight": "2.5",
    "--train": "c.npz",
    "--test": "d.npz",
    "--limit": "2",
    "--n": "2",
    "--max-replans": "3",
    "--scenes": "clutter",  # bench checker: a list of scene names
    "--scene": "shelf",  # run and demo: a name or a scene file (the other commands: choices)
    "--goal": "(on b c)",
    "--problems": "blocked,tall",
    "--planner": "search",
    "--record": "episode.rrd",  # run and demo: a file (the benchmarks: a flag)
    "--peers": "pyperplan,lama",
    "--baselines": "us,gn1",
    "--device": "cuda",  # accepted in the walk as on a machine with a GPU (`_inputs`)
}
# what an option needs to take effect, per command where it differs; tried in order
NEEDS = {
    "--placements": [["--motion-aware"], ["--motion-aware", "--observe", "state"]],
    "--scene": [["--motion-aware"]],
    "--perception": [["--observe", "camera"]],
    "--blur": [["--observe", "camera"]],
    "--checkpoint": [["--observe", "camera"], ["--modes", "frozen"]],
    "--replan": [["--plan", "plan.txt"]],
    "--stop-at-invalid": [["--plan", "plan.txt"]],
    "--video-format": [["--out", "folder"]],
    "--video": [["--out", "folder"]],
    "--no-video": [["--out", "folder"]],
    "--record": [["--out", "folder"]],  # the benchmarks: OUT/recordings/
    "--domain": [["problem.pddl"]],
    "--min-blocks": [["--max-blocks", "9"]],
    "--data": [["--blocks", "4"]],
    "--peers": [["--time-limit", "5"]],  # the same limit for every planner
    # a scene file (the shipped example's name), another goal, and the state observed
    "--goal": [["--scene", "tower", "--goal", "(on a c)", "--observe", "state"]],
    # a scene file the loop could run, run by the geometric episode's planner instead
    "--geo-planner": [["--scene", "tower", "--goal", "(on a c)", "--observe", "state"]],
    # a user's domain on a scene file, bound by the TOML binding before the JSON one
    "--binding": [
        [
            *("--scene", "tray", "--goal", "(in a tray)", "--observe", "state"),
            *("--domain", str(EXAMPLES / "tray.pddl")),
            *("--binding", str(EXAMPLES / "tray.binding.toml")),
        ]
    ],
}
# commands with no run configuration: what they write is named by their options
NOT_RUNS = {"bench record"}


@pytest.fixture(scope="module", autouse=True)
def _inputs(tmp_path_factory):
    """The base invocation of commands that refuse missing input files before any work: a
    tiny support dataset (one blank 30x45 image, no block; the walk reads no pixel) and the
    shipped checkpoint. ``--device cuda`` is accepted as on a machine with a GPU (the walk
    runs nothing on it; tests/tamp/cli/test_device_option.py checks the refusal where there
    is none)."""
    blank = pdata.SupportData(
        images=np.zeros((1, 30, 45, 3), np.uint8),
        colours=np.full((1, 4), -1, np.int8),
        supports=np.full((1, 4), pdata.PAD, np.int8),
        palette=np.eye(3, dtype=np.float32),
        meta={"scene": "latplan"},
    )
    path = pdata.save(tmp_path_factory.mktemp("inputs") / "tiny.npz", blank)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(BASE, "bench segmentation", [str(path), "--checkpoint", str(CHECKPOINT)])
        patch.setattr("task.config.device_problem", lambda name: check_device_name(name) and None)
        yield


def _leaves(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _leaves(sub, (*path, name))
            return
    yield " ".join(path), parser


COMMANDS = dict(_leaves(build_parser()))


def _recorded_as(body: dict, key: str) -> list:
    """The values ``body`` (nested dicts too) records under ``key``."""
    found = [body[key]] if key in body else []
    return found + [v for d in body.values() if isinstance(d, dict) for v in _recorded_as(d, key)]


def _values(action: argparse.Action, base: dict) -> list[list[str]]:
    """Each non-default way to give ``action`` on the command line (a choice that is what
    ``base`` records when the option is not given is its default, e.g. ``--goal-loss
    default``)."""
    flag = action.option_strings[0]
    if action.nargs == 0:
        return [[flag]]
    if action.choices:
        same = (action.default, *_recorded_as(base, action.dest))
        return [[flag, str(c)] for c in action.choices if c not in same]
    if flag in SAMPLES:
        return [[flag, SAMPLES[flag]]]
    if isinstance(action.default, int) and not isinstance(action.default, bool):
        return [[flag, str(action.default + 1)]]
    return [[flag, "2"]]  # an unset count (None): any valid one differs


def _recorded(command: str, extra: list[str]) -> dict | None:
    """The recorded config of ``command`` with ``extra`` options; None when refused (argparse
    exit 2 or a one-line TampError)."""
    argv = [*command.split(), *BASE.get(command, []), *extra]
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:
        assert exc.code == 2, argv
        return None
    try:
        return args.recorded(args)
    except TampError as exc:
        assert "\n" not in str(exc)
        return None


def _options(command: str):
    for action in COMMANDS[command]._actions:
        if action.option_strings and action.dest not in PRESENTATION and not action.required:
            yield action


@pytest.mark.parametrize("command", sorted(set(COMMANDS) - NOT_RUNS))
def test_every_option_changes_the_recorded_config_or_is_refused(command):
    base = _recorded(command, [])
    assert base is not None, f"{command}: refused without options"
    json.dumps(base)  # what is recorded is plain JSON
    idle = []
    for action in _options(command):
        for value in _values(action, base):
            alone = _recorded(command, value)
            if alone is not None:
                assert alone != base, f"{command} {value}: accepted and recorded no change"
                continue
            # refused alone: it must take effect with what it needs
            for needs in NEEDS.get(value[0], []):
                before = _recorded(command, needs)
                after = _recorded(command, [*needs, *value])
                if before is not None and after is not None:
                    assert after != before, f"{command} {needs} {value}: no change"
                    break
            else:
                idle.append(" ".join(value))
    assert not idle, f"{command}: options refused in every combination tried: {idle}"


def test_every_command_records_its_config_or_is_named_here():
    lacking = {c for c, p in COMMANDS.items() if p.get_default("recorded") is None}
    assert lacking == NOT_RUNS


def test_presentation_options_are_only_these():
    """Options exempt from the walk change how output is shown, never what is computed."""
    dests = {a.dest for p in COMMANDS.values() for a in p._actions if a.option_strings}
    assert PRESENTATION & dests == {"json", "out", "progress", "help"}


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["plan", "d", "p", "--placements", "0.02"], "--placements needs --motion-aware"),
        (["plan", "d", "p", "--scene", "shelf"], "--scene shelf needs --motion-aware"),
        (["run", "--placements", "0.01"], "--placements needs --motion-aware"),
        (
            ["run", "--motion-aware", "--placements", "0.01", "--observe", "camera"],
            "--placements needs --observe state",
        ),
        (["run", "--perception", "optimised"], "need --observe camera"),
        (
            ["bench", "executability", "--plans", "x.csv", "--no-ours", "--motion-aware"],
            "--no-ours",
        ),
        (["bench", "executability", "--plans", "x.csv", "--placements", "0.02"], "--motion-aware"),
        (["run", "--replan"], "apply to a given plan"),
        (["run", "--goal", "(on a b)"], "--goal needs --scene FILE.json"),
        (["run", "p.pddl", "--scene", "tower", "--goal", "(on a b)"], "--goal with PROBLEM.pddl"),
        (["run", "--scene", "tower"], "needs --goal"),
        (["run", "--scene", "attic"], "neither a named scene"),
        (
            ["demo", "--scene", "tower", "--goal", "(on b c)"],
            "--observe camera with a Blocksworld scene",
        ),
        (["run", "--scene", "tower", "--goal", "(on b c)", "--plan", "x"], "--plan with a scene"),
    ],
)
def test_options_that_cannot_apply_are_one_line_usage_errors(capsys, argv, expected):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err, err


def test_executability_records_motion_aware_and_placements():
    argv = ["bench", "executability", "--plans", "x.csv", "--motion-aware", "--placements", "0.02"]
    args = build_parser().parse_args(argv)
    recorded = args.recorded(args)
    assert recorded["lambda_motion"] == 0.05 and recorded["placements"] == 0.02
    assert recorded["planner"]["lambda_motion"] == 0.05


def test_the_image_scene_and_the_workcell_scene_have_different_names():
    images = {a.dest for a in COMMANDS["plan-images"]._actions}
    assert "image_scene" in images and "scene" not in images
    assert "image_scene" in {a.dest for a in COMMANDS["perception dataset"]._actions}
    for command, parser in COMMANDS.items():  # --motion-aware: one definition, one meaning
        flags = [a for a in parser._actions if "--motion-aware" in a.option_strings]
        assert len(flags) <= 1, command
        if flags:
            assert flags[0].help == COMMANDS["run"]._option_string_actions["--motion-aware"].help


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_count_is_bounded(command):
    """An integer option beyond any machine (10**12: threads, blocks, a window, a seed, a
    radius, instances) is a usage error, never a crash or a hang."""
    for action in COMMANDS[command]._actions:
        if action.type is None or action.type in (float, str) or not action.option_strings:
            continue
        try:
            action.type("1")
        except (argparse.ArgumentTypeError, ValueError):
            continue  # not a count (e.g. seconds > 0 take 1 too; a spec)
        if isinstance(action.type("1"), float):
            continue
        with pytest.raises(argparse.ArgumentTypeError):
            action.type(str(10**12))
