"""Episodes as Rerun recordings (`tamp.rerun_log`): ``tamp run --record FILE.rrd`` writes one
that Rerun's own reader reads back with every expected entity on the simulated time line; the
benchmarks' ``--record`` writes one per episode under ``--out``; without the ``rerun`` extra the
option is a one-line error naming it; and a recording changes nothing the episode does."""

from __future__ import annotations

import itertools
import json
import sys
from collections import defaultdict
from pathlib import Path

import pytest

from tamp.cli import main
from tamp.loop import Episode, LoopConfig
from tamp.rerun_log import TIMELINE, RecordingError, episode_file, require_rerun
from task.problem import TABLE, Problem

TWO = "(define (problem two) (:domain blocksworld-4ops) (:objects a b)\n"
TWO += "(:init (handempty) (ontable a) (ontable b) (clear a) (clear b))\n"
TWO += "(:goal (and (on a b))))\n"
# what a recording of a state-observed episode holds on the simulated time line
TIMED = (
    "/world/objects",
    "/belief/support",
    "/belief/state",
    "/plan/moves",
    "/plan/length",
    "/plan/cost",
    "/arm/joints",
    "/arm/planned_joints",
    "/arm/tcp",
    "/arm/tcp_path",
    "/arm/planned_tcp",
    "/gripper/width",
    "/gripper/force",
    "/checks/moves",
    "/checks/contacts",
    "/events",
    "/episode",
)


def _entities(path: Path) -> tuple[dict[str, int], dict[str, set[str]]]:
    """Rows per entity path, and the time lines each is on, read with Rerun's own reader."""
    from rerun.chunk import RrdReader

    rows, timelines = defaultdict(int), defaultdict(set)
    for chunk in RrdReader(path).stream():
        rows[chunk.entity_path] += chunk.num_rows
        timelines[chunk.entity_path] |= set(chunk.timeline_names)
    return dict(rows), dict(timelines)


@pytest.mark.sim
def test_tamp_run_record_writes_a_recording_rerun_reads_back(tmp_path, capsys):
    pytest.importorskip("rerun")
    problem, rrd = tmp_path / "two.pddl", tmp_path / "rec" / "two.rrd"
    problem.write_text(TWO)
    code = main(["run", str(problem), "--record", str(rrd), "--json"])
    assert code == 0
    body = json.loads(capsys.readouterr().out)
    assert body["config"]["record"] == str(rrd)
    rows, timelines = _entities(rrd)
    missing = [e for e in TIMED if TIMELINE not in timelines.get(e, ())]
    assert not missing, f"not on the {TIMELINE} time line: {missing}; got {sorted(rows)}"
    assert timelines["/arm/joints"] == {TIMELINE}  # the simulated time line only
    # frames every 50 ms of simulated time: many rows, one per frame for joints and forces
    frames = body["sim_time_s"] / 0.05
    assert rows["/arm/joints"] >= 0.8 * frames
    assert rows["/gripper/force"] >= 0.8 * frames
    assert rows["/checks/moves"] == len(body["moves"]) == 1
    assert rows["/world/objects"] >= 0.8 * frames  # the true poses, every frame
    assert rows["/world/slots"] == 1 and not timelines["/world/slots"]  # static


