"""What produced a benchmark's numbers: provenance in ``results.json`` and ``tamp bench record``."""

from __future__ import annotations

import json
import shlex
import subprocess
from pathlib import Path

import pytest

from tamp.bench import results
from tamp.bench.record import markdown, records
from tamp.bench.summary import Summary
from tamp.cli import main
from task.errors import DataError


def _git(root, *args: str) -> str:
    done = subprocess.run(
        ["git", "-C", str(root), "-c", "user.name=t", "-c", "user.email=t@t", *args],
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout.strip()


def test_git_state_reads_commit_and_dirty_and_none_outside_a_checkout(tmp_path):
    assert results.git_state(tmp_path) == (None, None)
    _git(tmp_path, "init", "-q")
    assert results.git_state(tmp_path) == (None, None)  # a repository without a commit
    (tmp_path / "a.txt").write_text("a\n")
    _git(tmp_path, "add", "a.txt")
    _git(tmp_path, "commit", "-q", "-m", "a")
    head = _git(tmp_path, "rev-parse", "HEAD")
    assert results.git_state(tmp_path) == (head, False)
    (tmp_path / "b.txt").write_text("untracked\n")
    assert results.git_state(tmp_path) == (head, True)
    (tmp_path / "b.txt").unlink()
    (tmp_path / "a.txt").write_text("changed\n")
    assert results.git_state(tmp_path) == (head, True)
    inner = tmp_path / "inner"  # code inside some other repository is not that repository's
    inner.mkdir()
    assert results.git_state(inner) == (None, None)


def test_a_benchmark_run_records_its_command_commit_and_machine(tmp_path):
    out = tmp_path / "run one"
    argv = ["bench", "random", "--blocks", "3", "--n", "1", "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    record = json.loads((out / "results.json").read_text())["machine"]
    assert record["command"] == "tamp " + shlex.join(argv)
    assert shlex.split(record["command"])[1:] == argv  # quoted: re-runnable as written
    assert (record["commit"], record["dirty"]) == results.git_state()
    assert record["cores"] and record["date"] and record["load_1min"] >= 0


def test_machine_without_a_command_line_records_none():
    assert results.machine()["command"] is None
    assert results.machine(["bench", "x"])["command"] == "tamp bench x"


REPO = Path(__file__).resolve().parents[3]
COMMIT = "0123456789abcdef0123456789abcdef01234567"


def _summary(seed: int | None, **figures) -> dict:
    base = dict(horizon=3, seed=seed, size=None, n=4, known=4, valid=3, optimal=2)
    base |= dict(optimal_pct=200 / 3, inexecutable=0, non_goal_reaching=0, no_plan=1)
    base |= dict(time_s=0.5, wall_s=2.0, windows=1.0)
    return Summary(**(base | figures)).asdict()


def _results(folder: Path, *, seeds=(0,), commit=COMMIT, dirty=False, command="tamp bench x"):
    """A planning benchmark's results.json as `tamp.bench.results.results` lays it out."""
    folder.mkdir(parents=True)
    rows = [_summary(s) for s in seeds]
    if len(seeds) > 1:
        rows.append(_summary(None, valid=3.5, no_plan=0.5, optimal_pct=50.0))
    rows.append(_summary(None, size=3, valid=1))  # a block-count row: never the headline
    body = {
        "benchmark": "planbench",
        "source": "tiny",
        "instances": 4,
        "seeds": list(seeds),
        "horizons": [3],
        "summary": rows,
        "machine": {
            "cores": 2,
            "processor": "x86_64",
            "python": "3.11",
            "torch": "2.x",
            "torch_threads": 1,
            "device": "cpu",
            "load_1min": 3.5,
            "date": "2026-12-01T10:00:00+00:00",
            "command": command,
            "commit": commit,
            "dirty": dirty,
        },
    }
    (folder / "results.json").write_text(json.dumps(body))
    return folder


def test_a_record_keeps_the_headline_figures_and_what_produced_them(tmp_path):
    r = records.extract(_results(tmp_path / "blocks"))
    assert (r.name, r.benchmark, r.instances, r.seeds) == ("blocks", "planbench", 4, (0,))
    assert (r.command, r.commit, r.dirty, r.date[:10]) == (
        "tamp bench x",
        COMMIT,
        False,
        "2026-12-01",
    )
    assert [f["valid"] for f in r.figures] == [3] and r.machine["load_1min"] == 3.5
    assert markdown.ours(r) == "3/4 valid (1 no plan), 66.7% optimal, 0.5 s/instance, 2 s in all"
    assert records.Record.from_json(json.loads(json.dumps(r.to_json()))) == r
    several = records.extract(_results(tmp_path / "seeds", seeds=(0, 1, 2)))
    assert [f["valid"] for f in several.figures] == [3.5]  # the mean over seeds
    assert markdown.ours(several).endswith("(mean of 3 seeds)") and "3.5/4 valid" in markdown.ours(
        several
    )


def test_a_dirty_run_is_marked_in_its_row_and_a_clean_one_is_not(tmp_path):
    clean = records.extract(_results(tmp_path / "clean"))
    dirty = records.extract(_results(tmp_path / "dirty", dirty=True))
    table = markdown.render([clean, dirty])
    lines = [line for line in table.splitlines() if line.startswith("| PlanBench")]
    assert ["uncommitted changes" in line for line in lines] == [False, True]
    assert "commit alone does not reproduce it" in table
    assert "uncommitted" not in markdown.render([clean])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"commit": None}, "records no git commit"),
        ({"command": None}, "records no command line"),
    ],
)
def test_a_results_folder_that_names_no_commit_or_command_is_refused(tmp_path, change, message):
    folder = _results(tmp_path / "old", **change)
    with pytest.raises(DataError, match=message):
        records.extract(folder)


