"""The Gymnasium and PettingZoo environments: their checkers pass, NADF driven through them is
NADF, episodes are deterministic by seed, and the reward counts progress and contacts."""

import math
import pathlib
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test

import nadf
import nadf.gym
from nadf.zoo import parallel_env

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLDS = ROOT / "worlds"
ROOM = WORLDS / "room-two-dividers.toml"
LIDAR = [
    'agents.0.sensor.kind="lidar"',
    "agents.0.sensor.range=3.0",
    "agents.0.sensor.rays=180",
    "agents.0.sensor.rate=10.0",
]


def episode(env, policy, seed=None, limit=100_000):
    """Steps `env` from `reset(seed)` with `policy(env, obs)` to the episode's end: the
    observations, rewards and the last step's flags and info."""
    obs, _ = env.reset(seed=seed)
    observations, rewards = [obs], []
    for _ in range(limit):
        obs, reward, terminated, truncated, info = env.step(policy(env, obs))
        observations.append(obs)
        rewards.append(reward)
        if terminated or truncated:
            return observations, rewards, terminated, truncated, info
    raise AssertionError("the episode did not end")


def expert(env, obs):
    return env.unwrapped.expert_action()


def test_gymnasium_checks_the_environment_with_and_without_a_lidar():
    for sets in ([], LIDAR):
        env = gym.make("nadf/Navigation-v0", world=ROOM, set=sets + ["duration=2"])
        with warnings.catch_warnings():
            # The velocity has no natural bound: the checker only remarks on it.
            warnings.filterwarnings("ignore", message=".*infinity.*")
            check_env(env.unwrapped)
        space = env.observation_space
        assert set(space.spaces) == ({"goal", "velocity", "lidar"} if sets else {"goal", "velocity", "guidance"})
        assert env.action_space.shape == (2,) and env.action_space.dtype == np.float32


def test_nadf_through_the_environment_is_nadf():
    """In the paper's room (no replanning, no lidar) the expert's actions, commanded for each
    step, drive the body exactly where its law does; the episode ends on arrival without a
    touch, when the law's run settles."""
    env = gym.make("nadf/Navigation-v0", world=ROOM)
    limit = env.unwrapped.agent.force_limit
    assert limit == 34.0  # measured: the law's largest force component is 33.6 N
    observations, rewards, terminated, truncated, info = episode(env, expert)
    assert terminated and not truncated
    steps = len(rewards)
    law = nadf.Simulation(ROOM)
    law.step(steps)
    ours = env.unwrapped.simulation.position[0]
    assert np.allclose(ours, law.position[0], atol=1e-5), (ours, law.position[0])
    summary = env.unwrapped.simulation.summaries()[0]
    assert summary["contacts"] == 0 and info["contacts"] == 0
    # The run's own settling time is 4.85 s; the episode ends when the body is in the band and
    # slower than 0.1 m/s.
    assert 4.85 <= info["time"] <= 6.0
    # No contacts: the rewards add up to the distance covered towards the target.
    start = math.dist([8.5, 1.5], [1.5, 8.5])
    assert sum(rewards) == pytest.approx(start - info["distance"], abs=1e-9)
    assert np.allclose(observations[0]["goal"], [-7.0, 7.0])


def test_the_expert_changes_nothing():
    env = nadf.gym.NavigationEnv(ROOM)
    env.reset()
    for _ in range(50):
        env.step(np.array([0.3, -0.2], dtype=np.float32))
    before = env.simulation.position
    first = env.expert_action()
    assert np.array_equal(first, env.expert_action())
    assert np.array_equal(env.simulation.position, before)
    assert env.action_space.contains(first)


def test_a_seed_makes_an_episode_and_another_seed_another():
    """Lidar dropout is the world's randomness: the same seed gives the same observations, step
    for step; another seed other scans; `reset()` after a seeded one draws the next seed."""
    sets = LIDAR + ["agents.0.sensor.dropout=0.3", "duration=1"]
    env = gym.make("nadf/Navigation-v0", world=ROOM, set=sets)
    fixed = np.array([0.5, 0.5], dtype=np.float32)
    run = lambda seed: episode(env, lambda e, o: fixed, seed=seed)[0]  # noqa: E731
    a, b, c = run(7), run(7), run(8)
    assert all(np.array_equal(x["lidar"], y["lidar"]) for x, y in zip(a, b))
    assert any(not np.array_equal(x["lidar"], y["lidar"]) for x, y in zip(a, c))
    env.reset(seed=7)
    after_seven = env.unwrapped.episode_seed
    env.reset()
    drawn = env.unwrapped.episode_seed
    env.reset(seed=7)
    env.reset()
    assert env.unwrapped.episode_seed == drawn != after_seven


