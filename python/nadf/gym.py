"""A Gymnasium environment made from any world file: one agent driven by the policy, the
others keeping their own controllers. Importing this module registers it as
``nadf/Navigation-v0``.

>>> import gymnasium as gym
>>> import nadf.gym
>>> env = gym.make("nadf/Navigation-v0", world="worlds/room-two-dividers.toml")  # doctest: +SKIP
>>> obs, info = env.reset(seed=0)                                                # doctest: +SKIP
>>> obs, reward, terminated, truncated, info = env.step(env.unwrapped.expert_action())  # doctest: +SKIP

- **Action**: ``Box(-1, 1, (2,))``, the force in the body frame over the agent's force limit
  (its ``max_force``; else ``force_limit``; else measured: the largest force component of its
  own law over a run of the world, so that the expert's actions fit). A disc has no
  orientation: its body frame is the world's axes at its position; a robot on wheels' turns
  with its heading.
- **Observation**: a ``Dict`` of ``goal`` (the target relative to the body, body frame, m),
  ``velocity`` (body frame, m/s), and ``lidar`` (the last scan's ranges, m, ray ``k`` at
  ``−fov/2 + (k + ½) fov/rays`` from the direction to the target) when the agent has one, or
  ``guidance`` (the unit direction of steepest descent of its harmonic field, body frame)
  when it does not. All ``float32``.
- **Reward**: the progress towards the target in the step (m) minus ``contact_penalty`` per
  contact started (against anything).
- **Episode**: ``terminated`` on arrival (within the settling band, 5 % of the initial distance,
  at most ``arrival_speed`` fast), ``truncated`` at the world's duration.
- ``reset(seed=s)`` runs the world with its seed ``s`` (everything random: sensor noise, lidar
  dropout, wandering obstacles); ``reset()`` after a seeded reset draws the next episode's seed
  from a generator seeded by ``s``, and before any seed runs the world's own.
- ``env.unwrapped.expert_action()``: the action of the agent's own law (NADF in the paper's
  worlds) in the current state, the baseline a learned policy must beat.
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Sequence, Tuple, Union

import gymnasium
import numpy as np

from . import _nadf
from ._env import (
    Controlled,
    Episodes,
    PathLike,
    agent_index,
    load_world,
    measured_force_limit,
)
from . import Simulation
from ._nadf import World

__all__ = ["NavigationEnv"]

ENV_ID = "nadf/Navigation-v0"


class NavigationEnv(gymnasium.Env):
    """One agent of a world, driven by the policy (see the module's documentation).

    :param world: a world file, or a loaded :class:`nadf.World`.
    :param set: ``--set`` overrides for a world file (``["field.cell=0.1"]``).
    :param agent: the controlled agent, by index or name.
    :param force_limit: N, for an agent without ``max_force`` (default: measured).
    :param frame_skip: physics steps per environment step (the action held over them).
    :param contact_penalty: subtracted from the reward per contact start.
    :param arrival_speed: m/s, the largest speed of an arrival.
    """

    metadata: Dict[str, Any] = {"render_modes": []}

    def __init__(
        self,
        world: Union[World, PathLike],
        set: Optional[Sequence[str]] = None,
        agent: Union[int, str] = 0,
        force_limit: Optional[float] = None,
        frame_skip: int = 1,
        contact_penalty: float = 1.0,
        arrival_speed: float = 0.1,
    ):
        super().__init__()
        if frame_skip < 1:
            raise ValueError(f"frame_skip must be at least 1, got {frame_skip}")
        self.world = load_world(world, set)
        index = agent_index(self.world, agent)
        self.frame_skip = int(frame_skip)
        sim = _nadf.Simulation(self.world)
        if force_limit is None and sim.agent_info(index)[3] is None:
            force_limit = measured_force_limit(self.world, [index])[index]
        self.agent = Controlled(
            sim, self.world, index, force_limit or 0.0, contact_penalty, arrival_speed
        )
        self.observation_space = self.agent.observation_space
        self.action_space = self.agent.action_space
        self._episodes = Episodes(self.world)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> Tuple[Dict[str, np.ndarray], Dict[str, Any]]:
        super().reset(seed=seed)
        world = self._episodes.begin(seed)
        if world is not None:
            self.agent.bind(_nadf.Simulation(world))
        obs = self.agent.observe()
        return obs, self.agent.info(0.0)

    def step(
        self, action: Sequence[float]
    ) -> Tuple[Dict[str, np.ndarray], float, bool, bool, Dict[str, Any]]:
        agent = self.agent
        before = agent.distance
        agent.sim.command(agent.index, agent.force(action))
        time = agent.sim.step(self.frame_skip)
        obs = agent.observe()
        terminated = agent.arrived()
        truncated = not terminated and agent.sim.finished
        return obs, agent.reward(before), terminated, truncated, agent.info(time)

    def expert_action(self) -> np.ndarray:
        """The action of the agent's own law in the current state (see
        :meth:`nadf._env.Controlled.expert_action`)."""
        return self.agent.expert_action()

    @property
    def simulation(self) -> Simulation:
        """The current episode's simulation (positions, fields, summaries so far)."""
        return Simulation._of(self._episodes.current, self.agent.sim)

    @property
    def episode_seed(self) -> int:
        """The seed of the current episode's world."""
        return self._episodes.seed


gymnasium.register(ENV_ID, entry_point=NavigationEnv, disable_env_checker=False)
