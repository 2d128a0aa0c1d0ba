"""Bad input raises ValueError / FileNotFoundError / OSError with the command line's
messages; a Rust panic surfaces as RuntimeError, never as pyo3's PanicException."""

import numpy as np
import pytest

import smoothtrace as st
from conftest import ROOT

P = np.zeros((2, 3))


@pytest.fixture
def mesh(torus_mesh):
    return torus_mesh


@pytest.mark.parametrize(
    "bad, match",
    [
        (np.zeros((4, 2)), r"V must have shape \(n, 3\), got \(4, 2\)"),
        (np.zeros(3), r"V must have shape \(n, 3\), got \(3,\)"),
        (np.zeros((2, 3), dtype=complex), "V must hold real numbers.*complex128"),
        (np.array([["a", "b", "c"]]), "V must hold real numbers"),
        (np.zeros((2, 3), dtype=bool), "V must hold real numbers.*bool"),
        (np.zeros((0, 3)), "V has no vertices"),
        (np.array([[0, 0, 0], [1, np.nan, 0]]), r"V\[1\] has a non-finite coordinate"),
        (np.array([[0, 0, 0], [np.inf, 0, 0]]), r"V\[1\] has a non-finite coordinate"),
        (np.array([[0, 0, 0], [1e39, 0, 0]]), r"V\[1\] = .* does not fit in 32-bit floats"),
    ],
)
def test_bad_vertices(bad, match):
    with pytest.raises(ValueError, match=match):
        st.SmoothDistance(bad, alpha=1.0)


def test_bad_faces_and_edges(mesh):
    V, F = mesh
    with pytest.raises(ValueError, match=r"faces\[1\] holds vertex index 9999, out of range \(there are 288 vertices"):
        st.SmoothDistance(V, faces=np.array([[0, 1, 2], [0, 9999, 1]]), alpha=1)
    with pytest.raises(ValueError, match=r"faces\[0\] holds vertex index -1"):
        st.SmoothDistance(V, faces=np.array([[0, -1, 2]]), alpha=1)
    with pytest.raises(ValueError, match="faces must be an integer array of vertex indices, got dtype float64"):
        st.SmoothDistance(V, faces=F.astype(float), alpha=1)
    with pytest.raises(ValueError, match=r"edges must have shape \(n, 2\), got \(576, 3\)"):
        st.SmoothDistance(V, edges=F, alpha=1)
    with pytest.raises(ValueError, match=r"edges\[0\] holds vertex index 288"):
        st.SmoothDistance(V, edges=[[0, 288]], alpha=1)
    with pytest.raises(ValueError, match="cannot build triangles: it has no faces; use points or edges"):
        st.SmoothDistance(V, primitives="triangles", alpha=1)
    with pytest.raises(ValueError, match="cannot build edges: it has no edges"):
        st.SmoothDistance(V, primitives="edges", alpha=1)
    with pytest.raises(ValueError, match="unknown primitive type 'quads'"):
        st.SmoothDistance(V, faces=F, primitives="quads", alpha=1)


def test_bad_queries(mesh):
    V, F = mesh
    sd = st.SmoothDistance(V, faces=F, alpha=1)
    with pytest.raises(ValueError, match=r"points\[1\] has a non-finite coordinate"):
        sd.value(np.array([[0, 0, 0], [np.nan, 0, 0]]))
    with pytest.raises(ValueError, match=r"points\[0\] has a non-finite"):
        sd.value_and_gradient(np.array([[np.inf, 0, 0]]))
    with pytest.raises(ValueError, match=r"P must have shape \(n, 3\), got \(3,\)"):
        sd.nearest(np.zeros(3))
    with pytest.raises(ValueError, match="P must hold real numbers"):
        sd.value(np.zeros((1, 3), dtype=object))
    with pytest.raises(ValueError, match=r"threads must be in 0..=1024 \(got -1\)"):
        sd.value(P, threads=-1)
    with pytest.raises(ValueError, match="threads must be an integer"):
        sd.value(P, threads=1.5)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(alpha=-1.0), r"alpha must be a positive number \(got -1\)"),
        (dict(alpha=0.0), r"alpha must be a positive number \(got 0\)"),
        (dict(alpha=float("nan")), r"alpha must be a positive number \(got NaN\)"),
        (dict(alpha_rel=float("inf")), r"alpha_rel must be a positive number \(got inf\)"),
        (dict(alpha=1.0, max_alpha=-2.0), r"max_alpha must be a positive number \(got -2\)"),
        (dict(alpha=1.0, beta=1.5), r"beta must be in \[0, 1\] \(got 1.5\)"),
        (dict(alpha=1.0, beta=-0.1), r"beta must be in \[0, 1\] \(got -0.1\)"),
        (dict(alpha=1.0, beta=float("nan")), r"beta must be in \[0, 1\] \(got NaN\)"),
        (dict(), "give alpha or alpha_rel"),
        (dict(alpha=1.0, alpha_rel=2.0), "give alpha or alpha_rel, not both"),
        (dict(alpha="1"), "alpha must be a number"),
        (dict(alpha=1.0, tolerance=-1e-3), r"tolerance must be a length >= 0 \(got -0.001\)"),
        (dict(alpha=1.0, tolerance=float("nan")), r"tolerance must be a length >= 0 \(got NaN\)"),
        (dict(alpha=1.0, tolerance="small"), "tolerance must be a number"),
    ],
)
def test_bad_parameters(mesh, kwargs, match):
    V, F = mesh
    with pytest.raises(ValueError, match=match):
        st.SmoothDistance(V, faces=F, **kwargs)


