"""Optimal plan lengths from Fast Downward, for benchmark sets whose data lack them.

Benchmark-only: nothing at plan time and no default test needs it. It runs the Fast Downward
build that the PyPI package ``up-fast-downward`` bundles (``pip install 'soft-tamp[bench]'``) as
subprocesses, in a temporary directory that is always removed:

1. ``fast-downward.py --translate DOMAIN PROBLEM`` writes the SAS+ task;
2. its metric line is set to 0, so every action costs 1 even where the PDDL has action costs;
3. ``fast-downward.py --search`` runs the `SEARCHES` one after the other, each on an equal share
   of the CPU time left, until one finds a plan or proves there is none. Both are A* with an
   admissible heuristic, so the plan is one of minimum *length*: merge-and-shrink (bisimulation,
   SCC-DFP merging, 50k states: exact on gripper, strong on Sokoban) and then LM-cut (what
   ``--alias seq-opt-lmcut`` runs: strong on Logistics and Miconic).

Time limits are CPU seconds (Fast Downward's own), memory limits an address-space cap; a
wall-clock guard (`GUARD_FACTOR`) kills the process group if the machine stalls. ``optimal_lengths``
caches results in a JSON file keyed by the domain and problem texts: a rerun costs nothing.
`lama_length` runs LAMA's first plan (``--alias lama-first``, satisficing, not optimal) for a
classical planner's length and time beside ours (``tamp bench random --lama``).
"""

from __future__ import annotations

import contextlib
import importlib.util
import math
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from tamp.bench.optimal import digest, read_cache, write_cache
from task.errors import DataError

PACKAGE = "up-fast-downward==1.0.0"
_MERGE_AND_SHRINK = (
    "astar(merge_and_shrink(merge_strategy=merge_sccs(order_of_sccs=topological,merge_selector="
    "score_based_filtering(scoring_functions=[goal_relevance(),dfp(),total_order()])),"
    "shrink_strategy=shrink_bisimulation(greedy=false),label_reduction=exact("
    "before_shrinking=true,before_merging=false),max_states=50000,threshold_before_merge=1))"
)
SEARCHES = (("merge-and-shrink", _MERGE_AND_SHRINK), ("lmcut", "astar(lmcut())"))
METHOD = f"Fast Downward ({PACKAGE}), unit costs, " + " then ".join(c for _, c in SEARCHES)
STATUSES = ("optimal", "solved", "unsolvable", "timeout", "memout", "error")  # solved: LAMA
GUARD = "killed by the wall-clock guard"  # results whose detail says so are never cached
GUARD_FACTOR = 5  # wall-clock guard: 5 x the CPU limit + 60 s (2 busy cores can stretch it)
# Fast Downward's exit codes (https://www.fast-downward.org/latest/documentation/exit-codes/);
# a component killed at the hard CPU limit makes the driver exit with 256 - signal.
_EXIT = {10: "unsolvable", 11: "unsolvable", 20: "memout", 21: "timeout", 22: "memout"}
_EXIT |= {23: "timeout", 24: "memout", 247: "timeout", 232: "timeout"}  # 256 - SIGKILL, SIGXCPU


@dataclass(frozen=True)
class FDResult:
    """One problem: ``length`` (actions in an optimal plan; None unless status is "optimal"),
    ``status`` (one of `STATUSES`), ``seconds`` (CPU seconds of all of Fast Downward's
    processes; wall seconds after a guard kill) and ``detail`` (one line: the exit code, and
    Fast Downward's message when unsolvable or an error)."""

    length: int | None
    status: str
    seconds: float
    detail: str


def _driver() -> Path | None:
    """``fast-downward.py`` inside the installed ``up_fast_downward`` (found without importing
    it, which would import unified-planning), or None when the package or its build is missing."""
    spec = importlib.util.find_spec("up_fast_downward")
    if spec is None or not spec.submodule_search_locations:
        return None
    root = Path(next(iter(spec.submodule_search_locations))) / "downward"
    paths = (root / "fast-downward.py", root / "builds" / "release" / "bin" / "downward")
    return paths[0] if all(p.is_file() for p in paths) else None


def available() -> bool:
    """Whether the ``bench`` extra (``up-fast-downward``) is installed with its binaries."""
    return _driver() is not None


def _require_driver() -> Path:
    if (driver := _driver()) is None:
        extra = f"pip install 'soft-tamp[bench]' (the package {PACKAGE})"
        raise DataError(f"Fast Downward is not installed: it is a benchmark-only extra, {extra}")
    return driver


