"""MAPPO-style training of one shared policy for every robot of a team scenario, through
torchrl's ``PettingZooWrapper`` around ``ronap.MultiNavEnv``: a shared actor on each robot's own
observation, a centralised critic on the global ``state()`` and the robot's index, PPO's clipped
loss, robots that are done masked out.

    python examples/mappo_torchrl.py --scenario scenarios/warehouse-team.toml --iterations 20

Prints one line per iteration: the mean reward per live robot-step, and the robots' success so
far. A sketch to start from (no tuning): BenchMARL builds on the same wrapper.
"""

from __future__ import annotations

import argparse

import torch
from torch import nn
from torchrl.envs.libs.pettingzoo import PettingZooWrapper

import ronap


def main(argv: list[str] | None = None) -> dict[str, float]:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="scenarios/warehouse-team.toml")
    p.add_argument("--iterations", type=int, default=20)
    p.add_argument("--steps", type=int, default=200, help="environment steps per iteration")
    p.add_argument("--max-steps", type=int, default=200, help="episode limit")
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    torch.manual_seed(args.seed)

    env = PettingZooWrapper(
        ronap.MultiNavEnv(scenario=args.scenario, episode_max_steps=args.max_steps),
        return_state=True,
        use_mask=True,
        categorical_actions=True,
        seed=args.seed,
    )
    (group,) = env.group_map  # every robot in one group: "robot"
    robots = len(env.group_map[group])
    obs_size = env.observation_spec[group, "observation"].shape[-1]
    state_size = env.observation_spec["state"].shape[-1]
    actor = nn.Sequential(nn.Linear(obs_size, 64), nn.Tanh(), nn.Linear(64, 3))
    critic = nn.Sequential(nn.Linear(state_size + robots, 64), nn.Tanh(), nn.Linear(64, 1))
    optim = torch.optim.Adam([*actor.parameters(), *critic.parameters()], lr=3e-4)
    ids = torch.eye(robots)

    def value(state: torch.Tensor) -> torch.Tensor:  # [T, state] -> [T, robots]
        s = state.unsqueeze(-2).expand(*state.shape[:-1], robots, state_size)
        return critic(torch.cat([s, ids.expand(*state.shape[:-1], robots, robots)], -1)).squeeze(-1)

    td = env.reset()
    successes, finished, summary = 0, 0, {}
    for it in range(args.iterations):
        batch: dict[str, list[torch.Tensor]] = {k: [] for k in ("obs", "state", "mask", "act", "logp", "rew", "done", "next_state")}
        with torch.no_grad():
            for _ in range(args.steps):
                obs, mask = td[group, "observation"], td[group, "mask"]
                dist = torch.distributions.Categorical(logits=actor(obs))
                action = dist.sample()
                td[group, "action"] = action
                td = env.step(td)
                nxt = td["next"]
                done = nxt[group, "done"].squeeze(-1)
                ended = done & mask
                finished += int(ended.sum())
                successes += int((nxt[group, "info", "success"] > 0)[ended].sum())
                for k, v in (("obs", obs), ("state", td["state"]), ("mask", mask), ("act", action), ("logp", dist.log_prob(action)),
                             ("rew", nxt[group, "reward"].squeeze(-1)), ("done", done), ("next_state", nxt["state"])):
                    batch[k].append(v)
                td = env.reset() if bool(nxt["done"].all()) else td["next"]
            b = {k: torch.stack(v) for k, v in batch.items()}
            m = b["mask"].float()
            # One-step advantages (TD(0)); GAE would add a backward pass over the batch.
            target = b["rew"] + 0.99 * value(b["next_state"]) * (~b["done"]).float()
            adv = target - value(b["state"])
            adv = (adv - adv[m > 0].mean()) / (adv[m > 0].std() + 1e-8)
        for _ in range(4):
            logp = torch.distributions.Categorical(logits=actor(b["obs"])).log_prob(b["act"])
            ratio = (logp - b["logp"]).exp()
            policy_loss = -torch.min(ratio * adv, ratio.clamp(0.8, 1.2) * adv)
            value_loss = (value(b["state"]) - target) ** 2
            loss = ((policy_loss + 0.5 * value_loss) * m).sum() / m.sum()
            optim.zero_grad()
            loss.backward()
            optim.step()
        summary = {
            "iteration": it,
            "reward": float((b["rew"] * m).sum() / m.sum()),
            "robots_finished": finished,
            "success": successes / finished if finished else 0.0,
        }
        print(f"iteration {it:3}  reward/step {summary['reward']:+.3f}  robots done {finished:5}  success {summary['success']:.2f}")
    env.close()
    return summary


if __name__ == "__main__":
    main()
