"""One outcome vocabulary (`tamp.outcome`): both executors, their failure memories and both
episodes name a failure or a status by one enum member, spelled once (that no import circle
joins the executors is `tests/test_layout.py`'s)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import tamp.loop.geo_fallback
from tamp.episode_report import EpisodeReport
from tamp.geo.check import FAILURES
from tamp.geo.episode import AGAIN_FROM_HOME, MoveRecord
from tamp.geo.ours.planner import BEFORE_GRASPS, FIXED_FAILURES
from tamp.loop import EpisodeStatus as LoopStatus
from tamp.loop.execute import GEO_RETRIED
from tamp.outcome import EpisodeStatus, Failure

ROOT = Path(__file__).resolve().parents[2]
# where a failure or a status is made, remembered or compared: no spelling of one as a string
SOURCES = (
    *sorted((ROOT / "tamp/geo").rglob("*.py")),
    ROOT / "tamp/loop/geo_fallback.py",
    ROOT / "tamp/loop/execute.py",
    ROOT / "tamp/loop/episode.py",
    ROOT / "tamp/loop/recover.py",
)
# every spelling in use, and the geometric room's old ones
SPELLINGS = {f.value for f in Failure} | {s.value for s in EpisodeStatus}
OLD = {"missed_grasp", "reached"}


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_failure_or_status_is_spelled_as_a_string(path):
    """A failure kind or a status is an enum member where it is made, remembered or compared;
    its string lives only in `tamp.outcome` (no table maps one room's words to the other's)."""
    tree = ast.parse(path.read_text())
    docstrings = {
        id(n.body[0].value)
        for n in ast.walk(tree)
        if isinstance(n, ast.Module | ast.ClassDef | ast.FunctionDef) and ast.get_docstring(n)
    }
    names = {  # attribute names (a config field called "collision"), no failure's spelling
        id(n.args[1])
        for n in ast.walk(tree)
        if isinstance(n, ast.Call)
        and isinstance(n.func, ast.Attribute)
        and n.func.attr == "__setattr__"
        and len(n.args) > 1
    }
    spelled = sorted(
        (n.lineno, n.value)
        for n in ast.walk(tree)
        if isinstance(n, ast.Constant)
        and n.value in SPELLINGS | OLD
        and id(n) not in docstrings | names
    )
    assert not spelled, spelled


def test_the_rooms_sets_of_failures_are_members_of_the_one_enum():
    assert not hasattr(tamp.loop.geo_fallback, "FAILURES")  # the string table of the old mapping
    for group in (FAILURES, AGAIN_FROM_HOME, FIXED_FAILURES, BEFORE_GRASPS, GEO_RETRIED):
        assert group and all(isinstance(f, Failure) for f in group), group


def test_both_episodes_report_in_one_status_enum():
    assert LoopStatus is EpisodeStatus
    assert EpisodeReport.__dataclass_fields__["status"].type == "EpisodeStatus"
    assert MoveRecord.__dataclass_fields__["failure"].type == "Failure | None"
    assert EpisodeStatus.GOAL_REACHED.value == "goal_reached"
    assert len({s.value for s in EpisodeStatus}) == len(EpisodeStatus)
    assert len({f.value for f in Failure}) == len(Failure)
