"""``plan-images`` on a black image pair under the LatPlan scene: the README promises an error
when there are no blocks, and there is one line of it (it used to plan "init [black] -> goal
[black]" and print VALID)."""

from __future__ import annotations

import numpy as np
import pytest

from tamp.camera.image_pair import blocks_in
from task.errors import TampError


@pytest.mark.parametrize("scene", ["latplan", "cubes"])
@pytest.mark.parametrize("shape", [(100, 150), (30, 45)])
def test_a_black_image_pair_has_no_blocks(scene, shape):
    black = np.zeros((*shape, 3), np.uint8)
    with pytest.raises(TampError) as excinfo:
        blocks_in([black, black.copy()], ["init.png", "goal.png"], scene)
    message = str(excinfo.value)
    assert "\n" not in message
    assert message.startswith("no blocks found in init.png or goal.png (looked for red, blue")
