#!/usr/bin/env python3
"""Crowd campaign for the clearance envelope (issue "never a touch", item 3).

Writes crowd worlds, runs each with `nadf run --no-record --json` and prints one table row per
world: robots reached, contacts (walls and agents), the closest approach between two robots,
the robots flagged deadlocked (parked with a neighbour next to them) and livelocked (moving but
getting nowhere) at some time, the robots that did not reach by what they were flagged
(deadlocked / livelocked only / neither: a robot in the last column ran out of time while
still making progress), the last settling time, and the wall time against the simulated time.

    python3 scripts/crowds.py --nadf target/release/nadf --robots 16 32 --arc 2.5 1.8 1.2 \
        --seeds 0 1 2 --controller nadf orca --kinds circle crossing door

Worlds (radius 0.3 m, 1 kg, K = 1 N normalized, B_d = 10, 2 m/s, 0.1 m cells, 10 Hz local
replanning, as the shipped circles):
- circle: `n` robots evenly on a circle with `arc` metres of it each (its radius at least 2 m),
  each to the antipode, its target turned by 0.05 rad and its start angle jittered by up to
  ±0.01 rad by the seed;
- crossing: two flows of n/2 robots at right angles through the centre of a square room,
  `arc` metres apart in each flow;
- door: two groups of n/2 robots swapping sides of a room through a 2 m door in a wall.
Everything else is the world file's default: the envelope is on unless `--bare` turns it off.
"""

import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time

from machine import describe

ROBOT = 'radius = 0.3\ncontroller = {{ kind = "{kind}", {gains}speed_limit = 2.0{bare} }}\n'

# Whether the robots run without the clearance envelope (`--bare`).
BARE = False


def controller(kind):
    gains = "k = 1.0, b = 10.0, " if kind == "nadf" else ""
    return ROBOT.format(kind=kind, gains=gains, bare=", envelope = false" if BARE else "")


def header(name, size, duration, walls=""):
    return (
        f'name = "{name}"\nsize = [{size:.2f}, {size:.2f}]\ndt = 0.01\n'
        f"duration = {duration:.1f}\nseed = 0\n\n[field]\ncell = 0.1\nreplan_hz = 10.0\n{walls}"
    )


def agent(k, start, target, kind):
    return (
        f'\n[[agents]]\nname = "r{k:03}"\nstart = [{start[0]:.3f}, {start[1]:.3f}]\n'
        f"target = [{target[0]:.3f}, {target[1]:.3f}]\n" + controller(kind)
    )


def circle(n, arc, seed, kind):
    rng = random.Random(seed)
    radius = max(n * arc / math.tau, 2.0)
    size = 2 * radius + 2.4
    c = size / 2
    text = header(f"circle-{n}-{arc}-{seed}", size, 2 * radius + 40)
    for k in range(n):
        a = math.tau * k / n + rng.uniform(-0.01, 0.01)
        b = a + math.pi + 0.05
        start = (c + radius * math.cos(a), c + radius * math.sin(a))
        target = (c + radius * math.cos(b), c + radius * math.sin(b))
        text += agent(k, start, target, kind)
    return text


def crossing(n, arc, seed, kind):
    rng = random.Random(seed)
    half = n // 2
    length = half * arc
    size = 2 * length + 6
    c = size / 2
    text = header(f"crossing-{n}-{arc}-{seed}", size, 2 * length + 40)
    for k in range(half):
        offset = (k - (half - 1) / 2) * arc + rng.uniform(-0.05, 0.05)
        # Flow 1 goes east along rows, flow 2 north along columns: each robot crosses the
        # centre square, where the flows meet.
        text += agent(2 * k, (1.5, c + offset), (size - 1.5, c + offset), kind)
        text += agent(2 * k + 1, (c + offset, 1.5), (c + offset, size - 1.5), kind)
    return text


