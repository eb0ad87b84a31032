"""Times ronap.evaluate with a Python policy shaped like SB3's PPO MlpPolicy (18 -> 64 -> 64 -> 3,
tanh, argmax), in numpy: one call per observation, then batched.

    python crates/ronap-py/bench/bench_batch.py [--seeds 1000] [--batch 1,100]
"""

import argparse
import time

import numpy as np

import ronap


def network(seed=0):
    rng = np.random.default_rng(seed)
    shapes = [(18, 64), (64, 64), (64, 3)]
    return [(rng.normal(0, 1 / np.sqrt(a), (a, b)).astype(np.float32), np.zeros(b, np.float32)) for a, b in shapes]


def forward(layers, x):
    for k, (w, b) in enumerate(layers):
        x = x @ w + b
        if k < len(layers) - 1:
            x = np.tanh(x)
    return x


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--seeds", type=int, default=1000)
    p.add_argument("--batch", default="0,100")
    args = p.parse_args()
    layers = network()
    one = lambda obs: int(np.argmax(forward(layers, obs)))
    rows = lambda obs: np.argmax(forward(layers, obs), axis=1)
    results = {}
    for batch in [int(b) for b in args.batch.split(",")]:
        start = time.perf_counter()
        if batch == 0:
            r = ronap.evaluate(one, range(args.seeds))
        else:
            r = ronap.evaluate(rows, range(args.seeds), batch=batch)
        wall = time.perf_counter() - start
        steps = sum(e["steps"] for e in r["episodes"])
        results[batch] = [(e["outcome"], e["steps"]) for e in r["episodes"]]
        print(f"batch {batch:>4}: {wall:6.2f} s for {args.seeds} episodes, {steps} steps, {steps / wall:,.0f} steps/s")
    first = next(iter(results.values()))
    assert all(v == first for v in results.values()), "batched episodes differ"


if __name__ == "__main__":
    main()
