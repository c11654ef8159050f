"""What the Gymnasium and PettingZoo environments share: one agent of a simulation driven by
a policy's actions, observed, and rewarded (``nadf.gym``, ``nadf.zoo``).

An action ``a`` in ``[-1, 1]²`` is the force ``F = R(θ) (a · F_max)``, N, in the world frame:
``F_max`` the agent's force limit, ``R(θ)`` the rotation of the agent's body frame (a robot on
wheels' heading; a disc has no orientation, so its body frame is the world's axes at its
position). The force is commanded for the environment step (``frame_skip`` physics steps);
the agent's law still runs beside it, and the clearance envelope, when on, still keeps the
body off the walls.
"""

from __future__ import annotations

import math
import os
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from gymnasium import spaces

from . import _nadf
from ._nadf import World

PathLike = Union[str, "os.PathLike[str]"]

#: Measured force limits, by world (as JSON) and agent (see :func:`measured_force_limit`).
_LIMITS: Dict[Tuple[str, int], float] = {}


def load_world(world: Union[World, PathLike], set: Optional[Sequence[str]]) -> World:
    """``world`` itself, or the world file at that path loaded with the overrides ``set``."""
    if isinstance(world, World):
        if set:
            raise TypeError("`set` is for a path; a loaded World already has its overrides")
        return world
    return _nadf.load(os.fspath(world), None if set is None else list(set))


def agent_index(world: World, agent: Union[int, str]) -> int:
    """The row of ``agent`` (an index or a name) in the world's agents."""
    names = world.agents
    if isinstance(agent, str):
        if agent not in names:
            raise ValueError(f"{world.path}: no agent named {agent!r} (the agents: {names})")
        return names.index(agent)
    if not 0 <= agent < len(names):
        raise IndexError(f"{world.path}: agent {agent}, but the world has {len(names)} agent(s)")
    return int(agent)


def round_up(x: float) -> float:
    """``x`` rounded up to two significant digits (34 for 33.48; 0.013 for 0.01234)."""
    if x <= 0.0:
        return 1.0
    unit = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.ceil(x / unit - 1e-9) * unit


def measured_force_limit(world: World, agents: Sequence[int]) -> Dict[int, float]:
    """The force limit of each of ``agents`` that has no ``max_force``, N: the largest
    component of its own law's force over a run of ``world`` in which every agent follows its
    law (the force applied in each step and the force the law gives for the state after it,
    :meth:`Expert.action`'s), rounded up to two significant digits. So the expert's actions lie
    in ``[-1, 1]`` and NADF driven through the environment is NADF. Measured once per world
    file, overrides and seed, and cached."""
    text = world.to_json()
    key = lambda i: (text, i)  # noqa: E731
    todo = [i for i in agents if key(i) not in _LIMITS]
    if todo:
        sim = _nadf.Simulation(world)
        peak = {i: 0.0 for i in todo}
        while not sim.finished:
            sim.step(1)
            forces = sim.forces()
            for i in todo:
                law = sim.law_force(i)
                peak[i] = max(peak[i], *map(abs, forces[i]), *map(abs, law))
        for i in todo:
            _LIMITS[key(i)] = round_up(peak[i])
    return {i: _LIMITS[key(i)] for i in agents}


