"""pyperplan's greedy best-first search with the FF heuristic (``-s gbf -H hff``) on one PDDL
problem, as a subprocess under a wall-clock limit (pyperplan has none of its own).

Benchmark-only: the PyPI package ``pyperplan`` comes with the ``bench`` extra. Each run works in
a temporary folder (always removed) holding copies of the domain and problem, where pyperplan
writes its plan (``problem.pddl.soln``, one action a line); the process group is killed at the
limit.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from task.errors import DataError

PACKAGE = "pyperplan==2.1"
STATUSES = ("solved", "unsolved", "timeout", "error")  # unsolved: the search space ran out


@dataclass(frozen=True)
class GBFResult:
    """One problem: ``length`` (actions in pyperplan's plan; None unless "solved"), ``status``
    (one of `STATUSES`), ``seconds`` (wall seconds, parsing and grounding included) and
    ``detail`` (one line: the exit code, or pyperplan's last message)."""

    length: int | None
    status: str
    seconds: float
    detail: str


def available() -> bool:
    """Whether pyperplan is installed (found without importing it)."""
    return importlib.util.find_spec("pyperplan") is not None


def require() -> None:
    """One-line DataError naming the extra to install when pyperplan is missing."""
    if not available():
        extra = f"pip install 'soft-tamp[bench]' (the package {PACKAGE})"
        raise DataError(f"pyperplan is not installed: it is a benchmark-only extra, {extra}")


def _last_line(log: Path) -> str:
    lines = [s.strip() for s in log.read_text(encoding="utf-8", errors="replace").splitlines()]
    useful = [s for s in lines if s]
    return useful[-1][:300] if useful else "no output"


def gbf_hff(domain: str, problem: str, time_limit_s: float = 60.0) -> GBFResult:
    """pyperplan's GBF + h_FF plan for the PDDL texts ``domain`` and ``problem`` within
    ``time_limit_s`` wall seconds; every outcome is a status (DataError only when pyperplan is
    not installed)."""
    require()
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="pyperplan-") as tmp:
        work = Path(tmp)
        (work / "domain.pddl").write_text(domain, encoding="utf-8")
        (work / "problem.pddl").write_text(problem, encoding="utf-8")
        args = [sys.executable, "-m", "pyperplan", "-s", "gbf", "-H", "hff"]
        args += ["domain.pddl", "problem.pddl"]
        with open(work / "log.txt", "w", encoding="utf-8") as log:
            proc = subprocess.Popen(
                args,
                cwd=work,
                stdout=log,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                start_new_session=True,
            )
        try:
            code = proc.wait(timeout=time_limit_s)
        except subprocess.TimeoutExpired:
            code = None
        finally:
            if proc.returncode is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        seconds = time.monotonic() - start
        if code is None:
            return GBFResult(None, "timeout", seconds, f"killed at {time_limit_s:g} s wall")
        plan = work / "problem.pddl.soln"
        if code == 0 and plan.is_file():
            lines = plan.read_text(encoding="utf-8").splitlines()
            length = sum(1 for s in lines if s.strip() and not s.lstrip().startswith(";"))
            return GBFResult(length, "solved", seconds, "exit 0: plan")
        status = "unsolved" if code == 0 else "error"
        return GBFResult(None, status, seconds, f"exit {code}: {_last_line(work / 'log.txt')}")
