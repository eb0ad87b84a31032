#!/usr/bin/env python3
"""Writes crates/ronap-core/tests/data/orca-rvo2.json: one ORCA step of random crowds computed by
RVO2 itself (the `pyrvo` bindings, `pip install pyrvo==0.4.3`), for the core's ORCA to be held to.

Each case is 2-50 agents with their own radius, speed limit, velocity and preferred velocity, half
of them among 1-3 boxes; every input is a multiple of 1/64 (exact in RVO2's float). A case is
kept only if RVO2 split no obstacle edge (its obstacle tree may cut edges into pieces, which
ronap does not). The file records the inputs, each agent's neighbours as RVO2 chose them and its
new velocity; with --rvo2-double, also the new velocity RVO2 gives built in double precision
(RVO2's sources with every float made a double, and a driver reading this script's crowds on
stdin: see --rvo2-double's help), which the core's f64 ORCA is held to.

    .venv/bin/python scripts/orca-reference.py [--cases 80] [--seed 1] [--rvo2-double BIN]
"""

import argparse
import json
import pathlib
import random
import subprocess

import pyrvo


def q(x):
    """`x` rounded to a multiple of 1/64."""
    return round(x * 64) / 64


def case(rng, with_boxes):
    n = rng.randint(2, 50)
    side = q(rng.uniform(60, 240))
    params = {
        "time_step": q(rng.choice([1.0, 0.25, 0.5])),
        "neighbor_dist": q(rng.uniform(15, 80)),
        "max_neighbors": rng.randint(1, 12),
        "time_horizon": q(rng.uniform(1, 10)),
        "time_horizon_obst": q(rng.uniform(1, 10)),
    }
    boxes = []
    if with_boxes:
        for _ in range(rng.randint(1, 3)):
            x0, y0 = q(rng.uniform(0, side)), q(rng.uniform(0, side))
            w, h = q(rng.uniform(5, 40)), q(rng.uniform(5, 40))
            boxes.append([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]])

    def inside(p, r):
        return any(
            b[0][0] - r <= p[0] <= b[1][0] + r and b[0][1] - r <= p[1] <= b[2][1] + r for b in boxes
        )

    agents = []
    while len(agents) < n:
        r = q(rng.uniform(2, 8))
        p = [q(rng.uniform(0, side)), q(rng.uniform(0, side))]
        if inside(p, r):
            continue
        speed = q(rng.uniform(0.5, 6))
        agents.append(
            {
                "position": p,
                "velocity": [q(rng.uniform(-speed, speed)), q(rng.uniform(-speed, speed))],
                "preferred": [q(rng.uniform(-8, 8)), q(rng.uniform(-8, 8))],
                "radius": r,
                "max_speed": speed,
            }
        )
    sim = pyrvo.RVOSimulator()
    sim.set_time_step(params["time_step"])
    for a in agents:
        k = sim.add_agent(
            tuple(a["position"]),
            params["neighbor_dist"],
            params["max_neighbors"],
            params["time_horizon"],
            params["time_horizon_obst"],
            a["radius"],
            a["max_speed"],
            tuple(a["velocity"]),
        )
        sim.set_agent_pref_velocity(k, tuple(a["preferred"]))
    for b in boxes:
        sim.add_obstacle([tuple(v) for v in b])
    sim.process_obstacles()
    if sim.get_num_obstacle_vertices() != 4 * len(boxes):
        return None
    sim.do_step()
    for k, a in enumerate(agents):
        v = sim.get_agent_velocity(k)
        # Nine significant digits give back RVO2's float exactly.
        a["new_velocity"] = [float(f"{v.x:.9g}"), float(f"{v.y:.9g}")]
        a["agent_neighbours"] = [
            sim.get_agent_agent_neighbor(k, j) for j in range(sim.get_agent_num_agent_neighbors(k))
        ]
        a["obstacle_neighbours"] = [
            sim.get_agent_obstacle_neighbor(k, j)
            for j in range(sim.get_agent_num_obstacle_neighbors(k))
        ]
    return {"params": params, "boxes": boxes, "agents": agents}


def double_velocities(binary, cases):
    """Each case's new velocities from RVO2 built in double precision (`binary`)."""
    lines = [f"cases {len(cases)}"]
    for c in cases:
        p = c["params"]
        lines.append(
            f"case {p['time_step']} {p['neighbor_dist']} {p['max_neighbors']} "
            f"{p['time_horizon']} {p['time_horizon_obst']} {len(c['agents'])} {len(c['boxes'])}"
        )
        for b in c["boxes"]:
            lines.append("box " + " ".join(f"{x} {y}" for x, y in b))
        for a in c["agents"]:
            values = [*a["position"], *a["velocity"], *a["preferred"], a["radius"], a["max_speed"]]
            lines.append("agent " + " ".join(str(v) for v in values))
    out = subprocess.run(
        [binary], input="\n".join(lines) + "\n", capture_output=True, text=True, check=True
    ).stdout.split("\n")
    k = 0
    for c in cases:
        for a in c["agents"]:
            a["new_velocity_f64"] = [float(v) for v in out[k].split()]
            k += 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=80)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument(
        "--out",
        default=str(
            pathlib.Path(__file__).resolve().parent.parent
            / "crates/ronap-core/tests/data/orca-rvo2.json"
        ),
    )
    ap.add_argument(
        "--rvo2-double",
        help="RVO2 built in double precision: its src/ with `sed -E 's/\\bfloat\\b/double/g; "
        "s/([0-9.])F\\b/\\1/g'`, compiled with a driver that reads 'cases N', then per case "
        "'case time_step neighbor_dist max_neighbors time_horizon time_horizon_obst agents boxes', "
        "'box x0 y0 ... x3 y3' lines and 'agent px py vx vy prefx prefy radius max_speed' lines, "
        "and prints each agent's velocity after doStep as '%%.17g %%.17g'",
    )
    args = ap.parse_args()
    rng = random.Random(args.seed)
    cases = []
    while len(cases) < args.cases:
        c = case(rng, with_boxes=len(cases) % 2 == 1)
        if c is not None:
            cases.append(c)
    if args.rvo2_double:
        double_velocities(args.rvo2_double, cases)
    text = json.dumps({"pyrvo": "0.4.3", "cases": cases}, separators=(",", ":"))
    pathlib.Path(args.out).write_text(text + "\n")
    agents = sum(len(c["agents"]) for c in cases)
    print(f"{len(cases)} cases, {agents} agents -> {args.out} ({len(text) // 1024} KiB)")


if __name__ == "__main__":
    main()
