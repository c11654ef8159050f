"""How fast nadf steps from Python: the paper's room without a sensor and with a 180-ray lidar,
stepped one physics step per call (what an environment's `step` costs at the least) and all
steps in one call (`Simulation.step(n)`), against the same run done by the crate alone
(`nadf.run`, the path of `nadf run --no-record`).

    python3 python/bench/steps.py [--repeats 3]

Prints steps per second and the cost of one step-call from Python over the Rust loop.
"""

import argparse
import pathlib
import time

import nadf

ROOM = pathlib.Path(__file__).resolve().parents[2] / "worlds" / "room-two-dividers.toml"
LIDAR = [
    'agents.0.sensor.kind="lidar"',
    "agents.0.sensor.range=3.0",
    "agents.0.sensor.rays=180",
    "agents.0.sensor.rate=10.0",
]
CASES = {"no sensor": [], "180-ray lidar": LIDAR}


def best(repeats, f):
    """The shortest of `repeats` timings of `f()`, s."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--duration", type=float, default=10.0, help="simulated seconds")
    args = parser.parse_args()
    for name, sets in CASES.items():
        sets = sets + [f"duration={args.duration}"]
        world = nadf.load(ROOM, set=sets)
        steps = world.steps

        def build():
            return nadf.Simulation(world)

        setup = best(args.repeats, build)
        rust = best(args.repeats, lambda: nadf.run(ROOM, set=sets)) - setup

        def one_call():
            sim = build()
            start = time.perf_counter()
            sim.step(steps)
            return time.perf_counter() - start

        def per_step():
            sim = build()
            start = time.perf_counter()
            for _ in range(steps):
                sim.step()
            return time.perf_counter() - start

        batched = min(one_call() for _ in range(args.repeats))
        single = min(per_step() for _ in range(args.repeats))
        print(
            f"{name:14s} {steps} steps: nadf.run {steps / rust:9.0f} steps/s; "
            f"step({steps}) {steps / batched:9.0f} steps/s; "
            f"step() x {steps} {steps / single:9.0f} steps/s "
            f"({(single - batched) / steps * 1e6:.2f} µs per call over the loop)"
        )


if __name__ == "__main__":
    main()
