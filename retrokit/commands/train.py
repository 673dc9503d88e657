"""``retrokit train``: one policy trained on a benchmark's training levels at once (the paper's Joint PPO).

Every training level runs in the native vector env (or, with ``--backend ray``,
in RLlib's env runners over a Ray cluster) and every update is over all of
them; checkpoints go into ``--out`` as it trains, ``--resume`` continues
a killed run, and the policy it saves is what ``retrokit evaluate --agent ppo
--init DIR`` fine-tunes on the test levels. See docs/evaluate.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from retrokit.commands._common import add_backend_options, add_learning_options

EXAMPLES = [
    "retrokit train --benchmark dasher --agent ppo --agent-config quick --timesteps 200000 --out runs/joint",
    "retrokit train --benchmark dasher --agent ppo --timesteps 200000 --out runs/joint --resume   # after a kill",
    "retrokit train --benchmark dasher --agent rainbow --agent-config quick --timesteps 200000 --out runs/joint-rainbow",
    "retrokit train --benchmark sonic --agent ppo --timesteps 50000000 --checkpoint-every 1800 --out runs/sonic",
    "retrokit train --benchmark sonic --agent ppo --backend ray --ray-address auto --env-runners 47 --timesteps 100000000 --out runs/sonic-ray",
    "retrokit train --benchmark dasher --agent rainbow --agent-config quick --backend ray --timesteps 200000 --out runs/joint-rainbow-ray",
]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``train`` command."""
    from retrokit.learning import DEFAULT_CHECKPOINT_SECONDS

    parser = subparsers.add_parser(
        "train",
        help="train one policy jointly on a benchmark's training levels (Joint PPO); evaluate it with --init",
        description="Train a learning agent on a benchmark's training levels at once (each level's envs in "
        "retrokit's vector env, every update over all of them), writing checkpoints, the learning curve "
        "(curve.csv, curve.png) and the policy (policy.json and its weights) into --out. `retrokit evaluate "
        "--agent ppo --init DIR` fine-tunes the policy on the test levels. Needs the extra retrokit-rl[train]. With "
        "--backend ray, RLlib trains it (PPO, or Rainbow by its DQN): --env-runners env runners spread over a Ray "
        "cluster's CPUs, each playing one training level; a runner lost with its node starts again on the nodes "
        "left.",
    )
    parser.add_argument("--benchmark", default="dasher", help="sonic, dasher, another cartridge's, or a YAML file (default: dasher)")
    parser.add_argument("--agent", default="ppo", help="the learning agent: ppo or rainbow (default: ppo)")
    add_learning_options(parser)
    parser.add_argument("--timesteps", type=int, required=True, help="timesteps to train for, over all levels")
    parser.add_argument("--levels", default="train", help="train (the default), test, all, or LEVEL,...")
    parser.add_argument("--seed", type=int, default=0, help="the run's seed (default: 0)")
    parser.add_argument("--out", type=Path, required=True, metavar="DIR", help="the run folder")
    parser.add_argument("--resume", action="store_true", help="continue the killed run in --out from its last checkpoint")
    parser.add_argument("--checkpoint-every", type=float, default=DEFAULT_CHECKPOINT_SECONDS, metavar="SECONDS",
                        help=f"seconds between checkpoints; 0: after every update (default: {DEFAULT_CHECKPOINT_SECONDS:g})")
    add_backend_options(parser, "this machine's processes", "RLlib's, pip install 'ray[rllib]'")
    parser.add_argument("--env-runners", type=int, default=None, metavar="N",
                        help="with --backend ray: RLlib's env runners, a multiple of the levels (default: one a level)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar or lines")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Train, then say where the policy is."""
    import math

    from retrokit.benchmark.definition import load_benchmark
    from retrokit.errors import InvalidArgumentError
    from retrokit.learning.algorithms import algorithm
    from retrokit.learning.config import load_config
    from retrokit.learning.policy import read_policy
    from retrokit.learning.setup import check_fits
    from retrokit.learning.task import learning_task
    from retrokit.learning.trainrun import Training, train

    if args.timesteps < 1:
        raise InvalidArgumentError(f"Expected --timesteps of 1 or more, got {args.timesteps}.")
    if args.seed < 0:
        raise InvalidArgumentError(f"Expected a --seed of 0 or more, got {args.seed}.")
    if not (math.isfinite(args.checkpoint_every) and args.checkpoint_every >= 0):
        raise InvalidArgumentError(f"Expected --checkpoint-every of 0 or more seconds, got {args.checkpoint_every}.")
    benchmark = load_benchmark(args.benchmark)
    levels = tuple(benchmark.select(args.levels))
    config = load_config(args.agent, args.agent_config)
    init = None
    if args.init is not None:
        init = read_policy(args.init, args.agent)
        check_fits(init, learning_task(benchmark), algorithm(args.agent).observation_options(config.values))
    if args.backend != "ray" and (args.ray_address is not None or args.env_runners is not None):
        raise InvalidArgumentError("Expected --ray-address and --env-runners with --backend ray only; add it, or drop them.")
    runners = None if args.backend != "ray" else len(levels) if args.env_runners is None else args.env_runners
    training = Training(benchmark, levels, args.agent, config, args.timesteps, args.seed, init, args.backend, runners)
    try:
        done = train(training, args.out, resume=args.resume, progress=not args.no_progress,
                     checkpoint_seconds=args.checkpoint_every, ray_address=args.ray_address)
    except KeyboardInterrupt:
        print(f"retrokit: interrupted; the last checkpoint is in {args.out}: add --resume to the same command "
              "to continue", file=sys.stderr)
        return 130
    episodes = sum(map(len, done.episodes.values()))
    print(f"trained {args.agent} for {done.timesteps:,} timesteps ({episodes:,} episodes) on {len(levels)} level(s)")
    print(f"wrote {args.out}/: policy.json (evaluate it with --init {args.out}), curve.csv, curve.png, run.json")
    return 0
