"""The command line's surface: every command, option, default and choice as the last release had
them (``fixtures/cli_surface.json``). A change here is a change users see: update the fixture
on purpose, never to make this pass."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from tamp.cli import build_parser

FIXTURE = Path(__file__).with_name("fixtures") / "cli_surface.json"
REPO = Path(__file__).resolve().parents[3]


def _plain(value: object) -> object:
    return value if isinstance(value, int | float | str | bool | type(None)) else repr(value)


def surface(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()) -> dict:
    """``{"bench planbench": {"--limit": {...}, ...}, ...}`` for a parser and its subparsers."""
    out, options = {}, {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                out |= surface(sub, (*path, name))
        elif not isinstance(action, argparse._HelpAction):
            key = ",".join(action.option_strings) or action.dest
            default = _plain(action.default)
            if isinstance(default, str):
                default = default.replace(str(REPO), "<repo>")
            options[key] = {
                "dest": action.dest,
                "default": default,
                "choices": list(action.choices) if action.choices else None,
                "nargs": action.nargs if isinstance(action.nargs, int | str | None) else None,
            }
    out[" ".join(path) or "tamp"] = options
    return out


def test_commands_and_options_are_unchanged():
    expected = json.loads(FIXTURE.read_text())
    actual = surface(build_parser())
    assert sorted(actual) == sorted(expected)
    for command, options in expected.items():
        assert actual[command] == options, command
