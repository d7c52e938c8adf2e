"""scipy's own test_rotation.py, read from the installed scipy, run against strapdown.Attitude (scipy_adapter).

Every test function of scipy's file runs, so a test that a new scipy release adds shows up here, passing or
failing.  The cases below fail on purpose: strapdown differs from scipy there by design.  They are strict
xfails, so one that starts to pass fails the run too (and a name scipy no longer has is an error).
"""

from scipy_adapter import load

IMMUTABLE = "by design: an Attitude is immutable (no item assignment; make a new one with concatenate or indexing)"
SERIES = "by design: strapdown interpolates several series sampled at the same times at once"

EXPECTED_FAILURES: dict[str, str] = {
    "test_cython_backend_selection": "by design: scipy's private choice of array backend (Rotation._backend)",
    "test_setitem_slice": IMMUTABLE,
    "test_setitem_integer": IMMUTABLE,
    "test_zero_rotation_get_set": IMMUTABLE + "; r[0] = ... raises TypeError, scipy's IndexError",
    "test_repr_single_rotation": "by design: the repr shows the quaternion and both frame names, not a matrix",
    "test_repr_rotation_sequence": "by design: the repr of a stack shows its shape, frames and dtype",
    "test_rotation_within_numpy_array": (
        "by design: np.array(attitude) is its (..., 4) quaternion array, so every array function takes an Attitude"
    ),
    "test_align_vectors_invalid_input": (
        "by design: align_vectors is vectorised over leading axes of epochs, so a and b of shape (1, 1, 3) are one "
        "epoch of one pair, not an error (every other invalid input of the test is refused)"
    ),
    "test_slerp_rot_is_rotation": "by design: strapdown's interpolation takes plain quaternion arrays too",
    "test_slerp_tensor_rot": SERIES,
}

load("test_rotation", globals(), EXPECTED_FAILURES)
