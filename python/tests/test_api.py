"""The Python API over the crate: the summary is the CLI's JSON, arrays have their documented
shapes, a bad world raises with the located message, and a run is deterministic."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import nadf

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLDS = ROOT / "worlds"
ROOM = WORLDS / "room-two-dividers.toml"
COARSE = ["field.cell=0.1", "duration=8"]


def nadf_binary() -> pathlib.Path:
    """The CLI the tests compare with: the release binary the README's test command built."""
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    binary = target / "release" / "nadf"
    assert binary.is_file(), f"no {binary}: build it with `cargo build --release` first"
    return binary


def test_the_summary_is_the_clis_json(tmp_path):
    out = tmp_path / "cli.json"
    sets = [arg for s in COARSE for arg in ("--set", s)]
    subprocess.run(
        [nadf_binary(), "run", ROOM, "--no-record", "--json", out, *sets],
        check=True,
        capture_output=True,
    )
    cli = json.loads(out.read_text())
    assert nadf.run(ROOM, set=COARSE) == cli
    assert cli["agents"][0]["reached"] is True


def test_a_run_writes_its_recording(tmp_path):
    rrd = tmp_path / "room.rrd"
    summary = nadf.run(ROOM, set=COARSE, record=rrd)
    assert rrd.stat().st_size > 10_000
    assert summary["world"] == "room-two-dividers"
    # Streaming goes through the CLI's checks: nothing listens on port 1.
    with pytest.raises(nadf.RunError, match="no Rerun viewer is listening"):
        nadf.run(ROOM, set=COARSE, connect="rerun+http://127.0.0.1:1/proxy")
    with pytest.raises(nadf.RunError, match="cannot stream"):
        nadf.run(ROOM, set=COARSE, connect="http://nowhere")


def test_a_stepped_simulation_records_until_it_is_closed(tmp_path):
    rrd = tmp_path / "stepped.rrd"
    with nadf.Simulation(ROOM, set=COARSE, record=rrd) as sim:
        sim.step(120)
        assert not rrd.exists()  # still being written
    assert rrd.stat().st_size > 10_000
    assert not (tmp_path / "stepped.rrd.partial").exists()
    assert sim.close() is None  # closed once
    # Dropped without closing: the file is complete all the same.
    dropped = tmp_path / "dropped.rrd"
    sim = nadf.Simulation(ROOM, set=COARSE, record=dropped)
    sim.step(10)
    del sim
    assert dropped.stat().st_size > 10_000
    with pytest.raises(nadf.RunError, match="directory"):
        nadf.Simulation(ROOM, set=COARSE, record=tmp_path / "missing" / "x.rrd")


def test_a_world_describes_itself():
    world = nadf.load(ROOM, set=COARSE)
    assert world.name == "room-two-dividers"
    assert (world.dt, world.duration, world.steps) == (0.01, 8.0, 800)
    assert world.agents == ["robot"]
    assert world.bounds == ([0.0, 0.0], [10.0, 10.0])
    assert "room-two-dividers" in repr(world)


def test_arrays_have_their_documented_shapes():
    world = nadf.load(WORLDS / "crowd.toml", set=["field.cell=0.1", "duration=2"])
    sim = nadf.Simulation(world)
    n = len(world.agents)
    assert sim.position.shape == (n, 2)
    # Before the first step: the starts, at rest, no force.
    assert np.allclose(sim.force, 0.0)
    assert sim.step(10) == pytest.approx(0.1)
    for array in (sim.position, sim.velocity, sim.force):
        assert array.shape == (n, 2) and array.dtype == np.float64
        assert np.isfinite(array).all()
    assert sim.heading.shape == (n,)
    assert sim.contacts.shape == (n,) and sim.contacts.dtype == np.int64
    assert sim.touching.shape == (n,) and sim.touching.dtype == bool
    assert np.linalg.norm(sim.velocity, axis=1).min() > 0.0
    field = sim.field(0)
    (x0, y0), (x1, y1) = world.bounds
    assert field["V"].shape == field["W"].shape == field["mask"].shape
    assert field["V"].ndim == 2 and field["mask"].dtype == np.uint8
    assert field["cell"] == pytest.approx(0.1)
    free = field["mask"] == 0
    # V in [0, 1) on the free cells, 1 − V as W, and log10 W where it is positive.
    assert ((field["V"][free] >= 0) & (field["V"][free] < 1)).all()
    assert np.allclose(field["V"][free] + field["W"][free], 1.0)
    assert np.allclose(np.log10(field["W"][free]), field["log10_W"][free])
    # [nx, ny]: x first, a cell per 0.1 m of the box (the grid is anchored on the target).
    nx, ny = field["V"].shape
    assert abs(nx - (x1 - x0) / 0.1) <= 2 and abs(ny - (y1 - y0) / 0.1) <= 2
    with pytest.raises(IndexError, match="the world has"):
        sim.field(len(world.agents))
    summaries = sim.summaries()
    assert [s["name"] for s in summaries] == world.agents


