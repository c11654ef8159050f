"""A PettingZoo parallel environment made from a world with several agents (a crowd): every
agent driven by its own policy, with the action, observation and reward of ``nadf.gym``'s
environment each.

>>> from nadf.zoo import parallel_env
>>> env = parallel_env("worlds/crowds/circle-16.toml")            # doctest: +SKIP
>>> obs, infos = env.reset(seed=0)                                # doctest: +SKIP
>>> actions = {a: env.expert_action(a) for a in env.agents}        # doctest: +SKIP
>>> obs, rewards, terminations, truncations, infos = env.step(actions)  # doctest: +SKIP

An agent that arrives is ``terminated`` and leaves ``env.agents``; its own law takes it back
and holds it at its target (it stays a body the others must avoid). Every agent still moving
at the world's duration is ``truncated``.
"""

from __future__ import annotations

import functools
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import gymnasium
import numpy as np
from pettingzoo import ParallelEnv

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

__all__ = ["CrowdEnv", "parallel_env"]


class CrowdEnv(ParallelEnv):
    """The agents ``agents`` of a world (by index or name; default all), each driven by a
    policy; the world's other agents keep their controllers. The parameters are
    :class:`nadf.gym.NavigationEnv`'s, ``force_limit`` for every controlled agent without
    ``max_force`` (default: each measured)."""

    metadata: Dict[str, Any] = {"name": "nadf_crowd_v0", "render_modes": []}

    def __init__(
        self,
        world: Union[World, PathLike],
        set: Optional[Sequence[str]] = None,
        agents: Optional[Sequence[Union[int, str]]] = None,
        force_limit: Optional[float] = None,
        frame_skip: int = 1,
        contact_penalty: float = 1.0,
        arrival_speed: float = 0.1,
    ):
        if frame_skip < 1:
            raise ValueError(f"frame_skip must be at least 1, got {frame_skip}")
        self.world = load_world(world, set)
        chosen = range(len(self.world.agents)) if agents is None else agents
        indices = [agent_index(self.world, a) for a in chosen]
        if not indices or len({*indices}) != len(indices):
            raise ValueError(
                f"{self.world.path}: the controlled agents {list(chosen)} must be one or more, "
                "each once"
            )
        self.frame_skip = int(frame_skip)
        sim = _nadf.Simulation(self.world)
        unlimited = [i for i in indices if sim.agent_info(i)[3] is None]
        limits = {i: force_limit for i in unlimited}
        if force_limit is None and unlimited:
            limits = measured_force_limit(self.world, unlimited)
        self._controlled = {
            self.world.agents[i]: Controlled(
                sim, self.world, i, limits.get(i) or 0.0, contact_penalty, arrival_speed
            )
            for i in indices
        }
        self.possible_agents: List[str] = list(self._controlled)
        self.agents: List[str] = list(self.possible_agents)
        self._sim = sim
        self._episodes = Episodes(self.world)

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> gymnasium.spaces.Space:
        return self._controlled[agent].observation_space

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> gymnasium.spaces.Space:
        return self._controlled[agent].action_space

    def reset(
        self, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> Tuple[Dict[str, Dict[str, np.ndarray]], Dict[str, Dict[str, Any]]]:
        world = self._episodes.begin(seed)
        if world is not None:
            self._sim = _nadf.Simulation(world)
        self.agents = list(self.possible_agents)
        for a in self._controlled.values():
            a.bind(self._sim)
        obs = {name: self._controlled[name].observe() for name in self.agents}
        return obs, {name: self._controlled[name].info(0.0) for name in self.agents}

    def step(self, actions: Dict[str, Sequence[float]]) -> Tuple[
        Dict[str, Dict[str, np.ndarray]],
        Dict[str, float],
        Dict[str, bool],
        Dict[str, bool],
        Dict[str, Dict[str, Any]],
    ]:
        missing = [name for name in self.agents if name not in actions]
        if missing:
            raise KeyError(f"no action for the agents {missing}")
        before = {name: self._controlled[name].distance for name in self.agents}
        for name in self.agents:
            agent = self._controlled[name]
            self._sim.command(agent.index, agent.force(actions[name]))
        time = self._sim.step(self.frame_skip)
        finished = self._sim.finished
        obs, rewards, terminations, truncations, infos = {}, {}, {}, {}, {}
        for name in self.agents:
            agent = self._controlled[name]
            obs[name] = agent.observe()
            rewards[name] = agent.reward(before[name])
            terminations[name] = agent.arrived()
            truncations[name] = finished and not terminations[name]
            infos[name] = agent.info(time)
            if terminations[name]:
                # Its own law holds it at its target from now on.
                self._sim.command(agent.index, None)
        self.agents = [n for n in self.agents if not (terminations[n] or truncations[n])]
        return obs, rewards, terminations, truncations, infos

    def expert_action(self, agent: str) -> np.ndarray:
        """The action of ``agent``'s own law in the current state (see
        :meth:`nadf._env.Controlled.expert_action`)."""
        return self._controlled[agent].expert_action()

    @property
    def simulation(self) -> Simulation:
        """The current episode's simulation (positions, fields, summaries so far)."""
        return Simulation._of(self._episodes.current, self._sim)

    @property
    def episode_seed(self) -> int:
        """The seed of the current episode's world."""
        return self._episodes.seed


def parallel_env(world: Union[World, PathLike], **kwargs: Any) -> CrowdEnv:
    """A :class:`CrowdEnv` of ``world`` (PettingZoo's ``parallel_env`` convention)."""
    return CrowdEnv(world, **kwargs)
