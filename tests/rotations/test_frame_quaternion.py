"""frame_quaternion in closed form (no numba kernel): the same rotation as frame_matrix, canonical, for every pair."""

import itertools

import numpy as np

from strapdown import as_matrix, canonical, frame_matrix, frame_quaternion


def _frames(letters):
    out = []
    for axes in itertools.permutations(letters, 3):
        try:
            frame_matrix(axes[0] + axes[1] + axes[2], "NED" if "N" in letters else "FRD")
        except ValueError:
            continue
        out.append("".join(axes))
    return out


def test_every_pair_of_frames_rotates_as_frame_matrix_and_is_canonical():
    for frames in (_frames("NESWUD"), _frames("FBRLUD")):
        assert len(frames) == 24  # the right-handed signed permutations
        for a, b in itertools.product(frames, frames):
            q = frame_quaternion(a, b)
            np.testing.assert_allclose(as_matrix(q), frame_matrix(a, b), atol=1e-15)
            np.testing.assert_allclose(np.linalg.norm(q), 1.0, rtol=0, atol=1e-15)
            np.testing.assert_array_equal(q, canonical(q))


def test_a_known_frame_rotation():
    # ENU -> NED: 180 deg about the axis (1, 1, 0)/sqrt(2)
    np.testing.assert_allclose(frame_quaternion("ENU", "NED"), [0, np.sqrt(0.5), np.sqrt(0.5), 0], atol=1e-16)