def test_other_folders_are_refused_in_one_line(tmp_path):
    with pytest.raises(DataError, match=r"no results\.json"):
        records.extract(tmp_path)
    (tmp_path / "motion").mkdir()
    (tmp_path / "motion" / "results.json").write_text(json.dumps({"summary": {}, "machine": {}}))
    with pytest.raises(DataError, match="records no command"):
        records.extract(tmp_path / "motion")
    body = {"summary": {}, "machine": {"command": "tamp bench motion", "commit": COMMIT}}
    (tmp_path / "motion" / "results.json").write_text(json.dumps(body))
    with pytest.raises(DataError, match=r"not the results of a benchmark .*families: planning"):
        records.extract(tmp_path / "motion")
    (tmp_path / "motion" / "results.json").write_bytes(b"\x89PNG\x00")
    with pytest.raises(DataError, match="not JSON"):
        records.extract(tmp_path / "motion")


def test_a_latplan_record_reads_true_states_and_images_apart(tmp_path):
    folder = _results(tmp_path / "latplan")
    body = json.loads((folder / "results.json").read_text())
    spread = lambda m: {"mean": m, "min": m, "max": m}  # noqa: E731
    body |= {
        "benchmark": "latplan-40",
        "n": 40,
        "seeds": [0],
        "summary": [
            {
                "resolution": "150x100",
                "mode": "state",
                "n": 40,
                "valid": spread(40),
                "optimal": spread(40),
            },
            {
                "resolution": "150x100",
                "mode": "frozen",
                "n": 40,
                "valid": spread(40),
                "optimal": spread(39),
            },
            {
                "resolution": "45x30",
                "mode": "frozen",
                "n": 40,
                "valid": spread(38),
                "optimal": spread(38),
            },
        ],
    }
    (folder / "results.json").write_text(json.dumps(body))
    r = records.extract(folder)
    assert markdown.label(r) == "LatPlan-40"
    assert markdown.ours(r) == (
        "true states: 40/40 valid, 40/40 optimal; images (frozen 150x100, frozen 45x30): "
        "38-40/40 valid, 38-39/40 optimal"
    )
    assert "31/40 optimal" in markdown.render([r])  # the paper's figure beside ours


