"""The planner's torch device (`task.config.PlannerConfig.device`): CPU plans are the ones
planned before the option existed, unknown devices and CUDA on a machine without it are refused
in one line, and on a machine with CUDA the windows run there (skipped without one)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch

from task.config import PlannerConfig, device_problem, torch_device
from task.domains import get_domain
from task.domains.base import SoftBatch
from task.errors import TampError
from task.planner import on_device, plan, plan_batch
from task.problem import PlanStatus
from task.symbolic.generate import random_problem

FIXTURE = Path(__file__).with_name("fixtures") / "cpu_plans.json"
CUDA = torch.cuda.is_available()


def _plans(device: str) -> dict:
    """Each own domain's samples (seed 0) planned at a small config, as the fixture holds them
    (written at the commit before `PlannerConfig.device`)."""
    out = {}
    for name in ("blocksworld", "logistics", "sokoban"):
        problems = list(get_domain(name).samples(0))
        config = PlannerConfig.for_domain(name, restarts=4, iters=15, max_windows=12, device=device)
        results = plan_batch(problems, config, seed=3)
        out[name] = [[r.status.value, [str(m) for m in r.plan.moves]] for r in results]
    return out


def test_cpu_plans_are_the_plans_before_the_device_option():
    assert _plans("cpu") == json.loads(FIXTURE.read_text())


@pytest.mark.parametrize("name", ["tpu", "gpu", "cuda:", "cuda:x", "CPU", ""])
def test_an_unknown_device_is_refused_listing_the_valid_ones(name):
    with pytest.raises(TampError, match=r"unknown device .*\(valid: cpu, cuda, cuda:N\)"):
        PlannerConfig(device=name)


@pytest.mark.skipif(CUDA, reason="this machine has CUDA")
@pytest.mark.parametrize("name", ["cuda", "cuda:0", "cuda:3"])
def test_cuda_where_there_is_none_is_refused_in_one_line_not_run_on_the_cpu(name):
    config = PlannerConfig(device=name)  # the name is valid; this machine lacks the device
    assert "CUDA" in device_problem(name)
    with pytest.raises(TampError, match="CUDA") as err:
        plan(random_problem(4, 0), config)
    assert "\n" not in str(err.value) and repr(name) in str(err.value)


def test_on_device_moves_every_tensor_of_a_batch():
    problems = [random_problem(4, 1), random_problem(5, 2)]
    batch = get_domain("blocksworld").encode(problems, [p.init for p in problems])
    batch = SoftBatch(*batch.astuple(), static={"extra": torch.ones(2)})
    moved = on_device(batch, torch_device("cpu"))
    for t in (*moved.astuple(), *moved.static.values()):
        assert t.device == torch.device("cpu")
    assert torch.equal(moved.F0, batch.F0) and torch.equal(moved.static["extra"], torch.ones(2))


@pytest.mark.skipif(not CUDA, reason="needs a CUDA device")
def test_on_cuda_the_windows_run_on_cuda_and_plan(monkeypatch):
    domain = get_domain("blocksworld")
    seen = set()
    step = domain.step

    def spy(F, M, batch):
        seen.update({F.device.type, M.device.type, batch.F0.device.type})
        return step(F, M, batch)

    monkeypatch.setattr(type(domain), "step", staticmethod(spy))
    problem = random_problem(8, 0)
    result = plan(problem, PlannerConfig(device="cuda"))
    assert seen == {"cuda"}
    assert result.status is PlanStatus.SOLVED


@pytest.mark.skipif(not CUDA, reason="needs a CUDA device")
def test_on_cuda_every_own_domain_plans_its_samples():
    plans = _plans("cuda")
    for name, rows in plans.items():
        assert all(status == "solved" for status, _ in rows), name
