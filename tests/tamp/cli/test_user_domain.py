"""``tamp run --scene FILE --domain D.pddl --binding B.json --goal G``: a user's own
pick-and-place domain runs at motion level (the example tray domain, the shipped tray scene),
its state read from the scene's geometry; what cannot run is refused in one line before any
work."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tamp.cli import build_parser, main

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "domains"
DOMAIN, BINDING = str(EXAMPLES / "tray.pddl"), str(EXAMPLES / "tray.binding.json")
GOAL = "(and (in a tray) (on b a))"


def _argv(*extra: str) -> list[str]:
    return ["run", "--scene", "tray", "--domain", DOMAIN, "--binding", BINDING, *extra]


@pytest.mark.sim
def test_the_example_domain_reaches_its_goal_in_the_tray_scene(tmp_path):
    out = tmp_path / "out"
    assert main([*_argv("--goal", GOAL), "--out", str(out), "--no-video"]) == 0
    body = json.loads((out / "report.json").read_text())
    report, config = body, body["config"]
    assert report["reached_goal"] and report["collisions"] == 0
    assert [m["move"].split(" at ")[0] for m in report["moves"]][1:] == [
        "move a -> tray",
        "move b -> a",
    ]
    assert config["domain"] == "tray-pick-place" and config["binding"] == BINDING
    assert config["domain_file"] == DOMAIN and config["planner"] == "motion-aware"
    assert "a user's pick-and-place domain" in config["why"]


def test_a_toml_binding_records_like_the_json_one(tmp_path):
    data = json.loads(Path(BINDING).read_text())
    lines = [f'domain = "{data["domain"]}"']
    for name, entry in data["actions"].items():
        lines += [f"[actions.{name}]", *(f'{k} = "{v}"' for k, v in entry.items())]
    lines += ["[scene]", 'objects = "item"', 'regions = "region"', "[scene.facts]"]
    lines += [f'{k} = "{v}"' for k, v in data["scene"]["facts"].items()]
    path = tmp_path / "tray.binding.toml"
    path.write_text("\n".join(lines) + "\n")
    args = build_parser().parse_args(
        ["run", "--scene", "tray", "--domain", DOMAIN, "--binding", str(path), "--goal", GOAL]
    )
    assert args.recorded(args)["domain"] == "tray-pick-place"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["run", "--scene", "tray", "--binding", BINDING, "--goal", GOAL],
            "--binding needs --domain",
        ),
        (["run", "--domain", DOMAIN, "--binding", BINDING], "--binding needs --scene FILE.json"),
        (["run", "--scene", "tray", "--domain", DOMAIN, "--goal", GOAL], "--domain needs PROBLEM"),
        (_argv("--goal", GOAL, "--geo-planner", "search"), "a user's domain is planned by"),
        (_argv("--goal", "(on a zz)"), "unknown object 'zz'"),
        (_argv(), "needs --goal"),
        (_argv("--goal", "(ontable c)", "--binding", "nope.json"), "nope.json"),
        (_argv("--goal", "(ontable c)", "--binding", DOMAIN), "a binding file ends in"),
        (_argv("--goal", "(clear c)", "--domain", BINDING), BINDING),
        (["run", "p.pddl", "--domain", DOMAIN, "--binding", BINDING], "--binding with PROBLEM"),
    ],
)
def test_what_cannot_run_is_refused_in_one_line(tmp_path, capsys, argv, expected):
    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err, err
    assert not (tmp_path / "out").exists()


def test_a_goal_the_binding_cannot_write_is_refused(tmp_path, capsys):
    data = json.loads(Path(BINDING).read_text())
    del data["scene"]["facts"]["clear"]
    path = tmp_path / "b.json"
    path.write_text(json.dumps(data))
    argv = ["run", "--scene", "tray", "--domain", DOMAIN, "--binding", str(path)]
    assert main([*argv, "--goal", "(clear c)"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "goal (clear c): the binding's scene facts do not write" in err


@pytest.mark.sim
def test_the_python_api_runs_the_example_domain_in_mujoco():
    from tamp import api

    report = api.run("tray", GOAL, sim="mujoco", domain=DOMAIN, binding=BINDING)
    assert report.reached_goal and report.collisions == 0


def test_the_api_refuses_a_domain_without_its_binding():
    from tamp import api
    from task.errors import TampError

    with pytest.raises(TampError, match="domain and binding go together"):
        api.run("tray", GOAL, domain=DOMAIN)
