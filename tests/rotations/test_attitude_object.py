"""strapdown.Attitude: what frames add, storage, cross-checks with scipy (its own suite: test_scipy_rotation.py)."""

import pickle

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown import Attitude, change_frame


def scipy_of(a):
    return Rotation.from_quat(a.q, scalar_first=True)


@pytest.fixture
def stack(rng):
    return Attitude(random_quaternions(10, rng), reference="NED", body="FRD")


def test_construction_normalises_copies_and_q_is_zero_copy(rng):
    raw = random_quaternions(5, rng) * 3.0
    a = Attitude(raw, "NED", "FRD")
    np.testing.assert_allclose(np.linalg.norm(a.q, axis=-1), 1, atol=1e-15)
    raw[:] = 1.0  # the object owns its data
    assert rotation_angle(a.q, raw / 2).max() > 0.1
    assert a.q is a.q  # the stored array itself, no copy per access
    assert not a.q.flags.writeable
    assert np.shares_memory(a.q, a[:].q)  # slicing does not copy either
    with pytest.raises(AttributeError, match="immutable"):
        a.reference = "ENU"
    with pytest.raises(ValueError, match="zero quaternion"):
        Attitude([0.0, 0, 0, 0])


def test_from_quat_layouts_match_scipy(rng):
    q_last = Rotation.random(20, rng=rng).as_quat()
    a = Attitude.from_quat(q_last, scalar_first=False)
    np.testing.assert_allclose(a.as_quat(scalar_first=False), q_last, atol=1e-15)
    np.testing.assert_allclose(a.q, np.roll(q_last, 1, -1), atol=1e-15)


def test_conversions_match_scipy(rng):
    r = Rotation.random(200, rng=rng)
    a = Attitude.from_scipy(r, reference="ENU", body="FLU")
    np.testing.assert_allclose(a.as_matrix(), r.as_matrix(), atol=1e-15)
    np.testing.assert_allclose(a.as_rotvec(), r.as_rotvec(), atol=1e-14)
    np.testing.assert_allclose(a.as_mrp(), r.as_mrp(), atol=1e-15)
    np.testing.assert_allclose(a.as_euler("ZYX"), r.as_euler("ZYX"), atol=1e-13)
    axes = [[0, 0, 1], [1, 0, 0], [0, 1, 1]]
    np.testing.assert_allclose(a.as_davenport(axes, "e"), r.as_davenport(axes, "e"), atol=1e-12)
    for back in (
        Attitude.from_matrix(r.as_matrix()),
        Attitude.from_rotvec(r.as_rotvec()),
        Attitude.from_mrp(r.as_mrp()),
        Attitude.from_euler("ZYX", r.as_euler("ZYX")),  # scipy's argument order
        Attitude.from_euler(r.as_euler("ZYX"), "ZYX"),  # strapdown's
        Attitude.from_davenport(axes, "e", r.as_davenport(axes, "e")),
        Attitude.from_gibbs(a.as_gibbs()),
        Attitude.from_axis_angle(*a.as_axis_angle()),
    ):
        assert rotation_angle(back.q, a.q).max() < 1e-13
    assert rotation_angle(a.as_scipy().as_quat(scalar_first=True), a.q).max() < 1e-15


def test_shape_len_indexing_iteration(stack):
    assert stack.shape == (10,) and len(stack) == 10 and not stack.single
    assert stack[3].single and stack[3].shape == () and stack[3].reference == "NED"
    np.testing.assert_array_equal(stack[2:5].q, stack.q[2:5])
    np.testing.assert_array_equal(stack[[1, 3]].q, stack.q[[1, 3]])
    mask = np.arange(10) % 2 == 0
    np.testing.assert_array_equal(stack[mask].q, stack.q[mask])
    np.testing.assert_array_equal(np.array([b.q for b in stack]), stack.q)
    grid = Attitude(np.tile(stack.q, (3, 1, 1)))
    assert (
        grid.shape
        == (
            3,
            10,
        )
        and grid[1, 2:4].shape == (2,)
        and grid[..., 0].shape == (3,)
    )
    with pytest.raises(IndexError):
        stack[0, 1]  # a second index would fall on the quaternion components
    with pytest.raises(TypeError, match="no len"):
        len(stack[0])
    with pytest.raises(TypeError, match="not subscriptable"):
        stack[0][0]
    with pytest.raises(TypeError, match="not iterable"):
        iter(stack[0])


