"""Configuration of the soft-T_P planner: one frozen dataclass."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, fields, replace

# moves per window (horizon, lookahead): far beyond any plan the windows decode, and the window's
# (B, T, N, A) logits and T-step rollout graph grow with it (1_000_000 hung before planning)
MAX_HORIZON = 1000
FALLBACK_SEARCHES = ("astar", "greedy")  # `PlannerConfig.fallback_search`
PART_WINDOW = ("horizon", "lookahead", "lookahead_share", "restarts", "iters", "lr", "init_noise")
DEVICES = ("cpu", "cuda", "cuda:N")  # `PlannerConfig.device`: torch devices planning runs on
_DEVICE = re.compile(r"cpu|cuda(:\d+)?")


@dataclass(frozen=True)
class PlannerConfig:
    """Planner settings. Paper values where the paper gives them (T=3, Adam lr 0.1, 0.3)."""

    horizon: int = 3  # T, moves per optimisation window
    lr: float = 0.1  # Adam learning rate on the action logits
    iters: int = 60  # Adam steps per window
    tau: float = 0.5  # softmax temperature of the action logits
    tau_end: float = 0.05  # temperature at the last Adam step (geometric annealing from tau)
    decode_tau: float | None = 0.005  # temperature of the rollout that is decoded, sharper than
    # tau_end so that hedged soft plans (two moves at once, each half) commit; None: tau_end
    threshold: float = 0.3  # decoding confidence: a step's move mass must reach this
    goal_loss: str = "default"  # the domain's first goal loss; "atoms": the paper's goal CE
    lambda_move: float = 0.05  # weight of the move-count loss (shorter plans)
    lambda_cycle: float = 1.0  # weight of the direct two-cycle loss
    lambda_fp: float = 1.0  # weight of the fixed-point loss (before refinement)
    lambda_motion: float = 0.0  # weight of the move costs of a `task.costs.CostSource` (0: none)
    fp_iters: int = 1  # T_P refinement applications between steps
    init_noise: float = 0.5  # std of the Gaussian initial logits (differs per restart)
    restarts: int = 16  # random restarts per problem, optimised in the same tensor program
    lookahead: int = 5  # window length of the long-lookahead restarts (an extension, not paper)
    lookahead_share: float = 0.5  # share of restarts that use ``lookahead``; 0 = the paper's
    max_windows: int = 40  # replanning windows before giving up
    proof_every: int = 5  # Adam steps between reads of a window that may reach the goal: once
    # every problem's decoded window reaches it in as few moves as the domain's lower bound
    # from the window's start allows, no later step could decode a shorter window and the
    # window stops (0: never, all ``iters`` steps; only windows of one problem, without
    # beliefs, and without move costs unless ``proof_costs``; `task.decode.proof_stop`)
    proof_costs: bool = False  # stop early with move costs too: a window reaching the goal in
    # as few moves as the bound wins over a cheaper one of that length a later step might decode
    time_limit_s: float | None = None  # wall-clock planning limit (problems planned together
    # in one batch start together and share it), checked at every Adam and rollout step: a
    # window it cuts short is abandoned; None: only max_windows stops the planner
    batched: bool = True  # one tensor program for all problems; False: one problem at a time
    rank_prefixes: bool = True  # rank (and cut) each window by its best prefix (`task.decode`)
    park_free: bool = False  # count parking moves (to the table) as free in that ranking
    park_from: int | None = None  # park_free for the problems of at least this many entities
    # (None: only park_free); Blocksworld's `planner_defaults` set 30: beyond the sizes whose
    # plan length the issue holds to the optimum, where the time budget binds instead
    safe_from: int | None = None  # problems of at least this many entities take the domain's
    # safe moves (`safe_moves`: Blocksworld's constructive moves, which some shortest plan
    # starts with) without a window; windows plan only from states that have none. None: off;
    # Blocksworld's `planner_defaults` set 16. Only without beliefs and a cost source
    crisp_check: bool = True  # decode only legal moves; False keeps an illegal strongest move
    fallback: bool | None = None  # when the windows revisit a state or run out, search on from
    # the world state, complete over the moves the cost source allows (`task.symbolic.lazy_search`);
    # None: only with a cost source (motion-aware planning); never with beliefs (perception)
    own_state_costs: bool = True  # with a cost source, each window move after the first is
    # checked in the state it starts from, and the window is cut before the first one the
    # source rules out there (`task.costs.IMPOSSIBLE`): the window's matrix prices every step
    # in the window's start state, where a move its earlier moves make legal is illegal and
    # priced 0 (`task.planner.windows.own_state_prefix`). False: every decoded move is kept
    fallback_nodes: int = 5_000  # state expansions the fallback may spend per problem (each
    # expanded state is priced once by the cost source when one of its moves is checked)
    shorten: bool = False  # cut cycles and redundant moves out of a plan that reaches the goal
    # (`task.symbolic.shorten`); only without beliefs and a cost source (their windows are
    # committed move by move)
    restart_probe: int = 0  # A* expansions the fallback first spends from the initial state
    # when its plan may drop the windows' moves (`task.planner.fallback.fall_back`), before
    # searching from where the windows left off; a plan found there is taken. 0: off (each
    # expansion prices a state, 28-38 ms at 20 cramped blocks); the motion-aware planner of
    # scene files sets it (`tamp.geo.ours.planner.PLANNER`)
    fallback_search: str = "astar"  # "astar": A* on the domain's lower bound (shortest plans;
    # out of budget with time left, a greedy search goes on: `task.planner.fallback.fall_back`);
    # "greedy": lazy greedy best-first on its `estimate` (else the lower bound) and its
    # `helpful` moves (far larger problems, longer plans; `task.symbolic.lazy_search.lazy_greedy`)
    improve_s: float = 0.0  # anytime improvement: after the windows (and `shorten`) give a
    # plan of L moves, A* on the domain's lower bound looks for one of fewer than L moves for
    # at most this many seconds (within ``time_limit_s`` when set) and ``improve_nodes``
    # expansions; a plan found replaces it and is a shortest one
    # (`task.symbolic.lazy_search.improve`).
    # Only without beliefs and a cost source; 0: off
    improve_nodes: int = 20_000  # state expansions the improvement may spend per problem
    improve_up_to: int | None = None  # improve only problems of at most this many entities
    # (None: any size); Blocksworld's `planner_defaults` turn the improvement on up to 15
    # blocks, where its A* proved the optimum within seconds (at 20 it never finished)
    window_share: float = 1.0  # with a time limit and the fallback on, the windows stop at
    # this share of the limit and the fallback searches in the rest (1: the windows may use all
    # of it, leaving the complete search none; the STRIPS lift's defaults: 0.5)
    part_window: tuple[tuple[str, object], ...] = ()  # window settings (field, value) for the
    # problems that take safe moves (`safe_from`), whose windows plan a part cut to what their
    # moves reach (`task.domains.base.window_part`); Blocksworld's `planner_defaults` set longer
    # windows with fewer restarts and Adam steps there (`for_parts`). (): the same as the others
    device: str = "cpu"  # torch device of the window tensors (and of a perception model read
    # alongside): "cpu", "cuda" or "cuda:N"; never falls back (`torch_device` refuses one that
    # this machine lacks). Decoding and the crisp checks stay on the CPU

    @classmethod
    def for_domain(cls, name: str, **given) -> PlannerConfig:
        """The defaults with domain ``name``'s own (its ``planner_defaults``, e.g. Sokoban's
        longer lookahead and window budget), then the fields ``given``. A field given also
        holds in the windows over a part of a problem: the domain's `part_window` setting
        of it is left out."""
        from task.domains import get_domain

        tuned = dict(get_domain(name).planner_defaults)
        parts = tuned.get("part_window", ())
        tuned["part_window"] = tuple((k, v) for k, v in parts if k not in given)
        return cls(**{**tuned, **given})

    def parks(self, problem) -> bool:
        """Whether ``problem``'s windows are ranked with parking moves free (`park_free`, or
        at least `park_from` entities)."""
        return self.park_free or (self.park_from is not None and problem.n >= self.park_from)

    def takes_safe(self, problem) -> bool:
        """Whether ``problem`` takes its domain's safe moves without a window (`safe_from`)."""
        return self.safe_from is not None and problem.n >= self.safe_from

    def for_parts(self) -> PlannerConfig:
        """The settings of the windows over a part of a problem (`part_window`)."""
        return replace(self, part_window=(), **dict(self.part_window)) if self.part_window else self

    def horizons(self) -> tuple[int, ...]:
        """Window length of each restart: the long-lookahead restarts come last."""
        n_long = round(self.restarts * self.lookahead_share)
        return (self.horizon,) * (self.restarts - n_long) + (self.lookahead,) * n_long

    def __post_init__(self) -> None:
        from task.errors import TampError

        for item in fields(self):  # nan slips through every comparison below; inf is no setting
            value = getattr(self, item.name)
            if isinstance(value, float) and not math.isfinite(value):
                raise TampError(f"PlannerConfig.{item.name} must be a finite number, got {value}")
        if self.park_from is not None and self.park_from < 1:
            raise TampError(f"PlannerConfig.park_from must be >= 1 or None, got {self.park_from}")
        if self.safe_from is not None and self.safe_from < 1:
            raise TampError(f"PlannerConfig.safe_from must be >= 1 or None, got {self.safe_from}")
        names = ("horizon", "iters", "restarts", "max_windows", "fallback_nodes", "improve_nodes")
        for name in names:
            if getattr(self, name) < 1:
                raise TampError(f"PlannerConfig.{name} must be >= 1, got {getattr(self, name)}")
        if self.restart_probe < 0:
            raise TampError(f"PlannerConfig.restart_probe must be >= 0, got {self.restart_probe}")
        if self.proof_every < 0:
            raise TampError(f"PlannerConfig.proof_every must be >= 0, got {self.proof_every}")
        for name in ("horizon", "lookahead"):
            if not 1 <= getattr(self, name) <= MAX_HORIZON:
                raise TampError(
                    f"PlannerConfig.{name} must be in 1..{MAX_HORIZON}, got {getattr(self, name)}"
                )
        check_device_name(self.device)
        for name, _ in self.part_window:
            if name not in PART_WINDOW:
                from task.errors import one_of

                raise TampError(
                    f"PlannerConfig.part_window: unknown setting {one_of(name, PART_WINDOW)}"
                )
        self.for_parts()  # its values checked as settings of their own
        if self.fallback_search not in FALLBACK_SEARCHES:
            from task.errors import one_of

            raise TampError(
                f"unknown PlannerConfig.fallback_search "
                f"{one_of(self.fallback_search, FALLBACK_SEARCHES)}"
            )
        if not 0.0 < self.threshold <= 1.0:
            raise TampError(f"PlannerConfig.threshold must be in (0, 1], got {self.threshold}")
        if not 0.0 <= self.lookahead_share <= 1.0:
            share = self.lookahead_share
            raise TampError(f"PlannerConfig.lookahead_share must be in [0, 1], got {share}")
        if not 0.0 < self.window_share <= 1.0:
            share = self.window_share
            raise TampError(f"PlannerConfig.window_share must be in (0, 1], got {share}")
        if self.improve_up_to is not None and self.improve_up_to < 1:
            raise TampError(
                f"PlannerConfig.improve_up_to must be >= 1 or None, got {self.improve_up_to}"
            )
        if not self.improve_s >= 0:
            raise TampError(f"PlannerConfig.improve_s must be >= 0, got {self.improve_s}")
        if self.time_limit_s is not None and not self.time_limit_s > 0:
            raise TampError(f"PlannerConfig.time_limit_s must be > 0, got {self.time_limit_s}")
        sharp = self.decode_tau if self.decode_tau is not None else self.tau_end
        if self.tau <= 0 or self.tau_end <= 0 or self.lr <= 0 or sharp <= 0:
            raise TampError("PlannerConfig.tau, tau_end, decode_tau and lr must be > 0")