def test_the_lidar_observation_is_the_last_scan():
    env = nadf.gym.NavigationEnv(ROOM, set=LIDAR)
    obs, _ = env.reset()
    assert obs["lidar"].shape == (180,) and np.all(obs["lidar"] == 3.0)  # nothing scanned yet
    obs, *_ = env.step(np.zeros(2, dtype=np.float32))
    ranges = obs["lidar"]
    assert env.observation_space["lidar"].contains(ranges)
    # The robot at (8.5, 1.5) sees the outer walls 1.5 m below it and to its right.
    assert ranges.min() == pytest.approx(1.5 - 0.0, abs=0.11)
    assert (ranges < 3.0).sum() > 30


def test_a_contact_costs_the_penalty():
    """Without the clearance envelope, full force into the wall below touches it: the step
    that touches loses `contact_penalty`, and the info counts the contact."""
    sets = ["agents.0.controller.envelope=false", "duration=3"]
    env = nadf.gym.NavigationEnv(ROOM, set=sets, contact_penalty=5.0)
    down = np.array([0.0, -1.0], dtype=np.float32)
    _, rewards, _, _, info = episode(env, lambda e, o: down)
    assert info["contacts"] >= 1
    assert min(rewards) < -4.9
    # With the envelope (the default) the same push never touches.
    env = nadf.gym.NavigationEnv(ROOM, set=["duration=3"], contact_penalty=5.0)
    _, rewards, _, _, info = episode(env, lambda e, o: down)
    assert info["contacts"] == 0 and min(rewards) > -0.1


def test_a_robot_on_wheels_is_observed_in_its_own_frame():
    world = nadf.load(WORLDS / "tb3-burger.toml")
    env = nadf.gym.NavigationEnv(world, force_limit=2.0)
    obs, _ = env.reset()
    sim = env.simulation
    heading = sim.heading[0]
    target = np.array(env.agent.target)
    to_goal = target - sim.position[0]
    c, s = math.cos(heading), math.sin(heading)
    assert np.allclose(obs["goal"], [c * to_goal[0] + s * to_goal[1], -s * to_goal[0] + c * to_goal[1]], atol=1e-5)


def test_bad_arguments_say_what_is_wrong():
    with pytest.raises(ValueError, match="no agent named 'nobody'"):
        nadf.gym.NavigationEnv(ROOM, agent="nobody")
    with pytest.raises(IndexError, match="has 1 agent"):
        nadf.gym.NavigationEnv(ROOM, agent=3)
    with pytest.raises(nadf.WorldError, match=r"room-two-dividers.toml: `agents.0.mass`: .*positive"):
        nadf.gym.NavigationEnv(ROOM, set=["agents.0.mass=-1"])
    with pytest.raises(ValueError, match="frame_skip"):
        nadf.gym.NavigationEnv(ROOM, frame_skip=0)
    env = nadf.gym.NavigationEnv(ROOM)
    env.reset()
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([np.nan, 0.0]))


def test_pettingzoo_checks_the_crowd_and_nadf_crosses_it():
    swap = WORLDS / "swap.toml"
    parallel_api_test(parallel_env(swap, set=["duration=2"]), num_cycles=100)
    env = parallel_env(WORLDS / "crowds" / "circle-8.toml")
    obs, _ = env.reset(seed=0)
    assert set(obs) == set(env.possible_agents) and len(env.possible_agents) == 8
    arrived = set()
    while env.agents:
        actions = {a: env.expert_action(a) for a in env.agents}
        _, _, terminations, truncations, infos = env.step(actions)
        arrived |= {a for a, t in terminations.items() if t}
        assert not any(truncations.values()), infos
    assert arrived == set(env.possible_agents)
    summaries = env.simulation.summaries()
    assert all(s["contacts"] == 0 and s["reached"] for s in summaries)


def test_the_example_runs_an_episode_and_draws_it(tmp_path):
    out = tmp_path / "episode.png"
    done = subprocess.run(
        [sys.executable, ROOT / "examples" / "gym_nadf.py", "--out", out],
        check=True,
        capture_output=True,
        text=True,
    )
    assert done.stdout.startswith("arrived at t = 5.27 s"), done.stdout
    assert "0 contacts" in done.stdout
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000
