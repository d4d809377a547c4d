"""Docs that cannot drift: the command-line reference is the parser's, the site builds without
a warning, the README's Python snippet runs, its results table is BENCHMARKS.md's, and every
output column and goal-loss kind the code has is explained in the user guide."""

from __future__ import annotations

import dataclasses
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tamp.bench.executability import PlanRow
from tamp.bench.motion import EPISODE_COLUMNS
from tamp.bench.planning import INSTANCE_COLUMNS
from tamp.bench.record import markdown
from tamp.cli.options import GOAL_LOSSES
from tamp.cli.reference import COMMAND, reference

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"


def test_the_cli_reference_is_the_parsers():
    committed = (DOCS / "cli.md").read_text(encoding="utf-8")
    assert committed == reference(), f"docs/cli.md differs from the parser: run {COMMAND}"


def test_the_cli_reference_names_every_command_and_option():
    text = reference()
    for command in ("tamp plan", "tamp run", "tamp bench planbench", "tamp perception train"):
        assert f"## {command}\n" in text
    for option in ("`--goal-loss`", "`--motion-aware`", "`--lama`", "`--plan`", "`--json`"):
        assert option in text
    assert str(ROOT) not in text  # machine-independent: the checkout's path is <repo>


@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None, reason="needs the docs extra")
def test_the_docs_build_without_a_warning(tmp_path):
    site = tmp_path / "site"
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert (site / "cli" / "index.html").is_file() and (site / "api" / "index.html").is_file()


def test_every_docs_page_is_in_the_site_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    for page in DOCS.rglob("*.md"):
        assert str(page.relative_to(DOCS)) in nav, f"{page} is not in mkdocs.yml's nav"


def _snippets(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


@pytest.mark.sim
def test_the_readme_python_snippet_runs():
    (snippet,) = _snippets(README.read_text(encoding="utf-8"))
    env = os.environ | {"OMP_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", snippet], cwd=ROOT, env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert "valid plan of" in done.stdout and "goal_reached True" in done.stdout


def test_the_api_page_opens_with_the_readme_snippet():
    (readme,) = _snippets(README.read_text(encoding="utf-8"))
    assert readme == _snippets((DOCS / "api.md").read_text(encoding="utf-8"))[0]


def test_the_readme_results_table_is_benchmarks_md_current_table():
    readme = README.read_text(encoding="utf-8")
    benchmarks = (ROOT / "BENCHMARKS.md").read_text(encoding="utf-8")
    assert markdown.block_of(readme) == markdown.block_of(benchmarks), (
        "README.md's current-results table differs from BENCHMARKS.md's: run tamp bench record"
    )


def test_the_readme_stays_short_and_links_pages_that_exist():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 200
    for link in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text):
        if not link.startswith("http"):
            assert (ROOT / link).exists(), f"README links {link}, which does not exist"


def test_every_output_column_is_explained():
    """The columns of instances.csv (lama_* and best_known included), episodes.csv and plans.csv."""
    guide = (DOCS / "guide" / "benchmarks.md").read_text() + (
        DOCS / "guide" / "evaluating.md"
    ).read_text()
    columns = list(INSTANCE_COLUMNS) + list(EPISODE_COLUMNS)
    columns += [f.name for f in dataclasses.fields(PlanRow)]
    missing = [c for c in columns if f"`{c}`" not in guide]
    assert not missing, f"docs/guide: no word on column(s) {missing}"


def test_every_goal_loss_kind_is_explained():
    planning = (DOCS / "guide" / "planning.md").read_text()
    missing = [k for k in GOAL_LOSSES if f"`{k}`" not in planning]
    assert not missing, f"docs/guide/planning.md: no word on --goal-loss {missing}"