def test_concatenate_pickle_repr(stack):
    both = Attitude.concatenate([stack[:3], stack[7], stack[8:]])
    np.testing.assert_array_equal(both.q, stack.q[[0, 1, 2, 7, 8, 9]])
    assert (both.reference, both.body) == ("NED", "FRD")
    with pytest.raises(ValueError, match=r"attitudes\[1\] maps 'FLU' to 'ENU'.*to_frame\('NED', 'FRD'\)"):
        Attitude.concatenate([stack, stack.to_frame("ENU", "FLU")])
    back = pickle.loads(pickle.dumps(stack))
    np.testing.assert_array_equal(back.q, stack.q)
    assert (back.reference, back.body) == ("NED", "FRD") and not back.q.flags.writeable
    assert repr(Attitude.identity(reference="NED", body="FRD")) == "Attitude([1, 0, 0, 0], reference='NED', body='FRD')"
    assert repr(stack) == "Attitude(shape=(10,), reference='NED', body='FRD', dtype=float64)"


def test_inv_apply_compose_magnitude_match_scipy(rng):
    p = Attitude(random_quaternions(100, rng))
    r = Attitude(random_quaternions(100, rng))
    v = rng.standard_normal((100, 3))
    np.testing.assert_allclose(p.apply(v), scipy_of(p).apply(v), atol=1e-14)
    np.testing.assert_allclose(p.apply(v, inverse=True), scipy_of(p).apply(v, inverse=True), atol=1e-14)
    np.testing.assert_allclose(p[0].apply(v), scipy_of(p[0]).apply(v), atol=1e-14)  # one attitude, many vectors
    assert rotation_angle((p * r).q, (scipy_of(p) * scipy_of(r)).as_quat(scalar_first=True)).max() < 1e-15
    assert rotation_angle(p.inv().q, scipy_of(p).inv().as_quat(scalar_first=True)).max() < 1e-15
    np.testing.assert_allclose(p.magnitude(), scipy_of(p).magnitude(), atol=1e-15)
    np.testing.assert_allclose((p * p.inv()).magnitude(), 0, atol=1e-15)


def test_mean_random_approx_equal_match_scipy(rng):
    a = Attitude(Rotation.random(50, rng=rng).as_quat(scalar_first=True), "NED", "FRD")
    w = rng.uniform(0.1, 1, 50)
    m = a.mean(weights=w)
    assert m.single and m.reference == "NED"
    assert rotation_angle(m.q, scipy_of(a).mean(weights=w).as_quat(scalar_first=True)) < 1e-12
    x = Attitude.random(5, rng=np.random.default_rng(7), reference="NED", body="FRD")
    y = Attitude.random(5, rng=np.random.default_rng(7), reference="NED", body="FRD")
    np.testing.assert_array_equal(x.q, y.q)  # reproducible from the generator
    assert Attitude.random().shape == () and Attitude.random(shape=(2, 3)).shape == (2, 3)
    # uniform (Haar): the rotation angle χ has density (1 - cos χ)/π, mean π/2 + 2/π
    angles = Attitude.random(200_000, rng=1).magnitude()
    assert abs(angles.mean() - (np.pi / 2 + 2 / np.pi)) < 0.01
    near = x * Attitude.from_rotvec([[1e-9, 0, 0]] * 5, reference="FRD", body="FRD")
    np.testing.assert_array_equal(x.approx_equal(near), True)
    np.testing.assert_array_equal(x.approx_equal(near, atol=1e-10), False)
    assert x[0].approx_equal(x[0], atol=1e-3, degrees=True)
    with pytest.raises(ValueError, match="reference frames differ"):
        x.approx_equal(x.to_frame("ENU"))


def test_composition_checks_frames():
    vehicle = Attitude.from_euler([30.0, 5.0, 2.0], degrees=True, reference="NED", body="FRD")
    mount = Attitude.from_euler([0.0, 0.0, 180.0], degrees=True, reference="FRD", body="imu")
    imu = vehicle * mount
    assert (imu.reference, imu.body) == ("NED", "imu")
    v = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(imu.apply(v), vehicle.apply(mount.apply(v)), atol=1e-15)
    with pytest.raises(ValueError, match=r"a's body axes must be b's reference frame"):
        mount * vehicle
    enu = vehicle.to_frame("ENU", "FLU")
    # a NED/FRD attitude times an ENU/FLU one: the message says how to re-express it
    with pytest.raises(ValueError, match=r"maps 'FLU' to 'ENU'.*b\.to_frame\('NED', 'FRD'\).*a\.inv\(\) \* b"):
        vehicle * enu
    rel = vehicle.inv() * enu.to_frame("NED", "FRD")  # the same body: the identity between body axes
    assert (rel.reference, rel.body) == ("FRD", "FRD") and rel.magnitude() < 1e-15
    # body axes of the same kind: to_frame on either side fixes it
    with pytest.raises(ValueError, match=r"b\.to_frame\(reference='FRD'\) or a\.to_frame\(body='FLU'\)"):
        vehicle * Attitude.identity(reference="FLU", body="imu")
    # unnamed frames are not checked
    anon = Attitude.identity()
    assert (vehicle * anon).reference == "NED" and (anon * vehicle).body == "FRD"
    with pytest.raises(TypeError):
        vehicle * 2.0


