"""Experiments on a Ray cluster: the shards of ``nadf experiment`` as Ray tasks, retried when
they fail, gathered and merged into exactly the results one machine writes.

>>> import ray, nadf.cluster
>>> ray.init(address="auto")                                            # doctest: +SKIP
>>> print(nadf.cluster.run_experiment("experiments/room-damping.toml", "out", shards=16))  # doctest: +SKIP

Each task runs one shard (``--shard I/N``) on its node into a scratch directory and sends back
its progress file and manifest; the driver writes them under ``out/shard-I-of-N/`` and merges
them (``nadf merge``), so no shared file system is needed for the results. Every node must
read the experiment file and the world (and map) files it names at the same path, and have
this package installed (the same checkout, or Ray's ``runtime_env``). Shards already complete
in ``out`` are not run again, so a batch killed half-way loses only the shards in flight.
"""

from __future__ import annotations

import os
import pathlib
import shutil
import tempfile
import time
from typing import Any, Dict, Optional, Sequence, Tuple

from . import _nadf

__all__ = ["run_experiment"]

def _run_shard(
    path: str,
    index: int,
    count: int,
    threads: int,
    sets: Optional[Sequence[str]],
    fail_first: Optional[str],
) -> Tuple[int, str, str, float]:
    """One shard on this node: its index, manifest and progress file, and its wall time. With
    ``fail_first`` (a directory all nodes see), its first attempt fails on purpose."""
    if fail_first:
        marker = pathlib.Path(fail_first) / f"failed-{index}-of-{count}"
        if not marker.exists():
            marker.touch()
            raise RuntimeError(f"injected failure of shard {index}/{count}")
    scratch = tempfile.mkdtemp(prefix="nadf-shard-")
    try:
        started = time.perf_counter()
        shard_dir, _, _ = _nadf.experiment_shard(
            path, scratch, index, count, False, threads, None if sets is None else list(sets)
        )
        wall = time.perf_counter() - started
        shard_dir = pathlib.Path(shard_dir)
        manifest = (shard_dir / "shard.json").read_text()
        progress = (shard_dir / "runs.jsonl").read_text()
        return index, manifest, progress, wall
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _complete(dir: pathlib.Path, digest: str) -> bool:
    """Whether ``dir`` holds a complete shard of the experiment with ``digest``."""
    import json

    try:
        manifest = json.loads((dir / "shard.json").read_text())
    except (OSError, ValueError):
        return False
    return manifest.get("digest") == digest and manifest.get("complete") is True


def run_experiment(
    experiment: "os.PathLike[str] | str",
    out: "os.PathLike[str] | str",
    shards: Optional[int] = None,
    set: Optional[Sequence[str]] = None,
    retries: int = 3,
    threads: int = 1,
    address: Optional[str] = None,
    verbose: bool = True,
    fail_first: "os.PathLike[str] | str | None" = None,
) -> Dict[str, Any]:
    """Runs the experiment file ``experiment`` on the Ray cluster in ``shards`` tasks (default:
    one per CPU of the cluster) of ``threads`` threads each, retrying a failed task up to
    ``retries`` times, and merges the shards into ``out`` (``runs.arrow``, ``summary.csv``,
    ``summary.png``: the files ``nadf experiment`` writes on one machine, byte for byte).

    Connects with ``ray.init(address=address)`` unless Ray is initialised already.
    ``fail_first`` (a directory every node sees) makes each shard's first attempt fail, to
    watch the retries. Returns the
    summary table (``table``), the shards run now and before (``ran``, ``kept``), the wall time
    (``wall_time``, s) and the sum of the shards' own (``shard_time``, s).
    """
    import ray

    path = str(pathlib.Path(experiment).resolve())
    sets = None if set is None else list(set)
    name, digest, runs = _nadf.experiment_info(path, sets)
    if not ray.is_initialized():
        ray.init(address=address)
    if shards is None:
        shards = max(1, int(ray.cluster_resources().get("CPU", 1) // threads))
    shards = int(min(shards, runs))
    if shards < 1:
        raise ValueError(f"shards must be at least 1, got {shards}")
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    dirs = {i: out / f"shard-{i}-of-{shards}" for i in range(shards)}
    todo = [i for i in range(shards) if not _complete(dirs[i], digest)]
    task = ray.remote(num_cpus=threads, max_retries=retries, retry_exceptions=True)(_run_shard)
    started = time.perf_counter()
    fault = None if fail_first is None else str(fail_first)
    pending = [task.remote(path, i, shards, threads, sets, fault) for i in todo]
    shard_time = 0.0
    while pending:
        finished, pending = ray.wait(pending, num_returns=1)
        index, manifest, progress, wall = ray.get(finished[0])
        shard_time += wall
        d = dirs[index]
        d.mkdir(parents=True, exist_ok=True)
        # The progress file first: a manifest that says complete is written last.
        (d / "runs.jsonl").write_text(progress)
        (d / "shard.json").write_text(manifest)
        if verbose:
            print(f"{name}: shard {index}/{shards} done ({len(todo) - len(pending)}/{len(todo)})")
    table = _nadf.merge([str(out)], str(out))
    return {
        "table": table,
        "ran": len(todo),
        "kept": shards - len(todo),
        "wall_time": time.perf_counter() - started,
        "shard_time": shard_time,
        "experiment": name,
        "runs": runs,
    }