def test_a_bad_world_raises_with_the_located_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        'size = [4.0, 3.0]\n\n[[agents]]\nname = "r"\nstart = [1.0, 1.0]\n'
        'target = [3.0, 2.0]\ncontroller = { kind = "nadf", b = -5.0 }\n'
    )
    with pytest.raises(nadf.WorldError) as error:
        nadf.load(bad)
    assert f"{bad}:7:" in str(error.value)
    assert "agents.0.controller.b" in str(error.value)
    with pytest.raises(nadf.WorldError, match="not KEY=VALUE"):
        nadf.run(ROOM, set=["duration"])
    with pytest.raises(nadf.WorldError, match="duration"):
        nadf.Simulation(ROOM, set=["duration=-1"])


def test_a_run_is_deterministic_and_steps_add_up():
    a = nadf.Simulation(ROOM, set=COARSE)
    b = nadf.Simulation(ROOM, set=COARSE)
    a.step(150)
    for _ in range(150):
        b.step()
    assert a.time == b.time == pytest.approx(1.5)
    assert np.array_equal(a.position, b.position)
    assert np.array_equal(a.velocity, b.velocity)
    assert a.summaries() == b.summaries()
    # Run to the end: the summary is the one `nadf.run` gives.
    a.step(a.world.steps - 150)
    assert a.finished
    assert a.summaries() == nadf.run(ROOM, set=COARSE)["agents"]


def test_a_commanded_force_drives_the_body_instead_of_its_law(tmp_path):
    world = tmp_path / "open.toml"
    world.write_text(
        'size = [20.0, 10.0]\nduration = 5.0\n[field]\ncell = 0.1\n\n[[agents]]\nname = "r"\n'
        'start = [2.0, 5.0]\ntarget = [18.0, 5.0]\nmass = 2.0\n'
        'controller = { kind = "nadf", b = 10.0, k = 1.0 }\n'
    )
    sim = nadf.Simulation(world)
    sim.command(0, [4.0, 1.0])
    sim.step(100)
    # 1 s of 4 N and 1 N on 2 kg from rest: v = a t = (2, 0.5) m/s, and x − x0 = a t² / 2 to
    # within the step (between the explicit and the semi-implicit Euler sums,
    # a dt² n (n ∓ 1) / 2: Rapier's substeps land in between).
    a = np.array([2.0, 0.5])
    assert np.allclose(sim.velocity[0], a * 1.0, atol=1e-4)
    moved = sim.position[0] - [2.0, 5.0]
    assert (moved > a * 0.01**2 * 100 * 99 / 2).all() and (moved < a * 0.01**2 * 100 * 101 / 2).all()
    assert np.allclose(sim.force[0], [4.0, 1.0])
    # Control back to the law: NADF damps the sideways motion the command left.
    sim.command(0, None)
    sim.step(50)
    assert abs(sim.velocity[0][1]) < 0.5 * 0.5
    assert not np.allclose(sim.force[0], [4.0, 1.0])
    with pytest.raises(ValueError, match="must be finite"):
        sim.command(0, [float("nan"), 0.0])
    with pytest.raises(IndexError):
        sim.command(1, [0.0, 0.0])
