"""Distance fields and renders against the command line's own outputs (`.npy`, PNG):
the same library path, so the arrays must be identical."""

import subprocess

import numpy as np
import pytest

import smoothtrace as st
from conftest import ROOT, torus
from pngread import read_png


def write_obj(path, V, F):
    with open(path, "w") as f:
        for v in V:
            f.write(f"v {v[0]:.9g} {v[1]:.9g} {v[2]:.9g}\n")
        for t in F:
            f.write(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n")


@pytest.fixture(scope="module")
def torus_obj(tmp_path_factory):
    path = tmp_path_factory.mktemp("mesh") / "torus.obj"
    write_obj(path, *torus(20, 10))
    return path


def run(cli, *args, cwd=None):
    r = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, cwd=cwd)
    assert r.returncode == 0, r.stderr
    return r


@pytest.mark.parametrize(
    "cli_args, kwargs",
    [
        (["--res-xyz", "20", "12", "16"], dict(resolution=(20, 12, 16))),
        (["--res", "24", "--method", "bvh"], dict(resolution=24, method="bvh")),
        (
            ["--res-xyz", "8", "9", "10", "--bounds", "-2", "-1", "-2", "2", "1", "2", "--band", "0.3"],
            dict(resolution=(8, 9, 10), bounds=[[-2, -1, -2], [2, 1, 2]], band=0.3),
        ),
        (["--res", "16", "--smooth", "--alpha", "20", "--beta", "0"], dict(resolution=16, smooth_alpha=20.0, beta=0.0)),
    ],
)
def test_field_equals_the_cli_npy(cli, torus_obj, tmp_path, cli_args, kwargs):
    out = tmp_path / "f.npy"
    run(cli, "field", torus_obj, "--primitive", "triangles", *cli_args, "-o", out)
    expected = np.load(out)
    V, F = st.load_mesh(torus_obj)
    field, bounds = st.distance_field(V, faces=F, return_bounds=True, **kwargs)
    assert field.dtype == np.float64 and field.shape == expected.shape
    np.testing.assert_array_equal(field, expected.astype(np.float64))
    assert bounds.shape == (2, 3)


def test_field_default_bounds_and_exactness(torus_mesh):
    V, F = torus_mesh
    field, (lo, hi) = st.distance_field(V, faces=F, resolution=(6, 5, 4), return_bounds=True)
    assert field.shape == (4, 5, 6)
    Vs = V.astype(np.float32).astype(np.float64)
    diag = np.linalg.norm(Vs.max(0) - Vs.min(0))
    np.testing.assert_allclose(lo, Vs.min(0) - 0.1 * diag, rtol=1e-6)
    np.testing.assert_allclose(hi, Vs.max(0) + 0.1 * diag, rtol=1e-6)
    # Voxel centres queried with nearest() give the same exact distances (f32 storage).
    h = (hi - lo) / np.array([6, 5, 4])
    k, j, i = np.meshgrid(np.arange(4), np.arange(5), np.arange(6), indexing="ij")
    centres = lo + (np.stack([i, j, k], axis=-1).reshape(-1, 3) + 0.5) * h
    d, _, _ = st.SmoothDistance(V, faces=F, alpha=1).nearest(centres)
    np.testing.assert_allclose(field.reshape(-1), d, rtol=1e-6, atol=1e-7)


def test_render_equals_the_cli_png(cli, tmp_path):
    scene = ROOT / "scenes" / "torus.toml"
    out = tmp_path / "torus.png"
    run(cli, "render", scene, "-o", out, "--width", "96", "--height", "54")
    expected = read_png(out)
    img = st.render(scene, width=96, height=54)
    assert img.shape == (54, 96, 4) and img.dtype == np.uint8
    np.testing.assert_array_equal(img[..., :3], expected[..., :3])
    assert (img[..., 3] == 255).all()
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 10, "the torus is not in the picture"


def test_render_arrays_equals_the_cli_png_of_the_same_scene(cli, torus_obj, tmp_path):
    scene = tmp_path / "arrays.toml"
    scene.write_text(
        f"""
[camera]
origin = [0.5, 2.0, 3.5]
target = [0.0, 0.0, 0.0]
fov = 45
[image]
width = 80
height = 60
[[object]]
mesh = "{torus_obj}"
primitives = "triangles"
alpha = 40.0
matcap = "jade"
"""
    )
    out = tmp_path / "arrays.png"
    run(cli, "render", scene, "-o", out)
    V, F = st.load_mesh(torus_obj)
    img = st.render_arrays(
        V,
        faces=F,
        alpha=40.0,
        camera=dict(origin=[0.5, 2.0, 3.5], target=[0, 0, 0], fov=45),
        matcap="jade",
        width=80,
        height=60,
    )
    np.testing.assert_array_equal(img[..., :3], read_png(out)[..., :3])


def test_render_arrays_default_camera_sees_the_object(torus_mesh):
    V, F = torus_mesh
    img = st.render_arrays(V, faces=F, alpha_rel=200, width=64, height=48, background=(0, 0, 0))
    hit = img[..., :3].any(axis=-1)
    # The object is in view and does not fill the whole frame.
    assert 0.05 < hit.mean() < 0.9
    assert not hit[0].any() and not hit[-1].any() and not hit[:, 0].any() and not hit[:, -1].any()