def _read(path: str | Path) -> str:
    """A PDDL file's text; one-line DataError if it cannot be read."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise DataError(f"{path}: cannot read the PDDL file ({exc.strerror or exc})") from None


def _call(
    args: list[str], cwd: Path, deadline: float, stop: threading.Event | None = None
) -> tuple[int | None, float]:
    """Run ``python args`` in its own process group; (exit code, CPU seconds it used).

    Past the wall-clock ``deadline``, or once ``stop`` is set, the whole group is killed and the
    code is None; so is it, before the exception goes on, on an interrupt (Ctrl-C).
    """
    with open(cwd / "log.txt", "a", encoding="utf-8") as log:
        proc = subprocess.Popen(
            [sys.executable, *args],
            cwd=cwd,
            stdout=log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )
    try:
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid != 0:
                proc.returncode = os.waitstatus_to_exitcode(status)
                return proc.returncode, usage.ru_utime + usage.ru_stime
            if time.monotonic() > deadline or (stop is not None and stop.is_set()):
                os.killpg(proc.pid, signal.SIGKILL)
                _, _, usage = os.wait4(proc.pid, 0)
                proc.returncode = -signal.SIGKILL
                return None, usage.ru_utime + usage.ru_stime
            time.sleep(0.02)
    finally:
        if proc.returncode is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def _unit_costs(sas: Path) -> None:
    """Set the SAS+ task's metric flag to 0: Fast Downward then counts every action as 1."""
    lines = sas.read_text(encoding="utf-8").split("\n")
    lines[lines.index("begin_metric") + 1] = "0"
    sas.write_text("\n".join(lines), encoding="utf-8")


def _last_message(log: Path) -> str:
    """The last informative lines Fast Downward printed (its error, usually), on one line."""
    skip = ("[t=", "INFO", "Peak memory", "Driver aborting", "translate exit", "search exit")
    lines = log.read_text(encoding="utf-8", errors="replace").splitlines()
    useful = [s.strip() for s in lines if s.strip() and not s.startswith(skip)]
    return " | ".join(useful[-3:])[:300] if useful else "no output"


def _outcome(
    code: int | None, seconds: float, start: float, work: Path, step: str, found: str = "optimal"
) -> FDResult:
    """The result of a run that stopped at ``step`` with exit ``code`` after ``seconds`` of CPU
    (``code`` None: a guard kill, timed in wall seconds since ``start``); a plan is ``found``."""
    if code is None:
        wall = time.monotonic() - start
        return FDResult(None, "timeout", wall, f"{step} {GUARD} after {wall:.0f} s wall")
    plan = work / "plan.txt"
    if code == 0 and plan.is_file():  # one action a line, then "; cost = ..." comments
        lines = plan.read_text(encoding="utf-8").splitlines()
        length = sum(1 for s in lines if s.strip() and not s.lstrip().startswith(";"))
        return FDResult(length, found, seconds, f"{step} exit 0: {found} plan")
    status = _EXIT.get(code, "error")
    detail = f"{step} exit {code}"
    if status in ("unsolvable", "error"):
        detail += f": {_last_message(work / 'log.txt')}"
    return FDResult(None, status, seconds, detail)


@contextlib.contextmanager
def _folder(domain: str, problem: str):
    """A temporary folder holding ``domain.pddl`` and ``problem.pddl``; removed afterwards."""
    with tempfile.TemporaryDirectory(prefix="fast-downward-") as tmp:
        (Path(tmp) / "domain.pddl").write_text(domain, encoding="utf-8")
        (Path(tmp) / "problem.pddl").write_text(problem, encoding="utf-8")
        yield Path(tmp)


def lama_length(
    domain: str, problem: str, time_limit_s: float = 60.0, memory_mb: int = 4096
) -> FDResult:
    """LAMA's first plan (``--alias lama-first``) for the PDDL texts ``domain`` and ``problem``:
    status "solved" with its length in actions, or why not; ``seconds``: CPU seconds of the
    translator and the search. One-line DataError if the ``bench`` extra is missing."""
    driver, limit = _require_driver(), max(1, math.ceil(time_limit_s))
    start = time.monotonic()
    with _folder(domain, problem) as work:
        args = [str(driver), "--alias", "lama-first", "--plan-file", "plan.txt"]
        args += ["--overall-time-limit", f"{limit}s", "--overall-memory-limit", f"{memory_mb}M"]
        code, spent = _call([*args, "domain.pddl", "problem.pddl"], work, start + 2 * limit + 60)
        return _outcome(code, spent, start, work, "lama-first", "solved")


