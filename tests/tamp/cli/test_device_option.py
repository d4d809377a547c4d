"""``--device``: parsed by every command that plans or runs perception, recorded in what they
write, and refused in one line (exit 2, never a traceback) where this machine lacks it."""

from __future__ import annotations

import argparse
import json

import pytest
import torch

from tamp.cli import build_parser, main

CUDA = torch.cuda.is_available()
# every command that plans or runs the perception model
RUNS_TORCH = {
    "plan",
    "example",
    "plan-images",
    "run",
    "demo",
    "bench planbench",
    "bench pddl",
    "bench random",
    "bench motion",
    "bench executability",
    "bench perception",
    "bench latplan",
    "bench segmentation",
    "perception train",
    "perception eval",
}


def _commands(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*path, name))
            return
    yield " ".join(path), parser


def test_every_command_that_runs_torch_takes_device_and_defaults_to_the_cpu():
    commands = dict(_commands(build_parser()))
    have = {c for c, p in commands.items() if "--device" in p._option_string_actions}
    assert have == RUNS_TORCH
    args = build_parser().parse_args(["plan", "d.pddl", "p.pddl"])
    assert args.recorded(args)["device"] == "cpu"
    args = build_parser().parse_args(["perception", "eval", "x.npz"])
    assert args.recorded(args)["device"] == "cpu"


def test_the_device_is_recorded_in_the_json_and_results(tmp_path, capsys):
    assert main(["example", "--json", "--device", "cpu"]) == 0
    assert json.loads(capsys.readouterr().out)["config"]["device"] == "cpu"
    argv = ["bench", "random", "--blocks", "4", "--n", "1", "--restarts", "2", "--iters", "5"]
    assert main([*argv, "--device", "cpu", "--no-progress", "--out", str(tmp_path)]) == 0
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["config"]["device"] == "cpu"
    assert results["machine"]["device"] == "cpu" and results["machine"]["gpu"] is None


@pytest.mark.skipif(CUDA, reason="this machine has CUDA")
@pytest.mark.parametrize(
    "argv",
    [
        ["plan", "d.pddl", "p.pddl"],
        ["example"],
        ["bench", "random"],
        ["bench", "planbench"],
        ["perception", "eval", "x.npz"],
    ],
)
def test_cuda_where_there_is_none_is_one_line_and_exit_2(capsys, argv):
    assert main([*argv, "--device", "cuda"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    assert "--device" in err and "cuda" in err and "CUDA" in err, err


@pytest.mark.parametrize("name", ["tpu", "cuda:x", "gpu"])
def test_an_unknown_device_is_one_line_listing_the_valid_ones(capsys, name):
    assert main(["plan", "d.pddl", "p.pddl", "--device", name]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and f"unknown device {name!r} (valid: cpu, cuda, cuda:N)" in err


@pytest.mark.skipif(not CUDA, reason="needs a CUDA device")
def test_on_cuda_the_example_plans_there_and_says_so(capsys):
    assert main(["example", "--json", "--device", "cuda"]) == 0
    body = json.loads(capsys.readouterr().out)
    assert body["config"]["device"] == "cuda" and body["status"] == "solved"
