"""The checker benchmark's printed tables: throughput, agreement with the meshes, rerouted moves."""

from __future__ import annotations

from tamp.bench.tables import table

# the figures the issue quotes for the checks and plans before the sphere model (issue 24)
BEFORE = "before: RRT-Connect on the mesh model 0.16-0.31 s a rerouted move, ~60 us a mesh check"


def _ms(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"


def _cm(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.1f}"


def checker_table(result: dict) -> str:
    """Three tables over the scenes of `tamp.bench.collision.run.run`'s result."""
    scenes = result["scenes"]
    cpu = result["cpu"]
    where = f"one core (pinned to CPU {cpu})" if cpu is not None else "one process (not pinned)"
    return "\n".join(
        [
            f"sphere checker throughput, {where}:",
            _rates(scenes),
            "against the mesh model near obstacles (false free must be 0; excess: how much "
            "farther than its margin the meshes were where the spheres refused):",
            _checks(scenes),
            "rerouted moves (planning time; mesh checks: calls to the mesh model per move):",
            _moves(scenes),
            BEFORE,
        ]
    )


def _rates(scenes: list) -> str:
    """Configurations checked per second, per scene, sample and batch size."""
    return table(
        ("scene", "sample", "batch", "configs/s", "configs/CPU-s", "threads"),
        [
            (
                s["scene"],
                r["sample"],
                r["batch"],
                f"{r['configs_per_s']:,.0f}",
                f"{r['configs_per_cpu_s']:,.0f}",
                "-" if r.get("threads") is None else r["threads"],
            )
            for s in scenes
            for r in s["throughput"]
        ],
    )


def _checks(scenes: list) -> str:
    """The spheres' verdicts against the meshes near obstacles, per scene."""
    return table(
        (
            "scene",
            "near",
            "mesh free",
            "false free",
            "false coll.",
            "of free",
            "excess cm p50/max",
            "mesh us",
            "spheres us",
        ),
        [
            (
                s["scene"],
                v["n"],
                v["mesh_free"],
                v["false_free"],
                v["false_collision"],
                f"{100 * v['false_collision_of_free']:.1f}%",
                f"{_cm(v['false_collision_excess_median_m'])}/"
                f"{_cm(v['false_collision_excess_max_m'])}",
                f"{v['mesh_us_per_config']:.0f}",
                f"{v['sphere_us_per_config']:.1f}",
            )
            for s in scenes
            for v in (s["validation"],)
        ],
    )


def _moves(scenes: list) -> str:
    """The rerouted moves' planning, per scene and planner."""
    return table(
        (
            "scene",
            "planner",
            "solved",
            "median ms",
            "p90 ms",
            "CPU ms p50/p90",
            "mesh checks",
            "found by",
        ),
        [
            (
                s["scene"],
                name,
                f"{m['solved']}/{m['moves']}",
                _ms(m["median_ms"]),
                _ms(m["p90_ms"]),
                f"{_ms(m['median_cpu_ms'])}/{_ms(m['p90_cpu_ms'])}",
                f"{m['mesh_checks_median']:.0f}",
                ", ".join(f"{k} {v}" for k, v in sorted(m["searches"].items())),
            )
            for s in scenes
            for name, m in s["moves"].items()
        ],
    )