def test_alpha_rel_of_a_single_point():
    with pytest.raises(ValueError, match="alpha_rel needs a mesh with a non-zero bounding box"):
        st.SmoothDistance([[1.0, 2.0, 3.0]], alpha_rel=10)


def test_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.obj: cannot read file"):
        st.load_mesh(tmp_path / "missing.obj")
    d = tmp_path / "dir.obj"
    d.mkdir()
    with pytest.raises(OSError, match="dir.obj: cannot read file") as e:
        st.load_mesh(d)
    assert not isinstance(e.value, FileNotFoundError)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 x 0\n")
    with pytest.raises(ValueError, match="bad.obj:2"):
        st.load_mesh(bad)
    oob = tmp_path / "oob.obj"
    oob.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(ValueError, match="oob.obj:3: .*vertex index"):
        st.load_mesh(oob)
    with pytest.raises(ValueError, match="unknown mesh extension 'xyz'"):
        st.load_mesh(tmp_path / "m.xyz")
    with pytest.raises(FileNotFoundError, match="cannot read scene file .*nope.toml"):
        st.render(tmp_path / "nope.toml")
    scene = tmp_path / "s.toml"
    scene.write_text("[camera]\norigin = [0, 0, 5]\ntarget = [0, 0, 0]\n[image]\nwidht = 3\n")
    with pytest.raises(ValueError, match=r"s.toml:5:1: unknown field `widht`"):
        st.render(scene)


def test_render_parameters(mesh):
    V, F = mesh
    scene = ROOT / "scenes" / "torus.toml"
    with pytest.raises(ValueError, match=r"width must be in 1..=16384 \(got 0\)"):
        st.render(scene, width=0)
    with pytest.raises(ValueError, match=r"beta must be in \[0, 1\] \(got 2\)"):
        st.render(scene, beta=2.0)
    with pytest.raises(ValueError, match=r"alpha_rel must be a positive number \(got -3\)"):
        st.render(scene, alpha_rel=-3.0)
    with pytest.raises(ValueError, match="unknown MatCap 'chalk'"):
        st.render_arrays(V, faces=F, alpha=10, matcap="chalk", width=8, height=8)
    with pytest.raises(FileNotFoundError, match="cannot read MatCap image .*none.png"):
        st.render_arrays(V, faces=F, alpha=10, matcap="none.png", width=8, height=8)
    with pytest.raises(ValueError, match="camera origin and target are the same point"):
        st.render_arrays(V, faces=F, alpha=10, camera=dict(origin=[0, 0, 0], target=[0, 0, 0]), width=8, height=8)
    with pytest.raises(ValueError, match="the camera at .* is inside the surface"):
        st.render_arrays(V, faces=F, alpha=10, camera=dict(origin=[1, 0, 0], target=[0, 0, 0]), width=8, height=8)
    with pytest.raises(ValueError, match="background must be three integers"):
        st.render_arrays(V, faces=F, alpha=10, background=(0, 300, 0))


def test_field_parameters(mesh):
    V, F = mesh
    with pytest.raises(ValueError, match="the resolution along y is 0"):
        st.distance_field(V, faces=F, resolution=(4, 0, 4))
    with pytest.raises(ValueError, match="the bounds are inverted along x"):
        st.distance_field(V, faces=F, bounds=[1, 0, 0, 0, 1, 1], resolution=4)
    with pytest.raises(ValueError, match="unknown method 'fmm'"):
        st.distance_field(V, faces=F, method="fmm")
    with pytest.raises(ValueError, match="the band must be a positive, finite distance"):
        st.distance_field(V, faces=F, band=-1.0, resolution=4)
    with pytest.raises(ValueError, match="above the limit of 65536 voxels per axis"):
        st.distance_field(V, faces=F, resolution=(100000, 1, 1))


def test_a_panic_becomes_runtime_error():
    # The hook panics on a rayon worker with the GIL released, as a bug in a query would.
    with pytest.raises(RuntimeError, match="internal error in smoothtrace .*: boom"):
        st._native._panic_for_tests("boom")
    # The module still works afterwards.
    assert st.SmoothDistance([[0.0, 0.0, 0.0]], alpha=1.0).value([[3.0, 4.0, 0.0]])[0] == 5.0