def door(n, arc, seed, kind):
    rng = random.Random(seed)
    half = n // 2
    cols = max(1, int(math.sqrt(half)))
    rows = math.ceil(half / cols)
    depth = rows * arc + 2
    width = max(cols * arc + 2, 8)
    size = max(width, 2 * depth + 2)
    c = size / 2
    # A wall across the room at y = c with a 2 m door in the middle.
    gap = 1.0
    walls = (
        f'\n[[walls]]\nshape = "box"\ncenter = [{(c - gap) / 2:.3f}, {c:.3f}]\n'
        f"half_extents = [{(c - gap) / 2:.3f}, 0.1]\n"
        f'\n[[walls]]\nshape = "box"\ncenter = [{(size + c + gap) / 2:.3f}, {c:.3f}]\n'
        f"half_extents = [{(size - c - gap) / 2:.3f}, 0.1]\n"
    )
    text = header(f"door-{n}-{arc}-{seed}", size, 60 + 4 * n, walls)
    k = 0
    for side in (-1, 1):
        for i in range(half):
            col, row = i % cols, i // cols
            x = c + (col - (cols - 1) / 2) * arc + rng.uniform(-0.05, 0.05)
            y = c + side * (1.2 + row * arc)
            text += agent(k, (x, y), (x, 2 * c - y), kind)
            k += 1
    return text


KINDS = {"circle": circle, "crossing": crossing, "door": door}


def run(nadf, text, extra):
    with tempfile.TemporaryDirectory() as tmp:
        world = os.path.join(tmp, "w.toml")
        out = os.path.join(tmp, "s.json")
        with open(world, "w") as f:
            f.write(text)
        started = time.time()
        proc = subprocess.run(
            [nadf, "run", world, "--no-record", "--json", out] + extra,
            capture_output=True,
            text=True,
        )
        wall = time.time() - started
        if proc.returncode != 0 and not os.path.exists(out):
            raise RuntimeError(proc.stderr + proc.stdout)
        with open(out) as f:
            return json.load(f), wall


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--nadf", required=True, help="the nadf binary")
    p.add_argument("--robots", type=int, nargs="+", default=[16])
    p.add_argument("--arc", type=float, nargs="+", default=[1.8])
    p.add_argument("--seeds", type=int, nargs="+", default=[0])
    p.add_argument("--controller", nargs="+", default=["nadf"], choices=["nadf", "orca"])
    p.add_argument("--kinds", nargs="+", default=["circle"], choices=sorted(KINDS))
    p.add_argument("--set", action="append", default=[], help="passed to nadf run --set")
    p.add_argument("--bare", action="store_true", help="the robots without the clearance envelope")
    args = p.parse_args()
    global BARE
    BARE = args.bare
    extra = [a for s in args.set for a in ("--set", s)]
    print(describe())
    print("world                      ctrl  robots reached contacts closest_m deadlocked livelocked unreached_d/l/-  last_settle_s  wall/sim")
    for kind in args.kinds:
        for n in args.robots:
            for arc in args.arc:
                for ctrl in args.controller:
                    for seed in args.seeds:
                        text = KINDS[kind](n, arc, seed, ctrl)
                        summary, wall = run(args.nadf, text, extra)
                        agents = summary["agents"]
                        duration = float(text.split("duration = ")[1].split("\n")[0])
                        reached = sum(a["reached"] for a in agents)
                        contacts = sum(a["contacts"] for a in agents)
                        closest = min(
                            (a["min_separation"] for a in agents if a["min_separation"] is not None),
                            default=float("inf"),
                        )
                        deadlocked = sum(a["deadlocked"] is not None for a in agents)
                        livelocked = sum(a["livelocked"] is not None for a in agents)
                        short = [a for a in agents if not a["reached"]]
                        dead = sum(a["deadlocked"] is not None for a in short)
                        live = sum(a["deadlocked"] is None and a["livelocked"] is not None for a in short)
                        why = f"{dead}/{live}/{len(short) - dead - live}"
                        settle = max((a["settling_time"] or float("nan") for a in agents), default=0)
                        print(
                            f"{kind}-{n}-{arc}-s{seed:<10} {ctrl:5} {len(agents):6} {reached:7} {contacts:8} "
                            f"{closest:9.4f} {deadlocked:10} {livelocked:10} {why:>15} {settle:14.2f} {wall / duration:9.3f}",
                            flush=True,
                        )


if __name__ == "__main__":
    sys.exit(main())
