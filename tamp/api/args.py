"""The Python API's argument checks: what each argument of a `tamp.api` function must be.

Each public function of `tamp.api` declares its arguments' kinds with `checked`; a call with an
argument of the wrong kind raises one `task.errors.TampError` line naming the function, the
argument, what was given and what is expected, before any work (``api.plan: seed must be an
int, got '0' (str)``), instead of a Python error from deep inside the planner or the simulator.
Values of the right kind are checked further where they are used (a scene file's fields, a
problem's names). Types that live in heavy modules (`tamp.loop.LoopConfig`,
`tamp.bench.suites.Suite`) are imported when an argument is checked against them.
"""

from __future__ import annotations

import functools
import importlib
import inspect
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from numbers import Integral
from pathlib import Path

from task.errors import TampError

SHOWN = 60  # characters of a given value's repr in a message


@dataclass(frozen=True)
class Kind:
    """What an argument must be: ``what`` in words (``an int``), ``test`` of a value."""

    what: str
    test: Callable[[object], bool]

    def optional(self) -> Kind:
        """The same kind, or None."""
        return Kind(f"{self.what} or None", lambda v: v is None or self.test(v))


def _integer(value: object) -> bool:
    return isinstance(value, Integral) and not isinstance(value, bool)


def instance(what: str, *types: type) -> Kind:
    """An instance of one of ``types``."""
    return Kind(what, lambda v: isinstance(v, types))


def lazy(what: str, module: str, name: str) -> Kind:
    """An instance of ``module.name``, imported when a value is checked."""
    return Kind(what, lambda v: isinstance(v, getattr(importlib.import_module(module), name)))


def sequence_of(what: str, item: Callable[[object], bool]) -> Kind:
    """A non-empty list or tuple (any sequence but a string) whose items pass ``item``."""

    def test(value: object) -> bool:
        if isinstance(value, str | bytes) or not isinstance(value, Sequence) or not value:
            return False
        return all(item(v) for v in value)

    return Kind(what, test)


def _plan_steps(value: object) -> bool:
    """A list or tuple (empty: the empty plan) of `Action`, `Move` or step strings."""
    from task.problem import Action, Move

    return isinstance(value, list | tuple) and all(
        isinstance(v, Action | Move | str) for v in value
    )


INT = Kind("an int", _integer)
BOOL = instance("a bool", bool)
TEXT = instance("a str", str)
SOURCE = instance("PDDL text (str) or a PDDL file (pathlib.Path)", str, Path)
PATH = instance("a path (str or pathlib.Path)", str, Path)
SCENE_FILE = instance("a scene file (str or pathlib.Path) or a shipped scene's name", str, Path)
SCENE = instance(
    "a scene file (str or pathlib.Path), a shipped scene's name (str) or a scene dict",
    str,
    Path,
    Mapping,
)
GOAL = instance("a PDDL goal (str) or a goal file (pathlib.Path)", str, Path)
PLAN = Kind(
    "plan text (str), a plan file (pathlib.Path) or a list of steps (Action, Move or "
    "'(action args)' str)",
    lambda v: isinstance(v, str | Path) or _plan_steps(v),
)
PLANNER_CONFIG = lazy("a task.config.PlannerConfig", "task.config", "PlannerConfig")
LOOP_CONFIG = lazy("a tamp.loop.LoopConfig", "tamp.loop", "LoopConfig")
GEO_CONFIG = lazy("a tamp.geo.config.GeoEpisodeConfig", "tamp.geo.config", "GeoEpisodeConfig")
EPISODE_CONFIG = Kind(
    "a tamp.loop.LoopConfig or a tamp.geo.config.GeoEpisodeConfig",
    lambda v: LOOP_CONFIG.test(v) or GEO_CONFIG.test(v),
)
SUITE = lazy("a tamp.bench.suites.Suite (api.random_suite, ...)", "tamp.bench.suites", "Suite")
COSTS = Kind(
    "a CostSource: a callable (indices, states, restarts) -> WindowCosts, e.g. "
    "api.CostFunction (a FixedCosts is one window's costs, not a source)",
    callable,
)
CALLBACK = Kind("a callable", callable)
IMAGE = Kind(
    "an image file (str or pathlib.Path) or an RGB uint8 array (H, W, 3)",
    lambda v: isinstance(v, (str, Path, importlib.import_module("numpy").ndarray)),
)
INTS = sequence_of("a non-empty list or tuple of ints", _integer)
TEXTS = sequence_of("a non-empty list or tuple of str", lambda v: isinstance(v, str))


def shown(value: object) -> str:
    """``value`` for a one-line message: its repr on one line, cut, and its type."""
    text = " ".join(repr(value).split())
    text = text if len(text) <= SHOWN else text[: SHOWN - 3] + "..."
    return f"{text} ({type(value).__name__})"


def checked(**kinds: Kind) -> Callable:
    """Decorate a `tamp.api` function: each argument named in ``kinds`` is checked against its
    kind when the function is called (arguments left out keep their defaults, unchecked), and
    a call that does not fit the signature is one line too."""

    def wrap(function: Callable) -> Callable:
        signature = inspect.signature(function)
        unknown = sorted(set(kinds) - set(signature.parameters))
        if unknown:
            raise TypeError(f"{function.__name__} has no arguments {unknown}")
        where = f"api.{function.__name__}"

        @functools.wraps(function)
        def call(*args, **kwargs):
            try:
                bound = signature.bind(*args, **kwargs)
            except TypeError as exc:
                raise TampError(f"{where}: {exc}") from None
            for name, value in bound.arguments.items():
                kind = kinds.get(name)
                if kind is not None and not kind.test(value):
                    raise TampError(f"{where}: {name} must be {kind.what}, got {shown(value)}")
            return function(*args, **kwargs)

        return call

    return wrap
