"""Environment steps per second from Python: VecNavEnv with 1, 64 and 1024 environments and
random actions, and one NavEnv.step() through gymnasium.make. With --shaping, instead: what
geodesic reward shaping costs, VecNavEnv(16, threads=1) with and without it, episodes of at most
2000 and 200 steps.

    python crates/ronap-py/bench/bench_env.py [--seconds 3] [--shaping]
"""

import argparse
import time

import gymnasium as gym
import numpy as np

import ronap


def vec_rate(n: int, seconds: float, **kwargs: object) -> float:
    env = ronap.VecNavEnv(n, **kwargs)
    env.reset(seed=0)
    # Random actions drawn before the clock starts and taken in turn: a draw from numpy costs
    # 4.5-9 us, half of a step's time with one environment.
    rng = np.random.default_rng(0)
    actions = [rng.integers(0, 3, n) for _ in range(256)]
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        env.step(actions[(steps // n) % len(actions)])
        steps += n
    return steps / (time.perf_counter() - start)


def single_step_us(seconds: float) -> float:
    env = gym.make("ronap/Nav-v0")
    env.reset(seed=0)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        _, _, terminated, truncated, _ = env.step(1)
        steps += 1
        if terminated or truncated:
            env.reset()
    return (time.perf_counter() - start) / steps * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="seconds per figure (default 3)")
    parser.add_argument("--shaping", action="store_true", help="time geodesic reward shaping instead")
    args = parser.parse_args()
    if args.shaping:
        for limit in (2000, 200):
            for shaping in ("geodesic", "none"):
                rate = vec_rate(16, args.seconds, threads=1, max_episode_steps=limit, reward_shaping=shaping)
                print(f"VecNavEnv(16, threads=1), episodes of at most {limit:>4} steps, shaping {shaping:<8}: {rate:>12,.0f} env-steps/s")
        return
    for n in (1, 64, 1024):
        print(f"VecNavEnv({n:>4}): {vec_rate(n, args.seconds):>14,.0f} env-steps/s")
    print(f"gymnasium.make('ronap/Nav-v0').step(): {single_step_us(args.seconds):.2f} us")


if __name__ == "__main__":
    main()
