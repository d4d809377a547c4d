"""``tamp perception dataset|train|eval``: make rendered data, train and score the support model."""

from __future__ import annotations

import argparse
import dataclasses
import json
import shlex
import sys
import time
from pathlib import Path

from tqdm import tqdm

from perception import CHECKPOINT
from tamp.cli.recorded import checkpoint, dataset_config, eval_config, out_file, train_config
from tamp.modes import ImageScene
from task.errors import TampError


def _command_line() -> str:
    return "tamp " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def dataset_command(args: argparse.Namespace) -> int:
    from perception import data as pdata
    from tamp.camera.dataset import generate

    recorded = dataset_config(args)  # refused combinations: before any work
    out_file(args.out)
    sims = tuple(recorded["sims"])
    if args.image_scene == ImageScene.LATPLAN:
        return _latplan_dataset(args, sims)
    with tqdm(
        total=args.n, desc="render", unit="image", file=sys.stderr, disable=not args.progress
    ) as bar:
        data = generate(
            args.n,
            args.seed,
            sims,
            args.min_blocks,
            args.max_blocks,
            progress=bar.update,
            meta={"command": _command_line()},
        )
    path = pdata.save(args.out, data)
    if args.json:
        print(json.dumps({"images": len(data), "redrawn": data.meta["redrawn"], "out": str(path)}))
    else:
        print(f"{len(data)} images ({data.meta['redrawn']} redrawn for occlusion) -> {path}")
    return 0


def _latplan_dataset(args: argparse.Namespace, sims: tuple[str, ...]) -> int:
    """LatPlan's scene (always its 4 blocks): 150x100 to --out, 45x30 to OUT_45x30.npz."""
    from perception import data as pdata
    from tamp.camera import latplan

    exclude = latplan.evaluation_layouts()
    with tqdm(
        total=args.n, desc="render", unit="image", file=sys.stderr, disable=not args.progress
    ) as bar:
        out = latplan.generate(
            args.n,
            args.seed,
            sims,
            exclude=exclude,
            exclude_source=str(latplan.EVALUATION),
            progress=bar.update,
            meta={"command": _command_line()},
        )
    big = Path(args.out)
    paths = [
        pdata.save(big, out[(150, 100)]),
        pdata.save(big.with_name(f"{big.stem}_45x30{big.suffix}"), out[(45, 30)]),
    ]
    meta = out[(150, 100)].meta
    if args.json:
        print(
            json.dumps(
                {
                    "images": args.n,
                    "out": [str(p) for p in paths],
                    "excluded_layouts": meta["excluded_layouts"],
                }
            )
        )
        return 0
    excluded = (
        f"{meta['excluded_layouts']} evaluation layouts excluded"
        if meta["evaluation_layouts_excluded"]
        else f"no evaluation layouts found at {latplan.EVALUATION}: exclusion NOT applied"
    )
    print(f"{args.n} images at 150x100 and 45x30 ({excluded}) -> {paths[0]}, {paths[1]}")
    return 0


# what a checkpoint's meta keeps of its training set's own meta (scene, camera provenance,
# whether evaluation layouts were excluded)
DATASET_KEYS = (
    "scene",
    "sims",
    "camera",
    "evaluation_layouts_excluded",
    "excluded_layouts",
    "excluded_from",
    "randomisation",
)


