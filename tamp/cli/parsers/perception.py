"""The ``tamp perception`` command group's parser: ``dataset``, ``train`` and ``eval``, each
binding its handler from `tamp.cli.perception`.
"""

from __future__ import annotations

from perception import CHECKPOINT
from tamp.cli.options import IMAGE_SCENES, device_option
from tamp.cli.parsers.handlers import lazy
from tamp.cli.types import MAX_BLOCKS, bounded, positive, radius, seed, threads

EPOCHS = 20  # perception.train.TrainConfig.epochs; the parser does not import torch


def perception_commands(sub) -> None:
    """``perception dataset|train|eval``."""
    group = sub.add_parser("perception", help="rendered data, training and scoring of perception")
    cmds = group.add_subparsers(dest="perception_command", required=True, metavar="COMMAND")

    p = cmds.add_parser("dataset", help="render a labelled support dataset")
    p.add_argument("--n", type=positive, default=4000, help="images (4000)")
    p.add_argument("--seed", type=seed, default=0, help="scene and view seed (0)")
    p.add_argument(
        "--sim",
        default="pybullet,mujoco",
        metavar="SIM[,SIM]",
        help="simulators, samples alternate (pybullet,mujoco)",
    )
    p.add_argument("--min-blocks", type=bounded(1, MAX_BLOCKS), default=3, help="(3)")
    p.add_argument("--max-blocks", type=bounded(1, MAX_BLOCKS), default=6, help="(6)")
    p.add_argument(
        "--image-scene",
        choices=IMAGE_SCENES,
        default="cubes",
        help="cubes (the robot's scene) or latplan: LatPlan's 4 cylinders on 5 slots, "
        "written at 150x100 to --out and at 45x30 beside it (cubes)",
    )
    p.add_argument("--out", required=True, metavar="FILE.npz", help="where to write it")
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.add_argument("--no-progress", dest="progress", action="store_false")
    p.set_defaults(
        func=lazy("tamp.cli.perception", "dataset_command"),
        recorded=lazy("tamp.cli.recorded", "dataset_config"),
    )

    p = cmds.add_parser("train", help="train the support model and write a checkpoint")
    p.add_argument("--train", required=True, metavar="FILE.npz", help="training dataset")
    p.add_argument("--test", required=True, metavar="FILE.npz", help="held-out test dataset")
    p.add_argument("--epochs", type=positive, default=EPOCHS, help="(%(default)s)")
    p.add_argument("--seed", type=seed, default=0, help="initialisation and batch order (0)")
    p.add_argument("--threads", type=threads, default=2, help="torch threads (2)")
    device_option(p, "the model's and its batches'")
    p.add_argument(
        "--out",
        required=True,
        metavar="FILE.pt",
        help="checkpoint to write (never the shipped one)",
    )
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.add_argument("--no-progress", dest="progress", action="store_false")
    p.set_defaults(
        func=lazy("tamp.cli.perception", "train_command"),
        recorded=lazy("tamp.cli.recorded", "train_config"),
    )

    p = cmds.add_parser("eval", help="relation accuracy of a checkpoint on a dataset")
    p.add_argument("data", metavar="FILE.npz")
    p.add_argument("--checkpoint", default=str(CHECKPOINT), metavar="FILE.pt")
    p.add_argument(
        "--blur", type=radius, default=0, metavar="R", help="Gaussian blur radius, pixels (0)"
    )
    device_option(p, "the model's")
    p.add_argument("--json", action="store_true")
    p.set_defaults(
        func=lazy("tamp.cli.perception", "eval_command"),
        recorded=lazy("tamp.cli.recorded", "eval_config"),
    )
