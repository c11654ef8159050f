"""nadf from Python: load and run world files, step a simulation, read its fields.

Everything is computed by the Rust crate (the extension module ``nadf._nadf``); this package
turns what it returns into NumPy arrays and dictionaries.

>>> import nadf
>>> summary = nadf.run("worlds/room-two-dividers.toml", set=["field.cell=0.1"])  # doctest: +SKIP
>>> summary["agents"][0]["reached"]                                              # doctest: +SKIP
True
"""

from __future__ import annotations

import io
import json
import os
from typing import Dict, List, Optional, Sequence, Union

import numpy as np

from . import _nadf
from ._nadf import RunError, World, WorldError

__all__ = ["load", "run", "Simulation", "World", "WorldError", "RunError"]

PathLike = Union[str, "os.PathLike[str]"]


def load(path: PathLike, set: Optional[Sequence[str]] = None) -> World:
    """Loads and checks the world file at ``path``, with ``--set`` overrides ``set``
    (``["field.cell=0.1", "agents.0.controller.b=5"]``).

    Raises :class:`WorldError` with the located message (file, line, key) when it does not load.
    """
    return _nadf.load(os.fspath(path), None if set is None else list(set))


def run(
    path: PathLike,
    set: Optional[Sequence[str]] = None,
    record: Optional[PathLike] = None,
    spawn: bool = False,
    connect: Optional[str] = None,
) -> dict:
    """Runs the world file at ``path`` to its duration, as ``nadf run`` does, and returns its
    summary: the dictionary ``nadf run --json`` writes. The recording as the CLI's options:
    ``record`` writes it to that file, ``spawn=True`` starts a Rerun viewer and streams into it,
    ``connect`` streams to the viewer at that URL (``"rerun+http://127.0.0.1:9876/proxy"``).
    The run releases the GIL.

    Raises :class:`WorldError` for a file that does not load, :class:`RunError` for a run that
    cannot be done (a target no path reaches, an output that cannot be written, no viewer at
    ``connect``).
    """
    text = _nadf.run_json(
        os.fspath(path),
        None if set is None else list(set),
        None if record is None else os.fspath(record),
        spawn,
        connect,
    )
    return json.loads(text)


class Simulation:
    """A running simulation of a world's disc agents, stepped from Python.

    Arrays have one row per agent, in the world file's order (``world.agents``).
    """

    def __init__(
        self,
        world: Union[World, PathLike],
        set: Optional[Sequence[str]] = None,
        record: Optional[PathLike] = None,
        spawn: bool = False,
        connect: Optional[str] = None,
    ):
        """Builds the simulation of ``world`` (a :class:`World`, or a path loaded with ``set``).
        With ``record``, ``spawn`` or ``connect`` (as :func:`run`'s), every step is recorded
        until :meth:`close` (or the end of a ``with`` block, or the object's end)."""
        if not isinstance(world, World):
            world = load(world, set)
        elif set is not None:
            raise TypeError("`set` is for a path; a loaded World already has its overrides")
        self.world: World = world
        self._sim = _nadf.Simulation(
            world, None if record is None else os.fspath(record), spawn, connect
        )

    @classmethod
    def _of(cls, world: World, sim: "_nadf.Simulation") -> "Simulation":
        """The simulation ``sim`` of ``world`` built elsewhere (an environment's episode)."""
        self = cls.__new__(cls)
        self.world = world
        self._sim = sim
        return self

    def step(self, n: int = 1) -> float:
        """Advances ``n`` physics steps (the GIL released while they run); returns the time, s."""
        if n < 0:
            raise ValueError(f"n must be at least 0, got {n}")
        return self._sim.step(n)

    def command(self, agent: int, force: Optional[Sequence[float]]) -> None:
        """Applies ``force`` (N, ``[fx, fy]``) to agent ``agent`` from the next step on instead of
        its control law's, until ``None`` gives control back. The law still runs (its bias or
        clamp moves on), but a lidar agent's field is re-solved for the walls it sees only
        when it is read (the law's force, the field's arrays) or control comes back; the
        clearance envelope, when on, still keeps the body off the walls;
        the speed limit and ``max_force`` do not apply. Raises ``ValueError`` for a force that
        is not finite."""
        self._sim.command(agent, None if force is None else [float(f) for f in force])

    def close(self) -> Optional[str]:
        """Ends the recording, if any: its verdict logged (interrupted, if the run has not
        reached its duration) and the file moved into place. Returns the file."""
        return self._sim.close()

    def __enter__(self) -> "Simulation":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def time(self) -> float:
        """Simulated time, s."""
        return self._sim.time

    @property
    def finished(self) -> bool:
        """Whether the run has reached the world's duration."""
        return self._sim.finished

    @property
    def position(self) -> np.ndarray:
        """Each agent's position, m: shape ``(agents, 2)``."""
        return np.array(self._sim.positions(), dtype=np.float64).reshape(-1, 2)

    @property
    def velocity(self) -> np.ndarray:
        """Each agent's velocity, m/s: shape ``(agents, 2)``."""
        return np.array(self._sim.velocities(), dtype=np.float64).reshape(-1, 2)

    @property
    def force(self) -> np.ndarray:
        """The control force each agent applied in the last step, N: shape ``(agents, 2)``."""
        return np.array(self._sim.forces(), dtype=np.float64).reshape(-1, 2)

    @property
    def heading(self) -> np.ndarray:
        """Each agent's heading, rad: a robot on wheels' own, another's the direction of its
        velocity (0 at rest): shape ``(agents,)``."""
        return np.array(self._sim.headings(), dtype=np.float64)

    @property
    def contacts(self) -> np.ndarray:
        """Contact starts of each agent so far: shape ``(agents,)``."""
        return np.array(self._sim.contacts(), dtype=np.int64)

    @property
    def touching(self) -> np.ndarray:
        """Whether each agent touches something now: shape ``(agents,)``."""
        return np.array(self._sim.touching(), dtype=bool)

    def summaries(self) -> List[dict]:
        """Each agent's summary so far (the ``agents`` of ``nadf run --json``)."""
        return json.loads(self._sim.summaries_json())

    def field(self, agent: int = 0) -> Dict[str, object]:
        """Agent ``agent``'s current harmonic field, as ``nadf field --npy`` writes it: ``V``,
        ``W`` (``1 − V``, exact far below f64's resolution of ``V``), ``log10_W`` and ``mask``
        (0 reachable, 1 blocked, 2 free but cut off), each of shape ``(nx, ny)`` with element
        ``[i, j]`` the cell whose centre is ``origin + ((i + ½) cell, (j + ½) cell)``; and
        ``origin`` (m) and ``cell`` (m)."""
        (v, w, log_w, mask), origin, cell = self._sim.field_npy(agent)
        arrays = [np.load(io.BytesIO(b)) for b in (v, w, log_w, mask)]
        return {
            "V": arrays[0],
            "W": arrays[1],
            "log10_W": arrays[2],
            "mask": arrays[3],
            "origin": tuple(origin),
            "cell": cell,
        }
