"""A step among ORCA pedestrians, ronap against RVO2 itself (the `pyrvo` bindings of its C++):
N pedestrians (discs of 6 px, 2 px a step, neighbour distance 200 px, at most 10 neighbours, a
20-step horizon: ronap's `orca` defaults) walking to goals drawn in an open 1000 px hall, a new
goal at each arrival. ronap's figure is `ronap bench --threads 1` of that scenario (the robot's
17-beam laser and step included); RVO2's is its `do_step` alone, the preferred velocities set
outside the clock.

    .venv/bin/python scripts/bench-rvo2.py [RONAP_BIN] [--count N] [--seconds S]
"""

import argparse
import math
import random
import re
import subprocess
import tempfile
import time

import pyrvo

SCENARIO = """[scene]
kind = "maze"

[maze]
cols = 1
rows = 1
cell_px = 1000.0

[episode]
min_goal_distance_px = 400.0

[[moving]]
count = {count}
shape = "disc"
radius_px = 6.0
motion = "orca"
on_arrival = "new_goal"
"""


def rvo2_step_us(count: int, seconds: float) -> float:
    rng = random.Random(0)
    speed = 2.0
    sim = pyrvo.RVOSimulator()
    sim.set_time_step(1.0)
    goals = []
    for _ in range(count):
        sim.add_agent((rng.uniform(10, 990), rng.uniform(10, 990)), 200.0, 10, 20.0, 20.0, 6.0, speed, (0.0, 0.0))
        goals.append((rng.uniform(10, 990), rng.uniform(10, 990)))
    clock = 0.0
    steps = 0
    while clock < seconds:
        for k in range(count):
            p = sim.get_agent_position(k)
            dx, dy = goals[k][0] - p.x, goals[k][1] - p.y
            d = math.hypot(dx, dy)
            if d < 6.0:
                goals[k] = (rng.uniform(10, 990), rng.uniform(10, 990))
                dx, dy, d = 0.0, 0.0, 1.0
            s = min(speed, d) / d
            sim.set_agent_pref_velocity(k, (dx * s, dy * s))
        t = time.perf_counter()
        sim.do_step()
        clock += time.perf_counter() - t
        steps += 1
    return clock / steps * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bin", nargs="?", default="target/release/ronap", help="the ronap binary")
    ap.add_argument("--count", type=int, default=100, help="pedestrians")
    ap.add_argument("--seconds", type=float, default=3.0, help="time each side for about this long")
    args = ap.parse_args()
    with tempfile.NamedTemporaryFile("w", suffix=".toml", prefix="ronap-orca-") as f:
        f.write(SCENARIO.format(count=args.count))
        f.flush()
        out = subprocess.run(
            [args.bin, "bench", "--scenario", f.name, "--threads", "1", "--seconds", str(args.seconds)],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    m = re.search(r"one thread\s+([\d,]+) steps/s", out)
    if m is None:
        raise SystemExit(f"no 'one thread' figure in ronap bench's output:\n{out}")
    ronap_rate = float(m.group(1).replace(",", ""))
    rvo2 = rvo2_step_us(args.count, args.seconds)
    print(f"{args.count} ORCA pedestrians, one step:")
    print(f"  ronap (ronap bench --threads 1, laser and robot included)  {1e6 / ronap_rate:8.1f} us  ({ronap_rate:,.0f} steps/s)")
    print(f"  RVO2 (pyrvo do_step)                                      {rvo2:8.1f} us  ({1e6 / rvo2:,.0f} steps/s)")


if __name__ == "__main__":
    main()
