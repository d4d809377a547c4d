"""Write a differentiable cost source, check its gradient, and let it steer the planner.

A cost source prices every move ``x -> y`` in the state a planning window starts from; the
planner adds ``lambda_motion * sum_t sum_(x,y) g_t(x, y) c(x, y)`` to its loss (`task.costs`),
so gradients flow from the costs into the action logits, and ranks equally short plans by the
cost of their moves. Here the cost is the squared horizontal distance (m^2) a block travels
from where it stands to where it lands, a stand-in for the arm's cost (`tamp.arm.costs`).
``torch.autograd.gradcheck`` compares its analytic gradient with finite differences in
float64. Run: ``python examples/cost_gradient.py`` (about 3 s).
"""

from __future__ import annotations

import torch

from tamp import api

# a sits on b; the goal puts b on c, so a must first go somewhere: the table or onto d
PROBLEM = api.Problem(
    "unstack", "blocksworld", ("a", "b", "c", "d"), ("b", "table", "table", "table"), (("b", "c"),)
)
# (x, y) of each entity's tower, in metres: d stands far away; the table's free slot is near
XY = torch.tensor([[0.4, 0.0], [0.4, 0.0], [0.4, 0.3], [0.7, -0.4]], dtype=torch.float64)
TABLE_XY = torch.tensor([0.45, -0.1], dtype=torch.float64)


def travel(xy: torch.Tensor) -> torch.Tensor:
    """Squared travel of each block x to each target y: (N, 2) positions -> (N, Y) m^2, the
    targets being the N blocks then the table (Y = N + 1)."""
    targets = torch.cat([xy, TABLE_XY[None].to(xy)])  # (Y, 2)
    return (xy[:, None, :] - targets[None, :, :]).pow(2).sum(-1)  # (N, Y)


def price(problem: api.Problem, state: object) -> torch.Tensor:
    """The cost source's function: (N, Y) costs of the moves from ``state``, float32."""
    return travel(XY).float()


def total(planned: api.PlanReport) -> float:
    """The summed cost of a plan's moves, m^2."""
    costs = price(PROBLEM, None)
    return sum(
        float(costs[PROBLEM.index(m.entity), PROBLEM.index(m.target)]) for m in planned.moves
    )


def main() -> None:
    xy = XY.clone().requires_grad_(True)
    assert torch.autograd.gradcheck(travel, (xy,), eps=1e-6, atol=1e-6)
    print("gradcheck of the cost against finite differences (float64): passed")

    plain = api.plan(PROBLEM, seed=0)
    priced = api.plan(PROBLEM, seed=0, costs=api.CostFunction(price, (PROBLEM,)))
    for label, planned in (("task only", plain), ("with costs", priced)):
        moves = ", ".join(str(m) for m in planned.moves)
        print(f"{label}: {moves} ({planned.validation.reason}, travel {total(planned):.3f} m^2)")
    assert priced.valid and priced.moves[0] == api.Move("a", "table")
    assert total(priced) < total(plain)


if __name__ == "__main__":
    main()
