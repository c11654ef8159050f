#!/usr/bin/env python3
"""nadf's field solver against pyamg on the same system (issue "Speed", item 2).

Runs `nadf field WORLD --npy` (timing the whole process, best of `--repeat`), rebuilds the very
system it solved from the exported mask and target (the 5-point Laplacian of `W = 1 - V` on the
reachable cells, `W = 1` on the target cells, `W = 0` on blocked cells and outside the grid),
solves it with pyamg's smoothed aggregation as a CG preconditioner to a relative residual of
1e-10 (setup and solve timed, best of `--repeat`; assembling the matrix is not counted), and
compares the two solutions where `W` is resolved (W >= 1e-6: pyamg's 1e-10 leaves the deeper
cells without digits).

    pip install pyamg scipy
    python3 scripts/pyamg_field.py --nadf target/release/nadf worlds/room-two-dividers.toml \
        --set field.cell=0.009765625

Prints one line per measure and the ratio of pyamg's time to the whole `nadf field` process,
with the export and without it (the same command without `--npy`, also best of `--repeat`):
the export writes the four arrays, which pyamg's side does not.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
import pyamg
import scipy.sparse as sp

from machine import describe


def nadf_field(nadf, world, sets, out):
    """One `nadf field` process: its wall time and the solve it reports, with the arrays
    written to `out` (`--npy`), or written nowhere when `out` is None."""
    cmd = [nadf, "field", world] + (["--npy", out] if out else [])
    for s in sets:
        cmd += ["--set", s]
    started = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - started
    if proc.returncode != 0:
        sys.exit(proc.stderr)
    solve = re.search(r"solve: ([0-9.]+) ms", proc.stdout + proc.stderr)
    return wall, float(solve.group(1)) / 1e3 if solve else float("nan"), proc.stdout


def system(mask, w):
    """The 5-point system of the unknown cells (reachable, not target), x index first."""
    nx, ny = mask.shape
    target = (mask == 0) & (w == 1.0)
    unknown = (mask == 0) & ~target
    index = -np.ones(mask.shape, dtype=np.int64)
    index[unknown] = np.arange(unknown.sum())
    n = int(unknown.sum())
    rows, cols = [np.arange(n)], [np.arange(n)]
    vals = [np.full(n, 4.0)]
    b = np.zeros(n)
    for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        src = (slice(max(0, -di), nx - max(0, di)), slice(max(0, -dj), ny - max(0, dj)))
        dst = (slice(max(0, di), nx - max(0, -di)), slice(max(0, dj), ny - max(0, -dj)))
        # Each cell k = (i, j) (the `src` slice) with its neighbour m = (i + di, j + dj) (`dst`).
        k_idx = index[src]
        m_idx = index[dst]
        m_target = target[dst]
        both = (k_idx >= 0) & (m_idx >= 0)
        rows.append(k_idx[both])
        cols.append(m_idx[both])
        vals.append(np.full(int(both.sum()), -1.0))
        hits = (k_idx >= 0) & m_target
        np.add.at(b, k_idx[hits], 1.0)
    a = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )
    return a, b, unknown


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("world")
    p.add_argument("--nadf", required=True)
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--tol", type=float, default=1e-10)
    args = p.parse_args()
    print(describe())
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "v.npy")
        runs = [nadf_field(args.nadf, args.world, args.set, out) for _ in range(args.repeat)]
        wall = min(r[0] for r in runs)
        solve = min(r[1] for r in runs)
        # The same command without the export: writing the four arrays (25 MB at 1025²) is
        # part of the process above, and pyamg's side writes nothing.
        bare = [nadf_field(args.nadf, args.world, args.set, None) for _ in range(args.repeat)]
        bare_wall = min(r[0] for r in bare)
        mask = np.load(os.path.join(tmp, "v.mask.npy"))
        w_nadf = np.load(os.path.join(tmp, "v.w.npy"))
    a, b, unknown = system(mask, w_nadf)
    print(f"system: {mask.shape[0]} x {mask.shape[1]} cells, {a.shape[0]} unknowns")
    setups, solves = [], []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        ml = pyamg.smoothed_aggregation_solver(a, symmetry="symmetric")
        t1 = time.perf_counter()
        residuals = []
        x = ml.solve(b, tol=args.tol, accel="cg", maxiter=500, residuals=residuals)
        t2 = time.perf_counter()
        setups.append(t1 - t0)
        solves.append(t2 - t1)
    pyamg_time = min(s + t for s, t in zip(setups, solves))
    rel = np.linalg.norm(b - a @ x) / np.linalg.norm(b)
    resolved = w_nadf[unknown] >= 1e-6
    diff = np.abs(x[resolved] - w_nadf[unknown][resolved]) / w_nadf[unknown][resolved]
    print(f"nadf field: whole process {wall:.3f} s, solve {solve:.3f} s (best of {args.repeat})")
    print(f"nadf field without --npy: whole process {bare_wall:.3f} s (best of {args.repeat})")
    print(
        f"pyamg SA + CG: setup {min(setups):.3f} s, solve {min(solves):.3f} s, "
        f"{len(residuals) - 1} iterations, relative residual {rel:.1e} (best of {args.repeat})"
    )
    print(f"largest relative difference where W >= 1e-6: {diff.max():.1e}")
    print(f"pyamg / nadf field process: {pyamg_time / wall:.1f}x")
    print(f"pyamg / nadf field process without the export: {pyamg_time / bare_wall:.1f}x")


if __name__ == "__main__":
    main()