def _experiments(root: Path) -> None:
    """An experiments index under ``root`` (what `markdown.page` lists last)."""
    (root / "docs" / "experiments").mkdir(parents=True)
    index = "# Experiments\n\nintro\n\n- [A study](a.md): what it measured.\n"
    (root / "docs" / "experiments" / "index.md").write_text(index)


def test_bench_record_writes_the_page_whole_and_only_the_readme_block(tmp_path, capsys):
    _results(tmp_path / "runs" / "blocks")
    _results(tmp_path / "runs" / "more", seeds=(0, 1))
    _experiments(tmp_path)
    md, readme = tmp_path / "B.md", tmp_path / "R.md"
    md.write_text("stale, hand-typed\n")
    readme.write_text(f"# Title\n\nbefore\n{markdown.START}\nstale\n{markdown.END}\nafter\n")
    into = tmp_path / "current"
    argv = ["bench", "record", "--results", str(tmp_path / "runs"), "--into", str(into)]
    files = ["--markdown", str(md), "--readme", str(readme)]
    assert main([*argv, *files]) == 0  # a parent folder: each subfolder
    assert sorted(p.name for p in into.iterdir()) == ["blocks.json", "more.json"]
    loaded = records.load_all(into)
    page = md.read_text()
    assert page == markdown.page(loaded, tmp_path) and "stale" not in page
    assert markdown.block_of(page) == markdown.render(loaded)
    assert "[A study](docs/experiments/a.md): what it measured." in page  # links from the root
    text = readme.read_text()
    assert text.startswith("# Title\n\nbefore\n") and text.endswith("\nafter\n")
    assert "stale" not in text and markdown.block_of(text) == markdown.render(loaded)
    assert "wrote 2 record(s)" in capsys.readouterr().out
    assert main(["bench", "record", "--into", str(into), *files]) == 0
    assert (md.read_text(), readme.read_text()) == (page, text)  # same records, same text


def test_bench_record_checks_everything_before_writing(tmp_path, capsys):
    _results(tmp_path / "blocks")
    _experiments(tmp_path)
    md, readme = tmp_path / "B.md", tmp_path / "R.md"
    readme.write_text("# no markers\n")
    into = tmp_path / "current"
    argv = ["bench", "record", "--results", str(tmp_path / "blocks"), "--into", str(into)]
    assert main([*argv, "--markdown", str(md), "--readme", str(readme)]) == 2
    assert "no current-results markers" in capsys.readouterr().err
    assert not into.exists() and not md.exists() and readme.read_text() == "# no markers\n"
    assert main([*argv, "--markdown", str(md), "--readme", str(tmp_path / "missing.md")]) == 2
    elsewhere = tmp_path / "elsewhere" / "B.md"  # no docs/experiments/index.md beside it
    elsewhere.parent.mkdir()
    assert main([*argv, "--markdown", str(elsewhere), "--readme", ""]) == 2
    assert "index.md: cannot read" in capsys.readouterr().err and not into.exists()
    assert main(["bench", "record", "--results", str(tmp_path / "nothing")]) == 2
    assert "no results.json" in capsys.readouterr().err


def test_benchmarks_md_is_the_page_the_records_give():
    """BENCHMARKS.md, all of it, cannot drift from ``results/current`` and the experiments
    index: regenerate it with ``tamp bench record`` (from the repository root) after changing
    a record or a study."""
    loaded = records.load_all(REPO / "results" / "current")
    assert loaded, "results/current holds no records"
    for r in loaded:
        assert r.command.startswith("tamp bench ") and len(r.commit) == 40, r.name
    text = (REPO / "BENCHMARKS.md").read_text(encoding="utf-8")
    assert text == markdown.page(loaded, REPO), "BENCHMARKS.md differs: run tamp bench record"


def test_the_readme_results_block_is_the_one_the_records_give():
    loaded = records.load_all(REPO / "results" / "current")
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert markdown.block_of(text) == markdown.render(loaded), "run tamp bench record"