@pytest.mark.sim
@pytest.mark.slow  # perception, rendering and an episode
def test_a_camera_episode_records_its_images_and_soft_supports(tmp_path):
    pytest.importorskip("rerun")
    from rerun.chunk import RrdReader

    from tamp.rerun_log import RerunRecorder

    problem = Problem("two", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    rrd = tmp_path / "camera.rrd"
    config = LoopConfig(observe="camera")
    report = Episode(problem, config, 0, recorder=RerunRecorder(rrd, "two")).run()
    rows, timelines = _entities(rrd)
    assert TIMELINE in timelines["/camera/image"] and TIMELINE in timelines["/belief/support"]
    observations = rows["/camera/image"]
    assert observations >= 1 + len(report.moves)  # the first image, and one after each move
    assert rows["/belief/support"] == observations  # every image was readable here
    shapes = set()
    for chunk in RrdReader(rrd).stream():
        if chunk.entity_path == "/belief/support":
            batch = chunk.to_record_batch()
            shape = next(c for c in batch.schema.names if c.endswith("Tensor:data"))
            shapes |= {tuple(t[0]["shape"]) for t in batch[shape].to_pylist()}
    assert shapes == {(2, 3)}  # (N, N + 1): the blocks, onto a block or the table


@pytest.mark.sim
@pytest.mark.slow  # two episodes
def test_a_recording_changes_nothing_the_episode_does(tmp_path):
    pytest.importorskip("rerun")
    from tamp.rerun_log import RerunRecorder

    problem = Problem("two", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    plain = Episode(problem, LoopConfig(), 3).run()
    frames = []
    recorder = RerunRecorder(tmp_path / "two.rrd", "two")
    recorded = Episode(problem, LoopConfig(), 3, recorder=recorder)
    recorded.on_frame = lambda sim: frames.append(sim.time)
    recorded.sim.frame_period = 0.4  # a video's frame rate, kept while the recorder records
    report = recorded.run()
    physical = [(m.move, m.ok, m.evidence, m.sim_time_s, m.path_rad) for m in report.moves]
    assert physical == [(m.move, m.ok, m.evidence, m.sim_time_s, m.path_rad) for m in plain.moves]
    assert report.status is plain.status
    assert report.sim_time_s == plain.sim_time_s
    assert len(frames) <= report.sim_time_s / 0.4 + 2  # on_frame kept its own period
    assert min(b - a for a, b in itertools.pairwise(frames)) >= 0.39  # a step: 2 ms
    assert set(report.truth_reads) - set(plain.truth_reads) == {"recording"}


@pytest.mark.sim
@pytest.mark.slow  # two episodes, and the benchmark's IK timing
def test_bench_motion_record_writes_one_recording_per_episode(tmp_path):
    pytest.importorskip("rerun")
    out = tmp_path / "out"
    argv = ["bench", "motion", "--blocks", "2", "--n", "2", "--sim", "pybullet"]
    code = main([*argv, "--out", str(out), "--record", "--no-progress", "--json"])
    assert code == 0
    names = [row["problem"] for row in _csv(out / "episodes.csv")]
    written = sorted(p.name for p in (out / "recordings").iterdir())
    assert written == sorted(episode_file(out, "pybullet", n).name for n in names)
    rows, timelines = _entities(out / "recordings" / written[0])
    assert TIMELINE in timelines["/arm/joints"] and rows["/plan/moves"] >= 1


def _csv(path: Path) -> list[dict]:
    import csv

    with path.open() as f:
        return list(csv.DictReader(f))


def test_without_the_extra_record_is_one_line_naming_it(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun fails, as without the extra
    with pytest.raises(RecordingError) as err:
        require_rerun()
    assert str(err.value).count("\n") == 0 and "pip install 'soft-tamp[rerun]'" in str(err.value)
    code = main(["run", "--record", str(tmp_path / "x.rrd")])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "soft-tamp[rerun]" in lines[0]
    assert not (tmp_path / "x.rrd").exists()
    code = main(["bench", "motion", "--record", "--out", str(tmp_path / "out"), "--n", "1"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and "soft-tamp[rerun]" in lines[-1]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["run", "--record", "episode.mp4"], "must end in .rrd"),
        (["bench", "motion", "--record"], "give --out DIR"),
        (["bench", "executability", "--plans", "p.csv", "--record"], "give --out DIR"),
    ],
)
def test_record_refusals_are_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_benchmark_recordings_are_named_by_sim_and_instance(tmp_path):
    assert episode_file(tmp_path, "mujoco", "instance-3") == (
        tmp_path / "recordings" / "mujoco-instance-3.rrd"
    )
    assert episode_file(tmp_path, "pybullet", "a/b c").name == "pybullet-a_b_c.rrd"


@pytest.mark.sim
@pytest.mark.slow  # an episode and the benchmark's set-up
def test_bench_executability_record_writes_a_given_plans_recording(tmp_path):
    pytest.importorskip("rerun")
    from task import data

    root = tmp_path / "blocksworld"
    (root / "instances" / "generated_basic_3").mkdir(parents=True)
    (root / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    (root / "instances" / "generated_basic_3" / "instance-1.pddl").write_text(TWO)
    plans = tmp_path / "model-x.csv"
    plans.write_text(
        "file,plan\ninstances/generated_basic_3/instance-1.pddl,(pick-up a);(stack a b)\n"
    )
    out = tmp_path / "out"
    argv = ["bench", "executability", "--plans", str(plans), "--data", str(root), "--no-ours"]
    assert main([*argv, "--threads", "1", "--no-progress", "--out", str(out), "--record"]) == 0
    written = [p.name for p in (out / "recordings").iterdir()]
    assert written == ["pybullet-generated_basic_3_instance-1-model-x.rrd"]  # SIM-INSTANCE-SOURCE
    rows, timelines = _entities(out / "recordings" / written[0])
    assert rows["/plan/moves"] == 1 and rows["/checks/moves"] == 1  # the given plan, one move
    assert TIMELINE in timelines["/gripper/force"]


# what a recording of a geometric episode (a scene file's) holds on the simulated time line:
# the loop's streams where the geometric episode has them (no planned phases: its executor
# runs a move's phases as one)
GEO_TIMED = (
    "/world/objects",
    "/belief/state",
    "/plan/moves",
    "/plan/length",
    "/plan/time_s",
    "/plan/cost",
    "/arm/joints",
    "/arm/tcp",
    "/arm/tcp_path",
    "/gripper/width",
    "/gripper/force",
    "/checks/moves",
    "/checks/contacts",
    "/events",
    "/episode",
)


@pytest.mark.sim
def test_a_geometric_episode_records_the_loop_s_streams(tmp_path, capsys):
    pytest.importorskip("rerun")
    from tests.tamp.world.test_load import TRAY, cube, scene

    path, rrd = tmp_path / "s.json", tmp_path / "tray.rrd"
    path.write_text(json.dumps(scene(cube("a", 0.45, -0.2, 0.025), regions=[TRAY])))
    argv = ["run", "--scene", str(path), "--goal", "(in a tray)", "--record", str(rrd)]
    assert main([*argv, "--json"]) == 0
    body = json.loads(capsys.readouterr().out)
    assert body["config"]["executor"] == "geometric" and body["config"]["record"] == str(rrd)
    rows, timelines = _entities(rrd)
    missing = [e for e in GEO_TIMED if TIMELINE not in timelines.get(e, ())]
    assert not missing, f"not on the {TIMELINE} time line: {missing}; got {sorted(rows)}"
    frames = body["sim_time_s"] / 0.05
    assert rows["/arm/joints"] >= 0.8 * frames and rows["/world/objects"] >= 0.8 * frames
    assert rows["/checks/moves"] == len(body["moves"]) == 1
    assert rows["/plan/moves"] == len(body["plans"]) == 1
    assert rows["/belief/state"] == 2  # the first observation and one after the move
