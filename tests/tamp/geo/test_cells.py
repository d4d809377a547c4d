"""Region cells as variables of the planner's Adam (`tamp.geo.ours.cells`): a window with empty
cells prices every restart row on its own, at the packed places exactly the arm's price, a
gradient step moves a row's cell towards the object it would carry there, the committed row
fixes the cell where the packing keeps its room, and a place that would take a neighbour's
room is refused."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from tamp.geo.ours.bridge import PACK, bridge
from tamp.geo.ours.cells import CellConfig, Cells, CellWindow
from tamp.geo.ours.costs import GeoCostConfig, GeoCosts
from tamp.world.goal import parse_goal
from task.costs import IMPOSSIBLE
from task.problem import Move
from tests.tamp.geo.geo_scenes import cube, scene

# a roomy unwalled area: two cubes go in with room to spare
AREA = {"name": "area", "min": [0.40, 0.10], "max": [0.62, 0.30]}


@pytest.fixture
def roomy():
    s = scene(cube("a", 0.45, -0.2), cube("b", 0.60, -0.15), regions=[AREA])
    b = bridge(s, parse_goal("(and (in a area) (in b area))", s))
    return b, GeoCosts(b, None, None, GeoCostConfig(ik=False))


def _column(b, cell: str) -> int:
    return b.problem.index(cell)


def test_a_window_with_empty_cells_prices_each_restart_row_and_starts_at_the_arm_price(roomy):
    b, costs = roomy
    window = costs([0], [b.problem.init], 4)
    assert isinstance(window, CellWindow) and window.parameters()
    c = window.compute()
    assert c.shape == (4, b.problem.n, len(b.problem.targets))  # (P * R, N, Y)
    base = torch.from_numpy(costs.price(b.problem.init))
    assert torch.allclose(c, base.expand_as(c).to(c.dtype), atol=1e-9)  # u = 0: the packed places


def test_a_gradient_step_moves_a_rows_cell_towards_the_object_carried_there(roomy):
    b, costs = roomy
    window = costs([0], [b.problem.init], 2)
    cell = dict(b.cells)["a"]
    i, j = b.problem.entities.index("a"), _column(b, cell)
    assert window.compute()[0, i, j] < IMPOSSIBLE
    window.compute()[0, i, j].backward()  # row 0 prices a -> its cell only
    grad = window.u.grad
    assert grad[1].abs().max() == 0  # row 1's places do not move for row 0's cost
    k = window.terms[0].free.index(int(cell.split(".c")[1]))
    towards = np.asarray(b.scene.object("a").pose.xyz[:2]) - np.asarray(b.site(cell).xy)
    assert float(-grad[0, k] @ torch.tensor(towards)) > 0  # descent carries it nearer to a


def test_the_committed_row_fixes_its_cell_and_a_place_taking_room_is_refused(roomy):
    b, costs = roomy
    window = costs([0], [b.problem.init], 2)
    cell_a, cell_b = dict(b.cells)["a"], dict(b.cells)["b"]
    with torch.no_grad():
        window.u[1] = 0.5  # row 1: every empty cell shifted by reach * tanh(0.5) in x and y
    window.commit([1], [(Move("a", cell_a),)])
    assert cell_a in costs.cells.moved and cell_b not in costs.cells.moved
    moved = np.asarray(costs.bridged.site(cell_a).xy)
    shift = CellConfig().reach * np.tanh(0.5)
    packed = np.asarray(b.site(cell_a).xy)
    room = next(r for r in costs.cells.regions if cell_a in r.cells)
    k = room.cells.index(cell_a)
    want = np.clip(packed + shift, room.lo[k], room.hi[k])
    assert costs.cells.kept == 0 and np.allclose(moved, want)  # room to spare: it moved
    assert not np.allclose(moved, packed)
    # b's cell cannot go onto a's
    cells = Cells(costs.bridged, PACK)
    before = costs.bridged
    after = cells.settle(before, cell_b, costs.bridged.site(cell_a).xy)
    assert after is before and cells.kept == 1
    assert cells.moved[cell_b] == tuple(before.site(cell_b).xy)


def test_with_cells_off_the_window_is_one_matrix_for_every_row(roomy):
    b, _ = roomy
    costs = GeoCosts(b, None, None, GeoCostConfig(ik=False, cells=None))
    window = costs([0], [b.problem.init], 4)
    assert not window.parameters() and window.compute().shape[0] == 1