def train_command(args: argparse.Namespace) -> int:
    import torch

    from perception import data as pdata
    from perception.train import TrainConfig, evaluate, save_checkpoint, train

    if Path(args.out).resolve() == CHECKPOINT.resolve():
        raise TampError(
            f"--out {args.out} is the shipped checkpoint; write elsewhere and copy it over "
            "deliberately"
        )
    train_config(args)
    out_file(args.out)
    torch.set_num_threads(args.threads)
    t0 = time.perf_counter()
    train_raw = pdata.load_many(args.train)  # several files: resized to the first's size
    test_raw = pdata.load_many(args.test.split(",")[:1])
    train_data, test_data = pdata.tensors(train_raw), pdata.tensors(test_raw)
    hw = list(train_raw.images.shape[1:3])
    config = TrainConfig(epochs=args.epochs, seed=args.seed, device=args.device)
    with tqdm(
        total=config.epochs, desc="train", unit="epoch", file=sys.stderr, disable=not args.progress
    ) as bar:

        def on_epoch(k: int, loss: float) -> None:
            bar.set_postfix(nll=f"{loss:.4f}")
            bar.update(1)

        model = train(train_data, config, on_epoch=on_epoch)
    scores = evaluate(model, test_data)
    more = {}  # each further test file, resized to the training input size
    for path in args.test.split(",")[1:]:
        resized = pdata.resize_data(pdata.load_many([path]), hw)
        more[path] = evaluate(model, pdata.tensors(resized))
    meta = {
        "command": _command_line(),
        "seed": args.seed,
        "train": {
            "file": str(args.train),
            "images": len(train_raw),
            "unreadable": train_data["dropped"],  # left out: segmentation could not read them
            "made_by": train_raw.meta.get("command"),
            "data_seed": train_raw.meta.get("seed"),
        },
        "test": {
            "file": str(args.test),
            "made_by": test_raw.meta.get("command"),
            "data_seed": test_raw.meta.get("seed"),
            **scores,
        },
        "more_tests": more,
        "dataset": {k: v for k, v in train_raw.meta.items() if k in DATASET_KEYS},
        "train_config": config.__dict__,
        "train_time_s": round(time.perf_counter() - t0, 1),
        "threads": args.threads,
    }
    if len(train_raw.meta.get("parts", [])) > 1:
        meta["input_hw"] = hw  # `Perceiver.load` resizes every image to this size first
    save_checkpoint(args.out, model, meta)
    if args.json:
        print(json.dumps({**scores, "out": str(args.out), "train_time_s": meta["train_time_s"]}))
        return 0
    print(
        f"relation accuracy {scores['relation_accuracy']:.4%} ({scores['blocks']} blocks), "
        f"scene accuracy {scores['scene_accuracy']:.2%} ({scores['scenes']} images; "
        f"{scores['unreadable']} unreadable, left out) -> {args.out}"
    )
    for path, more_scores in more.items():
        print(
            f"  {path}: relation accuracy {more_scores['relation_accuracy']:.4%}, "
            f"scene accuracy {more_scores['scene_accuracy']:.2%}"
        )
    return 0


def eval_command(args: argparse.Namespace) -> int:

    from perception import data as pdata
    from perception.train import evaluate, load_checkpoint

    recorded = eval_config(args)
    checkpoint(args.checkpoint)
    model, meta = load_checkpoint(args.checkpoint)
    model = model.to(args.device)
    data = pdata.load(args.data)
    if args.blur:
        from perception.perceive import blur

        data = dataclasses.replace(data, images=blur(data.images, args.blur))
    # as planning does (`perception.perceive.Perceiver`): every image at the checkpoint's
    # training input size when it records one
    hw = meta.get("input_hw")
    resized = hw is not None and tuple(data.images.shape[1:3]) != tuple(hw)
    if resized:
        data = pdata.resize_data(data, hw)
    scores = evaluate(model, pdata.tensors(data))
    scores["resized_to"] = list(hw) if resized else None
    if args.json:
        print(json.dumps({**scores, "config": recorded}))
    else:
        size = f"; resized to {hw[0]}x{hw[1]} as planning does" if resized else ""
        print(
            f"relation accuracy {scores['relation_accuracy']:.4%} ({scores['blocks']} blocks), "
            f"scene accuracy {scores['scene_accuracy']:.2%} ({scores['scenes']} images; "
            f"{scores['unreadable']} unreadable, left out{size})"
        )
    return 0
