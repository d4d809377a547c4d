"""The handlers the ``tamp`` parser binds to its commands: each imports its command's module
(torch, simulators) only when the command runs, so ``tamp --help`` and usage errors stay fast.
`lazy` calls a command with the parsed namespace; `at_edge` calls it with the typed settings that
the command's edge (`tamp.cli.settings`) builds from the namespace.
"""

from __future__ import annotations

import argparse


def at_edge(edge: str, then: str):
    """``then`` (a dotted function name) of the typed settings that ``edge`` builds from the
    parsed options: ``edge`` is the one function of its command that reads the namespace; both
    imported when the command runs."""

    def handler(args: argparse.Namespace):
        return _imported(then)(_imported(edge)(args))

    handler.__qualname__ = f"{then}({edge})"
    return handler


def _imported(dotted: str):
    """The function ``package.module.name``, its module imported now."""
    from importlib import import_module

    module, name = dotted.rsplit(".", 1)
    return getattr(import_module(module), name)


def lazy(module: str, name: str):
    """A handler that imports ``module`` (torch, simulators) only when its command runs."""

    def handler(args: argparse.Namespace) -> int:
        from importlib import import_module

        return getattr(import_module(module), name)(args)

    handler.__qualname__ = f"{module}.{name}"
    return handler
