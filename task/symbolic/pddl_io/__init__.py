"""task.symbolic.pddl_io: PDDL in and out; domains and problems through the `pddl` library,
plans in the VAL format. This package's names below are its API
(``from task.symbolic import pddl_io``; ``pddl_io.parse_domain(...)``).

Every failure is one `PDDLError` line that names the file (or the ``source`` given for text).

- ``text``: reading files in the encodings other tools save (`read_text`);
- ``tree``: PDDL text as nested lists with offsets and lines (what the styles and checks read);
- ``style``: PDDL as other tools write it, read as they mean it before the grammar sees it;
- ``strips_check``: the first construct the planners cannot plan with (`check_strips`);
- ``parse``: domains and problems parsed through the `pddl` grammar (`parse_domain`,
  `parse_problem`, `load_domain`, `load_problem`, `object_order`, `problem_with`);
- ``names``: the names check of a problem's atoms against its domain (predicates, arities,
  objects);
- ``plan_file``: the one plan reader of the project (`parse_plan_lines`) and plan text in the
  VAL format (`format_plan`, `write_plan`).
"""

from task.symbolic.pddl_io.parse import (
    load_domain,
    load_object_order,
    load_problem,
    object_order,
    parse_domain,
    parse_problem,
    problem_with,
)
from task.symbolic.pddl_io.plan_file import (
    PlanLine,
    format_plan,
    parse_plan,
    parse_plan_lines,
    read_plan,
    read_plan_lines,
    write_plan,
)
from task.symbolic.pddl_io.strips_check import check_strips
from task.symbolic.pddl_io.text import read_text

__all__ = [
    "PlanLine",
    "check_strips",
    "format_plan",
    "load_domain",
    "load_object_order",
    "load_problem",
    "object_order",
    "parse_domain",
    "parse_plan",
    "parse_plan_lines",
    "parse_problem",
    "problem_with",
    "read_plan",
    "read_plan_lines",
    "read_text",
    "write_plan",
]
