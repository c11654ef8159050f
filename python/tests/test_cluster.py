"""The Ray driver on a local cluster of two nodes started by the test: the shards run as Ray
tasks, failed ones are retried, and the merged results are the single-machine run's, byte for
byte."""

import os
import pathlib
import subprocess

import pytest

ray = pytest.importorskip("ray")
from ray.cluster_utils import Cluster  # noqa: E402

import nadf.cluster  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def nadf_binary() -> pathlib.Path:
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "nadf"


@pytest.fixture(scope="module")
def cluster():
    """A head node and a worker node, one CPU each."""
    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 1})
    c.add_node(num_cpus=1)
    ray.init(address=c.address)
    yield c
    ray.shutdown()
    c.shutdown()


def experiment(tmp_path: pathlib.Path) -> pathlib.Path:
    file = tmp_path / "exp.toml"
    world = (ROOT / "worlds" / "room-two-dividers.toml").as_posix()
    file.write_text(
        f"""[experiment]
world = "{world}"
runs = 10
seed = 3
set = ["field.cell=0.1", "duration=6"]
group = ["agents.0.controller.kind"]
[experiment.sample]
"agents.0.start" = {{ free_point = {{ clearance = 0.4 }} }}
"agents.0.controller.kind" = {{ choice = ["nadf", "viscous"] }}
"""
    )
    return file


def test_ray_shards_merge_into_the_single_machine_results(cluster, tmp_path):
    file = experiment(tmp_path)
    alone = tmp_path / "alone"
    subprocess.run(
        [nadf_binary(), "experiment", file, "--out", alone], check=True, capture_output=True
    )
    # Every shard's first attempt fails: Ray retries each once.
    faults = tmp_path / "faults"
    faults.mkdir()
    out = tmp_path / "ray"
    result = nadf.cluster.run_experiment(file, out, shards=4, verbose=False, fail_first=faults)
    assert result["ran"] == 4 and result["kept"] == 0
    assert len(list(faults.iterdir())) == 4  # each shard failed once, then ran
    for name in ["runs.arrow", "summary.csv"]:
        assert (out / name).read_bytes() == (alone / name).read_bytes(), name
    assert "agents.0.controller.kind=nadf" in result["table"]
    # Run again: every shard is complete in `out`, nothing runs, the same results.
    again = nadf.cluster.run_experiment(file, out, shards=4, verbose=False)
    assert again["ran"] == 0 and again["kept"] == 4
    assert (out / "runs.arrow").read_bytes() == (alone / "runs.arrow").read_bytes()


def test_a_shard_that_always_fails_stops_the_batch(cluster, tmp_path):
    file = experiment(tmp_path)
    bad = file.read_text().replace('"duration=6"', '"duration=6", "agents.0.mass=-1"')
    file.write_text(bad)
    with pytest.raises(nadf.WorldError, match="agents.0.mass"):
        nadf.cluster.run_experiment(file, tmp_path / "out", shards=2, verbose=False)
