"""Shared helpers.  Oracles here are independent of strapdown's own code (no Hamilton product is reused)."""

import itertools
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

# Kernels compile at their first call in the tests, as before strapdown._support.uncompiled (its own tests turn
# the uncompiled runs and the background worker on where they check them); children of the tests inherit this.
os.environ.setdefault("STRAPDOWN_UNCOMPILED", "never")
os.environ.setdefault("STRAPDOWN_BACKGROUND_COMPILE", "0")

# CI runs are deterministic (a red run must be reproducible); HYPOTHESIS_PROFILE=explore searches afresh.
# No deadline: the first call of a function loads or compiles its numba kernel.
settings.register_profile("ci", deadline=None, derandomize=True, max_examples=300)
settings.register_profile("explore", deadline=None, max_examples=3000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

SEQUENCES = [a + b + c for a, b, c in itertools.product("xyz", repeat=3) if a != b and b != c]
ALL_SEQUENCES = [s.upper() for s in SEQUENCES] + SEQUENCES  # 12 intrinsic + 12 extrinsic

BROAD_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "broad"


def random_quaternions(n, rng):
    """Uniformly distributed unit quaternions (normalised 4-D Gaussians), w of either sign."""
    q = rng.standard_normal((n, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def random_walk_quaternions(n, step, rng):
    """n attitudes (scalar first), each turned from the previous one by a Gaussian rotation vector of σ = step rad.

    Built with scipy, independently of strapdown's algebra.
    """
    from scipy.spatial.transform import Rotation

    steps = Rotation.from_rotvec(step * rng.standard_normal((n, 3)))
    out = [steps[0]]
    for s in steps[1:]:
        out.append(out[-1] * s)
    return Rotation.concatenate(out).as_quat(scalar_first=True)


def rotation_angle(p, q, normalize=True):
    """Angle of the rotation between attitudes p and q, sign-invariant: 4 asin(min(|p - q|, |p + q|) / 2).

    For unit quaternions |p - q|² = 2 - 2 cos(φ/2) = 4 sin²(φ/4); the chordal form is accurate for tiny
    angles and needs no quaternion product, so it does not share code with the functions under test.
    """
    p = np.asarray(p, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    if normalize:
        p = p / np.linalg.norm(p, axis=-1, keepdims=True)
        q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    d = np.minimum(np.linalg.norm(p - q, axis=-1), np.linalg.norm(p + q, axis=-1))
    return 4 * np.arcsin(np.minimum(d / 2, 1.0))


def wrapped(a):
    """Angles wrapped into [-π, π), for comparing angle triples across the ±π seam."""
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)


def run_isolated(code: str, *args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run Python ``code`` in a fresh interpreter (PYTHONPATH inherited), so that a crash fails a test, not pytest.

    A segfault or abort shows as a negative return code (or 134) in the result, with stdout and stderr as text.
    """
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=timeout, check=False
    )


def strapdown_cli(*args, timeout=180, cwd=None):
    """``python -m strapdown.cli ARGS`` as a subprocess (text output); a relative PYTHONPATH still works in ``cwd``."""
    import subprocess
    import sys

    env = dict(os.environ)
    if env.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in env["PYTHONPATH"].split(os.pathsep))
    command = [sys.executable, "-m", "strapdown.cli", *map(str, args)]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, cwd=cwd, env=env)


def pytest_configure(config):
    # the marks of scipy's own test modules, which tests/rotations/test_scipy_*.py run against strapdown
    for mark in ("skip_xp_backends", "xfail_xp_backends"):
        config.addinivalue_line("markers", f"{mark}: scipy's array-backend marks (only numpy runs here)")
