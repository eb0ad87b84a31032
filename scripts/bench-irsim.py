#!/usr/bin/env python3
"""ronap and IR-SIM side by side, on one thread: a robot with a 17-beam laser among walls, and a
crowd of 100 ORCA (RVO) agents. Prints steps per second of each, the median of --rounds runs.

    python scripts/bench-irsim.py [--ronap PATH] [--seconds 3] [--rounds 3]

Needs IR-SIM in the interpreter that runs it (`pip install ir-sim==2.12.0`) and a `ronap` binary
(--ronap, $RONAP_BIN, else target/release/ronap). The two tasks are alike, not the same: IR-SIM's
robot is a differential drive with a 17-beam lidar over 180 degrees among 20 thin walls in a 10 m
world (ronap: the paper's unicycle, 17 beams over 180 degrees, in a 10 x 10 maze); IR-SIM's crowd
is 100 omnidirectional agents of its `rvo` behaviour on a circle (ronap: 100 `orca` pedestrians
with random starts and goals in an open 1000 px hall, a new goal at each arrival, stepped with
the robot). Neither draws anything.
"""

import argparse
import os
import pathlib
import re
import statistics
import subprocess
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

IRSIM_ROBOT = """
world: {height: 10, width: 10, step_time: 0.1, sample_time: 0.1, collision_mode: 'stop', control_mode: 'auto'}
robot:
  - kinematics: {name: 'diff'}
    shape: {name: 'circle', radius: 0.05}
    state: [0.5, 0.5, 0]
    goal: [9.5, 9.5, 0]
    behavior: {name: 'dash'}
    vel_max: [0.5, 1.0]
    sensors:
      - {name: 'lidar2d', range_min: 0, range_max: 0.5, angle_range: 3.1416, number: 17}
obstacle:
  - number: 20
    distribution: {name: 'random', range_low: [1, 1, -3.14], range_high: [9, 9, 3.14]}
    shape:
      - {name: 'rectangle', length: 1.0, width: 0.1}
"""

IRSIM_CROWD = """
world: {height: 50, width: 50, step_time: 0.1, sample_time: 0.1, collision_mode: 'unobstructed', control_mode: 'auto'}
robot:
  - number: 100
    distribution: {name: 'circle', radius: 20.0, center: [25, 25]}
    kinematics: {name: 'omni'}
    shape: {name: 'circle', radius: 0.3}
    behavior: {name: 'rvo', vxmax: 1.0, vymax: 1.0, acce: 1.0, factor: 1.0}
    vel_min: [-1, -1]
    vel_max: [1, 1]
    arrive_mode: position
    goal_threshold: 0.15
"""

RONAP_CROWD = """
[scene]
kind = "maze"
[maze]
cols = 1
rows = 1
cell_px = 1000.0
[[moving]]
count = 100
shape = "disc"
radius_px = 6.0
motion = "orca"
speed_px = 5.0
pattern = "random"
on_arrival = "new_goal"
"""


def irsim_steps_per_second(world: str, seconds: float) -> float:
    import irsim

    env = irsim.make(world, disable_all_plot=True, log_level="ERROR", seed=0)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        env.step()
        steps += 1
        if env.done():
            env.reset()
    return steps / (time.perf_counter() - start)


def ronap_steps_per_second(ronap: str, args: list[str]) -> float:
    out = subprocess.run([ronap, "bench", "--threads", "1", *args], check=True, capture_output=True, text=True).stdout
    line = next(l for l in out.splitlines() if l.strip().startswith("one thread"))
    return float(re.sub(r"[^0-9.]", "", line.split("thread", 1)[1].split("steps")[0]))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--ronap", default=os.environ.get("RONAP_BIN") or str(ROOT / "target" / "release" / "ronap"))
    p.add_argument("--seconds", type=float, default=3.0)
    p.add_argument("--rounds", type=int, default=3)
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as d:
        d = pathlib.Path(d)
        (d / "robot.yaml").write_text(IRSIM_ROBOT)
        (d / "crowd.yaml").write_text(IRSIM_CROWD)
        (d / "crowd.toml").write_text(RONAP_CROWD)
        rows = [
            ("a robot with a 17-beam laser among walls", ["--scenario", str(ROOT / "scenarios" / "paper-maze.toml")], d / "robot.yaml"),
            ("100 ORCA / RVO agents", ["--scenario", str(d / "crowd.toml")], d / "crowd.yaml"),
        ]
        print("| what, one thread | ronap steps/s | IR-SIM steps/s | ratio |")
        print("| --- | ---: | ---: | ---: |")
        for name, ronap_args, world in rows:
            r = statistics.median(ronap_steps_per_second(a.ronap, ronap_args) for _ in range(a.rounds))
            i = statistics.median(irsim_steps_per_second(str(world), a.seconds) for _ in range(a.rounds))
            print(f"| {name} | {r:,.0f} | {i:,.0f} | {r / i:,.0f} |", flush=True)


if __name__ == "__main__":
    main()
