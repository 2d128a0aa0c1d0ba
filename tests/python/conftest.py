"""Shared fixtures of the Python tests: small procedural meshes, the repository's paths,
and the command-line binary built by `cargo test --release` (or $SMOOTHTRACE_BIN)."""

import os
import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))


def torus(nu=24, nv=12, R=1.0, r=0.35):
    """A closed triangle mesh: (V float64, F int64)."""
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(0, 2 * np.pi, nv, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    V = np.stack(
        [(R + r * np.cos(vv)) * np.cos(uu), r * np.sin(vv), (R + r * np.cos(vv)) * np.sin(uu)],
        axis=-1,
    ).reshape(-1, 3)
    F = []
    for i in range(nu):
        for j in range(nv):
            a = i * nv + j
            b = ((i + 1) % nu) * nv + j
            c = ((i + 1) % nu) * nv + (j + 1) % nv
            d = i * nv + (j + 1) % nv
            F += [[a, b, c], [a, c, d]]
    return V, np.array(F, dtype=np.int64)


def as_stored(V):
    """Coordinates as the library stores them (float32), back in float64."""
    return np.asarray(V, dtype=np.float32).astype(np.float64)


@pytest.fixture(scope="session")
def torus_mesh():
    return torus()


@pytest.fixture(scope="session")
def rng():
    return np.random.default_rng(20261123)


@pytest.fixture(scope="session")
def cli():
    """Path of the smoothtrace binary; skips when it has not been built."""
    path = pathlib.Path(os.environ.get("SMOOTHTRACE_BIN", ROOT / "target" / "release" / "smoothtrace"))
    if not path.is_file():
        pytest.skip(f"the command line binary {path} is not built (run cargo build --release or set SMOOTHTRACE_BIN)")
    return path


@pytest.fixture(scope="session")
def data_dir():
    d = ROOT / "data"
    if not (d / "bunny-7k.obj").is_file():
        pytest.skip(f"{d} has no bunny-7k.obj (link ../shared/data as data/ to run the data tests)")
    return d