def test_to_frame_is_change_frame_and_keeps_physics(rng):
    q = random_quaternions(100, rng)
    a = Attitude(q, "NED", "FRD")
    b = a.to_frame("ENU", "FLU")
    expected = change_frame(q, ref_from="NED", ref_to="ENU", body_from="FRD", body_to="FLU")
    assert rotation_angle(b.q, expected).max() < 1e-15
    # physics: a body vector, re-expressed, lands on the re-expressed reference vector (independent matrices)
    ned_to_enu = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1.0]])
    frd_to_flu = np.diag([1.0, -1, -1])
    v_frd = rng.standard_normal((100, 3))
    np.testing.assert_allclose(b.apply(v_frd @ frd_to_flu.T), a.apply(v_frd) @ ned_to_enu.T, atol=1e-14)
    assert b.to_frame("NED", "FRD").approx_equal(a).all()
    assert a.to_frame(body="FRD") is a
    with pytest.raises(ValueError, match="reference frame has no name"):
        Attitude(q).to_frame("ENU")


def test_inv_swaps_frames_and_float32_is_kept(rng):
    a = Attitude(random_quaternions(4, rng).astype(np.float32), "NED", "FRD")
    assert a.dtype == np.float32 and a.q.dtype == np.float32
    assert (a.inv().reference, a.inv().body) == ("FRD", "NED")
    for out in (a.as_euler(), a.as_mrp(), a.as_rotvec(), a.magnitude(), (a * a.inv()).q, a.mean().q):
        assert out.dtype == np.float32
    assert Attitude.from_euler(np.zeros((2, 3), np.float32)).dtype == np.float32


def test_bad_frame_names():
    with pytest.raises(ValueError, match="reference must be a frame name"):
        Attitude.identity(reference=3)
    with pytest.raises(ValueError, match="body must be a frame name"):
        Attitude([1.0, 0, 0, 0], body="")


def test_estimate_hands_out_an_attitude():
    from strapdown.fusion import madgwick

    n = 50
    acc = np.tile([0.0, 0.0, 9.81], (n, 1))  # at rest, sensor z up (ENU-like): specific force +g along z
    est = madgwick(np.zeros((n, 3)), acc, dt=0.01, frame="NED")
    att = est.attitude
    assert isinstance(att, Attitude) and att.reference == "NED" and att.body is None
    assert np.shares_memory(att.q, est.q) and att.shape == (n,)
    np.testing.assert_allclose(att.as_euler("ZYX")[:, 1:], np.stack([est.pitch, est.roll], -1), atol=1e-12)


def test_power_matches_scipy_and_needs_matching_frames(rng):
    q = random_quaternions(50, rng)
    rel = Attitude(q, "FRD", "FRD")  # a rotation between two sets of body axes
    for t in (0.5, 2.0, -0.3, 0.0):
        assert rotation_angle((rel**t).q, (scipy_of(rel) ** t).as_quat(scalar_first=True)).max() < 1e-13
    np.testing.assert_array_equal((Attitude(q, "NED", "FRD") ** -1).q, Attitude(q, "NED", "FRD").inv().q)
    with pytest.raises(ValueError, match=r"same name.*maps 'FRD' to 'NED'"):
        Attitude(q, "NED", "FRD") ** 0.5


def test_array_conversion_is_zero_copy_and_arithmetic_is_refused(rng):
    from strapdown import as_euler
    from strapdown.propagate.interpolate import RotationSpline

    a = Attitude(random_quaternions(8, rng), "NED", "FRD")
    assert np.shares_memory(np.asarray(a), a.q)
    np.testing.assert_array_equal(as_euler(a), a.as_euler())  # any array function takes an Attitude
    RotationSpline(np.arange(8.0), a)
    with pytest.raises(TypeError):
        np.float64(2.0) * a
    with pytest.raises(TypeError):
        np.add(a, a)


def test_mean_axes_are_numbered_in_the_attitudes_shape(rng):
    """``axis=-1`` is the Attitude's last axis (as for numpy arrays of that shape), not q's component axis."""
    a = Attitude(Rotation.random(12, rng=rng).as_quat(scalar_first=True).reshape(3, 4, 4), "NED", "FRD")
    for axis, want_shape in ((-1, (3,)), (1, (3,)), (-2, (4,)), ((0, -1), ())):
        m = a.mean(axis=axis)
        assert m.shape == want_shape and (m.reference, m.body) == ("NED", "FRD")
    for i in range(3):  # each row's mean is scipy's mean of that row
        want = scipy_of(a[i]).mean().as_quat(scalar_first=True)
        assert rotation_angle(a.mean(axis=-1).q[i], want) < 1e-12
    with pytest.raises(ValueError, match=r"axis 2 is out of range for an Attitude of shape \(3, 4\)"):
        a.mean(axis=2)
