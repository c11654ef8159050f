"""NADF as the policy of one Gymnasium episode in the paper's room, and its path on the field.

    pip install "./python[test]"     # nadf with gymnasium and matplotlib
    python3 examples/gym_nadf.py [--out room-episode.png]

A learned policy would replace `expert_action()`; the episode's return is the baseline it must
beat (progress towards the target, minus a penalty per contact).
"""

import argparse
import pathlib

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")  # a file, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nadf.gym  # noqa: E402,F401  (registers nadf/Navigation-v0)

ROOM = pathlib.Path(__file__).resolve().parents[1] / "worlds" / "room-two-dividers.toml"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default="room-episode.png", help="the picture to write")
args = parser.parse_args()

# 1. The environment, and one episode with NADF's own force as the action.
env = gym.make("nadf/Navigation-v0", world=ROOM)
obs, info = env.reset(seed=0)
path, episode_return = [env.unwrapped.simulation.position[0]], 0.0
while True:
    action = env.unwrapped.expert_action()
    obs, reward, terminated, truncated, info = env.step(action)
    path.append(env.unwrapped.simulation.position[0])
    episode_return += reward
    if terminated or truncated:
        break
path = np.array(path)
print(
    f"{'arrived' if terminated else 'truncated'} at t = {info['time']:.2f} s, "
    f"{info['distance']:.3f} m from the target, {info['contacts']} contacts, "
    f"return {episode_return:.3f} (force limit {info['force_limit']:g} N)"
)

# 2. The path over the harmonic field it followed: log10(1 - V), walls in grey.
field = env.unwrapped.simulation.field(0)
(x0, y0), cell = field["origin"], field["cell"]
nx, ny = field["mask"].shape
extent = (x0, x0 + nx * cell, y0, y0 + ny * cell)
shown = np.ma.masked_where(field["mask"] != 0, field["log10_W"])
fig, ax = plt.subplots(figsize=(6, 6))
ax.imshow(field["mask"].T == 1, origin="lower", extent=extent, cmap="Greys", vmax=1.5)
im = ax.imshow(shown.T, origin="lower", extent=extent, cmap="viridis", alpha=0.8)
ax.plot(path[:, 0], path[:, 1], color="white", lw=2, label="NADF through the environment")
ax.plot(*path[0], "o", color="orange", label="start")
ax.plot(*env.unwrapped.agent.target, "*", color="red", ms=14, label="target")
ax.set(xlabel="x (m)", ylabel="y (m)", title=f"return {episode_return:.2f} in {info['time']:.2f} s")
fig.colorbar(im, ax=ax, label="log10(1 − V)", shrink=0.8)
ax.legend(loc="upper right")
fig.savefig(args.out, dpi=100, bbox_inches="tight")
print(f"wrote {args.out}")
