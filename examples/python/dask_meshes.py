"""A batch of meshes on a Dask cluster: every mesh of a folder, one task per mesh, each
task loading its mesh on the worker, writing a 64^3 distance field next to the others
(`OUT/<name>.npy`) and returning a one-line summary. A LocalCluster of two worker
processes stands in for a real cluster (pass a scheduler address to use one).

Run from the repository root after `pip install ".[dask]"` (and `ln -s ../shared/data data`):
    python examples/python/dask_meshes.py [FOLDER] [--out DIR] [--scheduler ADDRESS]
"""

import argparse
import pathlib
import time

import numpy as np
from dask.distributed import Client, LocalCluster

import smoothtrace as st
import smoothtrace.dask as sdask

ap = argparse.ArgumentParser()
ap.add_argument("folder", nargs="?", default="data")
ap.add_argument("--out", default="fields", help="folder for the .npy fields")
ap.add_argument("--res", type=int, default=64)
ap.add_argument("--scheduler", help="address of a running scheduler (default: a LocalCluster)")
a = ap.parse_args()
out = pathlib.Path(a.out).resolve()
out.mkdir(parents=True, exist_ok=True)
paths = sorted(p for p in pathlib.Path(a.folder).glob("*.obj"))


def field(path, V, F):
    """One task: the mesh's distance field to its triangles, saved as .npy."""
    t = time.perf_counter()
    f = st.distance_field(V, F, resolution=a.res, threads=1)
    np.save(out / (pathlib.Path(path).stem + ".npy"), f.astype(np.float32))
    return pathlib.Path(path).name, len(V), len(F), f.shape, time.perf_counter() - t


if __name__ == "__main__":
    cluster = None if a.scheduler else LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None)
    with Client(a.scheduler or cluster) as client:
        t = time.perf_counter()
        rows = sdask.map_meshes(paths, field).compute()
        for name, nv, nf, shape, s in rows:
            print(f"{name:16s} {nv:7d} vertices {nf:7d} triangles -> {shape} in {s:6.2f} s")
        print(f"{len(rows)} meshes in {time.perf_counter() - t:.1f} s on {len(client.scheduler_info()['workers'])} workers -> {out}")
    if cluster is not None:
        cluster.close()