def test_every_study_is_indexed_and_every_family_without_a_record_names_studies_that_exist():
    folder = REPO / markdown.EXPERIMENTS
    studies = {p.name for p in folder.glob("*.md")} - {"index.md"}
    listed = markdown.experiments_index(REPO)
    assert sorted(studies) == sorted(
        line.split("](docs/experiments/")[1].split(")")[0] for line in listed
    )
    for s in markdown.STUDIED:
        assert s.command.startswith("tamp bench ") and f"--out results/{s.name}" in s.command
        assert set(s.studies) <= studies, s.name
    for path in folder.glob("*.md"):  # each study opens with a title and a header paragraph
        lines = path.read_text(encoding="utf-8").splitlines()
        assert lines[0].startswith("# ") and lines[1] == "" and lines[2], path.name


@pytest.mark.sim
def test_a_motion_run_is_recorded_with_its_figures_per_simulator(tmp_path):
    """A real (tiny) `bench motion` run: one random 3-block episode in PyBullet, about 10 s."""
    out = tmp_path / "motion"
    argv = ["bench", "motion", "--blocks", "3", "--n", "1", "--sim", "pybullet"]
    assert main([*argv, "--no-progress", "--out", str(out)]) == 0
    summary = json.loads((out / "results.json").read_text())["summary"]["pybullet"]
    r = records.extract(out)
    assert (r.family, r.benchmark, r.instances, r.seeds) == (
        records.Family.MOTION,
        "motion",
        1,
        (0,),
    )
    (row,) = r.figures
    assert row["sim"] == "pybullet" and set(row) == set(records.MOTION_FIGURES)
    assert all(row[k] == summary[k] for k in records.MOTION_FIGURES if k != "sim")
    goal = f"pybullet: {summary['goal_reached']}/1 goal reached"
    assert markdown.ours(r).startswith(goal) and f"{summary['moves_ok']}/{summary['moves']}" in (
        markdown.ours(r)
    )
    assert records.Record.from_json(json.loads(json.dumps(r.to_json()))) == r
    table = markdown.render([r])
    assert markdown.TITLES[records.Family.MOTION] in table and "Planning" not in table


@pytest.mark.sim
def test_a_tamp_run_is_recorded_with_its_figures_per_problem_planner_and_simulator(tmp_path):
    """A real (tiny) `bench tamp` run: one variant of `blocked`, ours, PyBullet, about 6 s."""
    out = tmp_path / "tamp"
    argv = ["bench", "tamp", "--problems", "blocked", "--n", "1", "--sim", "pybullet"]
    argv += ["--planner", "motion-aware", "--workers", "1", "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    (summary,) = json.loads((out / "results.json").read_text())["summary"]
    r = records.extract(out)
    assert (r.family, r.benchmark, r.instances, r.seeds) == (records.Family.TAMP, "tamp", 1, (0,))
    assert r.figures == ({k: summary[k] for k in records.TAMP_FIGURES},)
    solved, collided = summary["solved"], summary["collided"]
    assert markdown.ours(r) == (
        f"motion-aware, pybullet: {solved}/1 solved (blocked {solved}/1), {collided} collided"
    )
    assert markdown.label(r) == "Canonical problems, 1 variants each"
    assert records.Record.from_json(json.loads(json.dumps(r.to_json()))) == r


def test_a_partial_run_and_a_record_of_an_unknown_family_are_refused(tmp_path):
    folder = _results(tmp_path / "cut")
    body = json.loads((folder / "results.json").read_text()) | {"partial": {"done": 2, "of": 4}}
    (folder / "results.json").write_text(json.dumps(body))
    with pytest.raises(DataError, match=r"a partial run \(2 of 4 done"):
        records.extract(folder)
    into = tmp_path / "current"
    records.write(records.extract(_results(tmp_path / "blocks")), into)
    body = json.loads((into / "blocks.json").read_text()) | {"family": "dance"}
    (into / "blocks.json").write_text(json.dumps(body))
    with pytest.raises(DataError, match=r"blocks\.json: family 'dance' is not one of planning"):
        records.load_all(into)
