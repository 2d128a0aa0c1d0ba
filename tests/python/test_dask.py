"""smoothtrace.dask (issue 33): a distance volume as a dask array computed on a
LocalCluster of two worker processes equals smoothtrace.distance_field; .to_zarr()
stores it; map_meshes runs one task per mesh file; the command line's .zarr arrays read
in zarr-python. Skipped, with the reason, when dask/distributed/zarr are not installed
(they are the optional extra `pip install .[dask]`)."""

import subprocess
import sys

import numpy as np
import pytest

import smoothtrace as st

from conftest import torus


@pytest.fixture(scope="module")
def sdask():
    pytest.importorskip("dask.array", reason="dask is not installed (pip install .[dask])")
    import smoothtrace.dask as sdask

    return sdask


@pytest.fixture(scope="module")
def client(sdask):
    distributed = pytest.importorskip(
        "distributed", reason="dask.distributed is not installed (pip install .[dask])"
    )
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_blocks_on_two_worker_processes_equal_distance_field(sdask, client):
    V, F = torus(40, 20)
    want, box = st.distance_field(V, F, resolution=(23, 17, 11), return_bounds=True)
    vol, box2 = sdask.distance_field(V, F, resolution=(23, 17, 11), chunks=(4, 7, 6), threads=1, return_bounds=True)
    assert vol.shape == want.shape == (11, 17, 23)
    assert vol.dtype == np.float32
    assert vol.numblocks == (3, 3, 4)
    np.testing.assert_array_equal(box, box2)
    got = client.compute(vol).result()
    # Two worker processes really did the work.
    assert len(client.scheduler_info()["workers"]) == 2
    diag = np.linalg.norm(box[1] - box[0])
    err = np.abs(got.astype(np.float64) - want).max()
    assert err <= 1e-6 * diag, f"max difference {err:e} > {1e-6 * diag:e}"


@pytest.mark.parametrize("kw", [{"method": "bvh", "band": 0.2}, {"smooth_alpha_rel": 300.0}])
def test_other_methods_by_blocks(sdask, client, kw):
    V, F = torus(30, 12)
    want = st.distance_field(V, F, resolution=14, **kw)
    got = client.compute(sdask.distance_field(V, F, resolution=14, chunks=5, threads=1, **kw)).result()
    finite = np.isfinite(want)
    np.testing.assert_array_equal(np.isfinite(got), finite)
    np.testing.assert_allclose(got[finite], want[finite], rtol=0, atol=1e-6 * 3.0)


def test_to_zarr_writes_the_volume(sdask, client, tmp_path):
    zarr = pytest.importorskip("zarr", reason="zarr is not installed (pip install .[dask])")
    V, F = torus(24, 12)
    vol = sdask.distance_field(V, F, resolution=16, chunks=6, threads=1)
    vol.to_zarr(str(tmp_path / "t.zarr"))
    back = zarr.open_array(str(tmp_path / "t.zarr"), mode="r")
    assert back.shape == vol.shape
    np.testing.assert_array_equal(back[:], vol.compute())


def test_bad_chunks_and_arguments_raise_value_error(sdask):
    V, F = torus(12, 6)
    with pytest.raises(ValueError, match="at least 1"):
        sdask.distance_field(V, F, resolution=8, chunks=0)
    with pytest.raises(ValueError, match="three"):
        sdask.distance_field(V, F, resolution=8, chunks=(2, 2))
    with pytest.raises(ValueError, match="unknown method"):
        sdask.distance_field(V, F, resolution=8, method="fast")


def test_map_meshes_runs_one_task_per_file(sdask, client, data_dir):
    paths = [p for p in (data_dir / n for n in ("bunny-7k.obj", "spot.obj", "teapot.obj")) if p.is_file()]
    if not paths:
        pytest.skip("no meshes in ../shared/data")

    def summary(path, V, F):
        f = st.distance_field(V, F, resolution=16, threads=1)
        return (path, len(V), len(F), float(f.max()))

    out = sdask.map_meshes(paths, summary).compute()
    assert [o[0] for o in out] == [str(p) for p in paths]
    for (path, nv, nf, fmax), p in zip(out, paths):
        V, F = st.load_mesh(p)
        assert (nv, nf) == (len(V), len(F))
        assert fmax > 0


def test_import_error_names_the_extra():
    code = (
        "import sys; sys.modules['dask'] = None; sys.modules['dask.array'] = None\n"
        "try:\n    import smoothtrace.dask\nexcept ImportError as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "smoothtrace[dask]" in out.stdout, out


def test_cli_zarr_reads_in_zarr_python(cli, tmp_path):
    zarr = pytest.importorskip("zarr", reason="zarr is not installed (pip install .[dask])")
    if int(zarr.__version__.split(".")[0]) < 3:
        pytest.skip(f"zarr {zarr.__version__} reads Zarr v2 only; the command line writes v3")
    V, F = torus(24, 12)
    obj = tmp_path / "t.obj"
    obj.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in V) + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)
    )
    for extra in ([], ["--gzip"]):
        out = tmp_path / f"t{len(extra)}.zarr"
        r = subprocess.run(
            [str(cli), "field", str(obj), "-p", "triangles", "--res", "20", "--chunk", "7", "-o", str(out), *extra],
            capture_output=True, text=True,
        )
        assert r.returncode == 0, r.stderr
        a = zarr.open_array(str(out), mode="r")
        want, box = st.distance_field(V, F, resolution=20, return_bounds=True)
        assert a.shape == want.shape and a.chunks == (7, 7, 7)
        np.testing.assert_allclose(a.attrs["bounds"], box, rtol=1e-15)
        np.testing.assert_allclose(a.attrs["voxel_size"], (box[1] - box[0]) / want.shape[::-1], rtol=1e-12)
        diag = np.linalg.norm(box[1] - box[0])
        assert np.abs(a[:] - want).max() <= 1e-6 * diag
