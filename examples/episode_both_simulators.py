"""Run one closed-loop episode in PyBullet and in MuJoCo, and read its report.

The simulated Panda plans a window, executes each move as a pick-and-place, observes the block
poses, and replans on a failure. `tamp.api.run` returns a frozen `tamp.loop.EpisodeReport`
(the one report type of every episode, a scene file's too); ``report.to_json()`` is what
``tamp run --out DIR`` writes as report.json. Run:
``python examples/episode_both_simulators.py`` (about 15 s, headless).
"""

from __future__ import annotations

import json

from tamp import api

# b sits on a; the goal is the tower a on b on c
PROBLEM = api.Problem(
    name="three",
    domain="blocksworld",
    entities=("a", "b", "c"),
    init=("table", "a", "table"),
    goal=(("a", "b"), ("b", "c")),
)


def main() -> None:
    for sim in ("pybullet", "mujoco"):
        report = api.run(PROBLEM, sim=sim, seed=0)
        ok = sum(move.ok for move in report.moves)
        reached = f"goal reached (ground truth): {report.reached_goal}"
        print(f"{sim} ({report.planner} planner): {report.status.value}, {reached}")
        print(f"  moves {ok}/{len(report.moves)} ok, {report.replans} replans")
        for move in report.moves:
            failure = move.failure.value if move.failure else "ok"
            print(f"  {move.move}: {failure}, {move.sim_time_s:.1f} s simulated")
        print(f"  simulated {report.sim_time_s:.1f} s in {report.wall_time_s:.1f} s wall")
        body = report.to_json()  # plain values: json.dumps works as is
        print(f"  report.json keys: {', '.join(sorted(body)[:6])}, ...")
        assert report.reached_goal, json.dumps(body)[:400]


if __name__ == "__main__":
    main()