def _solve(
    driver: Path,
    domain: str,
    problem: str,
    time_limit_s: float,
    memory_mb: int,
    stop: threading.Event | None = None,
) -> FDResult:
    """Translate, switch to unit costs, run `SEARCHES`; inside a temporary directory."""
    limit = max(1, math.ceil(time_limit_s))
    start = time.monotonic()
    deadline = start + GUARD_FACTOR * limit + 60
    with _folder(domain, problem) as work:
        memory = ["--overall-memory-limit", f"{memory_mb}M"]
        translate = [str(driver), "--translate", "--sas-file", "task.sas"]
        translate += ["--translate-time-limit", f"{limit}s", *memory, "domain.pddl", "problem.pddl"]
        code, spent = _call(translate, work, deadline, stop)
        if code != 0:
            return _outcome(code, spent, start, work, "translate")
        _unit_costs(work / "task.sas")
        details = []
        for k, (name, config) in enumerate(SEARCHES):
            left = max(1, round((limit - spent) / (len(SEARCHES) - k)))
            search = [str(driver), "--search", "--plan-file", "plan.txt", "--search-time-limit"]
            search += [f"{left}s", *memory, "task.sas", "--search", config]
            code, more = _call(search, work, deadline, stop)
            spent += more
            result = _outcome(code, spent, start, work, name)
            details.append(result.detail)
            if code is None or result.status in ("optimal", "unsolvable"):
                break
        return replace(result, detail="; ".join(details))


def optimal_length(
    domain_path: str | Path,
    problem_path: str | Path,
    time_limit_s: float = 60.0,
    memory_mb: int = 4096,
) -> FDResult:
    """The optimal plan length (number of actions) of one PDDL problem, by Fast Downward.

    One-line DataError if the ``bench`` extra is missing or a file cannot be read; everything
    Fast Downward reports (unsolvable, out of time or memory, a PDDL it rejects) is a status.
    """
    driver = _require_driver()
    domain, problem = _read(domain_path), _read(problem_path)
    return _solve(driver, domain, problem, time_limit_s, memory_mb)


def _reusable(entry: object, time_limit_s: float) -> FDResult | None:
    """A cached result that a run with ``time_limit_s`` would not change, else None: proofs
    (optimal, unsolvable) always, a timeout or memout only if it had at least as much time."""
    try:
        result = FDResult(**{k: entry[k] for k in ("length", "status", "seconds", "detail")})
        enough = float(entry["time_limit_s"]) >= time_limit_s
    except (KeyError, TypeError, ValueError):
        return None
    proof = result.status in ("optimal", "unsolvable")
    return result if proof or (enough and result.status in ("timeout", "memout")) else None


def optimal_lengths(
    pairs: Sequence[tuple[str | Path, str | Path]],
    cache_path: str | Path | None,
    time_limit_s: float = 60.0,
    progress: Callable[[int], None] | None = None,
    workers: int = 1,
    memory_mb: int = 4096,
) -> list[FDResult]:
    """Optimal lengths of ``(domain_path, problem_path)`` pairs, in order.

    With ``cache_path`` (a JSON file), results are looked up by the digest of both texts and new
    ones are written back after each problem, so an interrupted run keeps what it finished.
    ``workers`` problems run at once (each is its own process group; the threads only wait).
    ``progress(k)``: k more problems done (cache hits are reported at once). Errors and guard
    kills are not cached; an interrupt kills the running Fast Downward processes.
    """
    driver = _require_driver()
    report = progress or (lambda k: None)
    texts = [(_read(d), _read(p)) for d, p in pairs]
    keys = [digest(f"{digest(d)}:{digest(p)}") for d, p in texts]
    path = None if cache_path is None else Path(cache_path)
    entries = {} if path is None else read_cache(path, METHOD, "problems")
    results: list[FDResult | None] = [_reusable(entries.get(k), time_limit_s) for k in keys]
    todo = [i for i, r in enumerate(results) if r is None]
    report(len(keys) - len(todo))
    stop = threading.Event()
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        run = [(_solve, driver, *texts[i], time_limit_s, memory_mb, stop) for i in todo]
        jobs = {pool.submit(*job): i for job, i in zip(run, todo, strict=True)}
        pending = set(jobs)
        try:
            while pending:  # a timed wait, so that Ctrl-C reaches the main thread at once
                done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
                for job in done:
                    results[jobs[job]] = result = job.result()
                    if path and result.status != "error" and GUARD not in result.detail:
                        entries[keys[jobs[job]]] = {**asdict(result), "time_limit_s": time_limit_s}
                        write_cache(path, entries, METHOD, "problems")
                    report(1)
        except BaseException:
            stop.set()
            pool.shutdown(cancel_futures=True)
            raise
    return [r for r in results if r is not None]
