"""One large distance volume on a Dask cluster, stored as Zarr block by block: the blocks
are computed by the library (the GIL released) on the workers, and `to_zarr` writes each
as it finishes, so no process holds the whole volume.

Run from the repository root after `pip install ".[dask]"`:
    python examples/python/dask_volume.py [MESH] [--res 512] [--chunks 128] [--out bunny.zarr]
"""

import argparse
import time

import numpy as np
import zarr
from dask.distributed import Client, LocalCluster

import smoothtrace as st
import smoothtrace.dask as sdask

ap = argparse.ArgumentParser()
ap.add_argument("mesh", nargs="?", default="data/bunny.obj")
ap.add_argument("--res", type=int, default=512)
ap.add_argument("--chunks", type=int, default=128)
ap.add_argument("--out", default="bunny.zarr")
a = ap.parse_args()

if __name__ == "__main__":
    V, F = st.load_mesh(a.mesh)
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster):
        vol, box = sdask.distance_field(V, F, resolution=a.res, chunks=a.chunks, threads=1, return_bounds=True)
        print(f"{a.mesh}: {vol.shape} float32 in {vol.npartitions} blocks of {a.chunks}^3")
        t = time.perf_counter()
        vol.to_zarr(a.out, overwrite=True)
        print(f"wrote {a.out} in {time.perf_counter() - t:.1f} s")
    z = zarr.open_array(a.out, mode="r")
    k = z.shape[0] // 2
    print(f"middle slice: min {np.min(z[k]):.5f}, max {np.max(z[k]):.5f}; bounds {box.tolist()}")
