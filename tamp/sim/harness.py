"""What an experiment adds around a move that the robot knows nothing of: a fault to inject and
the recorders called while it runs. Both executors take one (`tamp.loop.execute.execute_move`,
`tamp.geo.execute.run_move`), so the fault and the recorders travel together, by name."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from motion.pick_place import Phase
    from tamp.sim.base import Simulator


@dataclass(frozen=True)
class Harness:
    """``drop_at`` in [0, 1]: the gripper opens at that fraction of the transit (fault
    injection; None: no fault); ``on_frame(sim)``: called at every frame the simulator draws
    (a video); ``on_phase(sim, phase)``: called as each planned phase starts (a recording,
    `tamp.rerun_log`). The default: no fault, nothing recorded."""

    drop_at: float | None = None
    on_frame: Callable[[Simulator], None] | None = None
    on_phase: Callable[[Simulator, Phase], None] | None = None