def check_device_name(name: str) -> str:
    """``name`` when it spells a device planning knows (`DEVICES`), else TampError listing
    them. Whether this machine has it is `torch_device`'s question."""
    from task.errors import TampError, one_of

    if not isinstance(name, str) or not _DEVICE.fullmatch(name):
        raise TampError(f"unknown device {one_of(name, DEVICES)}")
    return name


def device_problem(name: str) -> str | None:
    """Why this machine cannot run torch on device ``name`` (one line), or None when it can.
    Imports torch only for a CUDA device."""
    check_device_name(name)
    if name == "cpu":
        return None
    import torch

    if not torch.backends.cuda.is_built():
        return f"this torch build has no CUDA (torch {torch.__version__})"
    count = torch.cuda.device_count()
    if count == 0:
        return f"no CUDA device is visible (torch {torch.__version__}, CUDA {torch.version.cuda})"
    index = int(name.partition(":")[2] or 0)
    if index >= count:
        return f"only {count} CUDA device(s) here (valid: cuda, cuda:0..cuda:{count - 1})"
    return None


def torch_device(name: str):
    """The `torch.device` named ``name``; TampError (one line) when it is unknown or this
    machine lacks it: a request for CUDA never silently runs on the CPU."""
    from task.errors import TampError

    why = device_problem(name)
    if why is not None:
        raise TampError(f"device {name!r}: {why}")
    import torch

    return torch.device(name)