class Episodes:
    """The worlds of an environment's episodes. ``begin(seed=s)`` runs the world with its
    seed ``s`` and seeds a generator from it; ``begin()`` after that draws the next episode's
    seed from the generator, and before any seed runs the world's own seed."""

    def __init__(self, world: World):
        self.world = world
        #: The current episode's world and seed.
        self.current = world
        self.seed = world.seed
        self._rng: Optional[np.random.Generator] = None
        self._fresh = True

    def begin(self, seed: Optional[int]) -> Optional[World]:
        """The world of the next episode, or ``None`` when it is the world the environment
        was built with and its first simulation has not been stepped (it serves again)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
            self.seed = int(seed)
        elif self._rng is not None:
            self.seed = int(self._rng.integers(0, 2**63))
        else:
            self.seed = self.world.seed
        fresh, self._fresh = self._fresh, False
        if fresh and self.seed == self.world.seed:
            return None
        self.current = self.world.reseeded(self.seed)
        return self.current


def to_body(theta: float, x: float, y: float) -> Tuple[float, float]:
    """The world-frame vector ``(x, y)`` in a body frame turned by ``theta`` (rad): ``R(θ)ᵀ``.
    (Two-vectors in plain floats: NumPy's per-call cost was most of an environment step.)"""
    c, s = math.cos(theta), math.sin(theta)
    return (c * x + s * y, c * y - s * x)


def to_world(theta: float, x: float, y: float) -> Tuple[float, float]:
    """The body-frame vector ``(x, y)`` in the world frame, the body turned by ``theta``
    (rad): ``R(θ)``."""
    c, s = math.cos(theta), math.sin(theta)
    return (c * x - s * y, s * x + c * y)


def unit_clip(v: float) -> float:
    """``v`` clipped to ``[-1, 1]``."""
    return min(max(v, -1.0), 1.0)


class Controlled:
    """One agent of a simulation under a policy: its spaces, its observation, its reward.

    ``force_limit`` (N) scales the actions: the agent's ``max_force`` when the world gives one,
    else this, else measured (:func:`measured_force_limit`). ``contact_penalty`` is subtracted
    from the reward per contact start; an agent within its settling band (5 % of its initial
    distance, where ``reached`` is judged) at a speed at most ``arrival_speed`` (m/s) has
    arrived.
    """

    def __init__(
        self,
        sim: _nadf.Simulation,
        world: World,
        index: int,
        force_limit: float,
        contact_penalty: float,
        arrival_speed: float,
    ):
        self.index = index
        self.name = world.agents[index]
        target, self.radius, self.mass, max_force, self.band, lidar = sim.agent_info(index)
        self.target = np.array(target)
        # The same in plain floats, for the observation's arithmetic.
        self._target = (float(target[0]), float(target[1]))
        self.force_limit = float(max_force if max_force is not None else force_limit)
        if not (self.force_limit > 0.0 and math.isfinite(self.force_limit)):
            raise ValueError(f"agent {self.name!r}: force limit {self.force_limit} N")
        self.contact_penalty = float(contact_penalty)
        self.arrival_speed = float(arrival_speed)
        self.lidar = lidar
        (x0, y0), (x1, y1) = world.bounds
        reach = float(math.hypot(x1 - x0, y1 - y0))
        parts = {
            "goal": spaces.Box(-reach, reach, (2,), np.float32),
            "velocity": spaces.Box(-np.inf, np.inf, (2,), np.float32),
        }
        if lidar is not None:
            rays, range_ = lidar
            parts["lidar"] = spaces.Box(0.0, range_, (rays,), np.float32)
        else:
            parts["guidance"] = spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.observation_space = spaces.Dict(parts)
        self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.bind(sim)

    def bind(self, sim: _nadf.Simulation) -> None:
        """Follows a new episode's simulation ``sim``."""
        self.sim = sim
        self.frame = 0.0
        self.position = self.target
        self.velocity = np.zeros(2)
        self.speed = 0.0
        self.contacts = 0
        self.distance = math.inf
        self.observe()

    def observe(self) -> Dict[str, np.ndarray]:
        """The observation now: the goal and the velocity in the body frame, and the lidar's
        last ranges (every ray at its range before the first scan) or the guidance direction
        in the body frame (zero where the field has none)."""
        position, velocity, frame, guidance, ranges, contacts = self.sim.observation(self.index)
        self.frame = frame
        self.position = np.array(position)
        self.velocity = np.array(velocity)
        self.speed = math.hypot(*velocity)
        self.new_contacts = contacts - self.contacts
        self.contacts = contacts
        goal = (self._target[0] - position[0], self._target[1] - position[1])
        self.distance = math.hypot(*goal)
        obs = {
            "goal": np.array(to_body(frame, *goal), np.float32),
            "velocity": np.array(to_body(frame, *velocity), np.float32),
        }
        if self.lidar is not None:
            rays, range_ = self.lidar
            scan = np.frombuffer(ranges, dtype="<f4")
            obs["lidar"] = scan.copy() if scan.size else np.full(rays, range_, np.float32)
        else:
            g = (0.0, 0.0) if guidance is None else to_body(frame, *guidance)
            obs["guidance"] = np.array(g, np.float32)
        return obs

    def force(self, action: Sequence[float]) -> List[float]:
        """The world-frame force, N, of ``action`` (clipped to ``[-1, 1]``)."""
        x, y = np.asarray(action, dtype=np.float64).reshape(2).tolist()
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"agent {self.name!r}: an action must be finite, got {action!r}")
        limit = self.force_limit
        return list(to_world(self.frame, unit_clip(x) * limit, unit_clip(y) * limit))

    def expert_action(self) -> np.ndarray:
        """The action of the agent's own law in the state it is in now: its force for the next
        step (computed without changing the run; a lidar agent's field is first solved for
        the walls seen since it was last solved), in the body frame, over the force limit,
        clipped to ``[-1, 1]``. For a world without replanning or a lidar this is the force
        the law applies, so the expert driven through the environment reproduces the law's
        run (to the actions' float32 rounding)."""
        x, y = to_body(self.frame, *self.sim.law_force(self.index))
        limit = self.force_limit
        return np.array([unit_clip(x / limit), unit_clip(y / limit)], np.float32)

    def arrived(self) -> bool:
        """Whether it is within its settling band, at most ``arrival_speed`` fast."""
        return self.distance <= self.band and self.speed <= self.arrival_speed

    def reward(self, before: float) -> float:
        """The progress towards the target since the distance was ``before`` (m), minus the
        contact penalty per contact started since."""
        return (before - self.distance) - self.contact_penalty * self.new_contacts

    def info(self, time: float) -> Dict[str, object]:
        """What the step's ``info`` reports of the agent."""
        return {
            "time": time,
            "distance": self.distance,
            "contacts": self.contacts,
            "force_limit": self.force_limit,
        }
