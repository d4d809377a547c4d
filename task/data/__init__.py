"""soft-tamp's own embedded PDDL: the 4-operator blocksworld domain and a 5-block example, and
the logistics-strips and typed-sokoban domains (written out here; the same names and semantics as
PlanBench's) that `task.domains.logistics` and `task.domains.sokoban` recognise and write for.

The files ship as package data and are read through `importlib.resources`, so they work from a
source checkout, an installed wheel or a zip alike. ``DOMAIN_FILE`` is the domain that PlanBench
and generated instances (``:domain blocksworld-4ops``) validate against.
"""

from __future__ import annotations

from importlib import resources

from pddl.core import Domain

from task.errors import PDDLError, one_of
from task.symbolic import pddl_io

DOMAIN_FILE = "blocksworld-4ops.pddl"
EXAMPLE_FILE = "example-5.pddl"


def names() -> tuple[str, ...]:
    """The embedded PDDL files."""
    files = resources.files(__name__).iterdir()
    return tuple(sorted(f.name for f in files if f.name.endswith(".pddl")))


def read_text(name: str) -> str:
    """The text of the embedded file ``name``; PDDLError listing the embedded files otherwise."""
    if name not in names():
        raise PDDLError(f"no embedded PDDL file {one_of(name, names())}")
    return resources.files(__name__).joinpath(name).read_text(encoding="utf-8")


def source(name: str) -> str:
    """How an embedded file is named in messages, e.g. ``task.data/example-5.pddl``."""
    return f"{__name__}/{name}"


def domain() -> Domain:
    """The parsed embedded 4-operator blocksworld domain."""
    return pddl_io.parse_domain(read_text(DOMAIN_FILE), source(DOMAIN_FILE))
