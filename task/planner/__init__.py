"""planner: the receding-window planner, the paper's method end to end.

`plan` and `plan_batch` (`loop.py`) run receding windows over a batch of problems: each window
(`windows.py`) optimises the action logits with Adam, decodes the moves against a crisp state and
executes the legal ones; when the windows revisit a state or run out, the complete fallback
search (`fallback.py`) plans on over crisp states with the cost source's feasibility. A domain
never changes this code (`task.domains`).
"""

from task.planner.loop import plan, plan_batch
from task.planner.windows import on_device

__all__ = ["on_device", "plan", "plan_batch"]
