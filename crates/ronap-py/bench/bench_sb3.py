"""Stable-Baselines3 with ronap, timed.

    python crates/ronap-py/bench/bench_sb3.py evaluate [--seeds 1000] [--batch 0,100]
    python crates/ronap-py/bench/bench_sb3.py train [--timesteps 200000] [--envs 16]

`evaluate`: a PPO MlpPolicy (as SB3 builds it, untrained, seed 0) run by ronap.evaluate over the
seeds, one predict() per observation (batch 0) and batched; the episodes must be the same.
`train`: PPO (SB3's defaults unless --epochs/--batch-size, seed 0) for the same timesteps on ronap.sb3.VecEnv(envs) and on
SB3's make_vec_env(ronap.NavEnv, n_envs=envs) (DummyVecEnv), each then evaluated greedily on the
held-out seeds 100000.. (batched); prints wall time, steps/s and success of both.
"""

import argparse
import time

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

import ronap
import ronap.sb3


def success(model, seeds, batch=100, **config):
    """Greedy success rate of `model` over `seeds`, with its predict() batched."""
    act = lambda obs: model.predict(obs, deterministic=True)[0]
    r = ronap.evaluate(act, seeds, batch=batch, **config)
    return r["summary"]["success_rate"], r


def evaluate(args):
    model = PPO("MlpPolicy", ronap.NavEnv(), seed=0, device="cpu")
    seeds = range(args.seeds)
    first = None
    for batch in [int(b) for b in args.batch.split(",")]:
        start = time.perf_counter()
        if batch == 0:
            act = lambda obs: int(model.predict(obs, deterministic=True)[0])
            r = ronap.evaluate(act, seeds)
        else:
            rate, r = success(model, seeds, batch=batch)
        wall = time.perf_counter() - start
        steps = sum(e["steps"] for e in r["episodes"])
        rows = [(e["outcome"], e["steps"]) for e in r["episodes"]]
        first = first or rows
        assert rows == first, "batched episodes differ"
        print(f"batch {batch:>4}: {wall:7.2f} s for {args.seeds} episodes, {steps} steps, {steps / wall:,.0f} steps/s")


def train(args):
    config = dict(maze_cols=args.cols, maze_rows=args.rows)
    held_out = range(100_000, 100_000 + args.eval_seeds)
    for name, make in [
        ("ronap.sb3.VecEnv", lambda: ronap.sb3.VecEnv(args.envs, **config)),
        ("make_vec_env(NavEnv)", lambda: make_vec_env(ronap.NavEnv, n_envs=args.envs, seed=0, env_kwargs=config)),
    ]:
        env = make()
        model = PPO("MlpPolicy", env, seed=0, device="cpu", n_epochs=args.epochs, batch_size=args.batch_size)
        start = time.perf_counter()
        model.learn(args.timesteps)
        wall = time.perf_counter() - start
        rate, _ = success(model, held_out, **config)
        print(
            f"{name:<22} {args.timesteps} timesteps in {wall:7.1f} s ({args.timesteps / wall:,.0f} steps/s); "
            f"greedy success on {args.eval_seeds} held-out seeds {rate:.1%}",
            flush=True,
        )


def main():
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="what", required=True)
    e = sub.add_parser("evaluate")
    e.add_argument("--seeds", type=int, default=1000)
    e.add_argument("--batch", default="0,100")
    t = sub.add_parser("train")
    t.add_argument("--timesteps", type=int, default=200_000)
    t.add_argument("--envs", type=int, default=16)
    t.add_argument("--cols", type=int, default=5)
    t.add_argument("--rows", type=int, default=5)
    t.add_argument("--eval-seeds", type=int, default=500)
    t.add_argument("--epochs", type=int, default=10, help="PPO n_epochs (SB3's default 10)")
    t.add_argument("--batch-size", type=int, default=64, help="PPO batch_size (SB3's default 64)")
    p.add_argument("--torch-threads", type=int, default=0, help="torch.set_num_threads (0: torch's default)")
    args = p.parse_args()
    if args.torch_threads:
        torch.set_num_threads(args.torch_threads)
    (evaluate if args.what == "evaluate" else train)(args)


if __name__ == "__main__":
    main()
