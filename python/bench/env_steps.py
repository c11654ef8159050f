"""Environment steps per second of `nadf/Navigation-v0` on the paper's room, without a sensor
and with a 180-ray lidar: random actions (drawn beforehand, so the policy costs nothing) and
NADF's own (`expert_action()` each step), through `gymnasium.make` (its wrappers included) and
on the unwrapped environment; and of the PettingZoo crowd `circle-16`.

    python3 python/bench/env_steps.py [--steps 20000]

Each episode runs until it terminates or truncates, then resets; resets are timed too.
"""

import argparse
import pathlib
import time

import gymnasium as gym
import numpy as np

import nadf.gym  # noqa: F401  (registers nadf/Navigation-v0)
from nadf.zoo import parallel_env

ROOT = pathlib.Path(__file__).resolve().parents[2]
ROOM = ROOT / "worlds" / "room-two-dividers.toml"
CIRCLE = ROOT / "worlds" / "crowds" / "circle-16.toml"
LIDAR = [
    'agents.0.sensor.kind="lidar"',
    "agents.0.sensor.range=3.0",
    "agents.0.sensor.rays=180",
    "agents.0.sensor.rate=10.0",
]


def rate(env, steps, policy):
    """Environment steps per second over `steps` steps of `policy(env)` (episodes reset)."""
    env.reset(seed=0)
    start = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(policy(env))
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20000)
    args = parser.parse_args()
    actions = np.random.default_rng(0).uniform(-1, 1, (args.steps, 2)).astype(np.float32)
    for name, sets in {"no sensor": [], "180-ray lidar": LIDAR}.items():
        made = gym.make("nadf/Navigation-v0", world=ROOM, set=sets)
        for label, env in (("gym.make", made), ("unwrapped", made.unwrapped)):
            it = iter(actions)
            random = rate(env, args.steps, lambda e: next(it))
            expert = rate(env, args.steps, lambda e: e.unwrapped.expert_action())
            print(
                f"room, {name:14s} {label:10s} random actions {random:8.0f} steps/s, "
                f"expert {expert:8.0f} steps/s"
            )
    env = parallel_env(CIRCLE)
    env.reset(seed=0)
    steps, start = 0, time.perf_counter()
    while env.agents and steps < args.steps // 10:
        env.step({a: env.expert_action(a) for a in env.agents})
        steps += 1
    elapsed = time.perf_counter() - start
    print(
        f"circle-16 (PettingZoo, 16 agents, expert actions): {steps / elapsed:.0f} steps/s, "
        f"{steps * 0.01 / elapsed:.2f}x real time"
    )


if __name__ == "__main__":
    main()
