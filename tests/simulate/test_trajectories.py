"""Trajectories: the truth must be true.  Each quantity is checked against an independent computation:
finite differences of the attitude, numerical quadrature, scipy's DOP853, kinematics by hand."""

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.spatial.transform import Rotation

import strapdown as sd
from conftest import rotation_angle
from strapdown import quaternion as quat
from strapdown.simulate import (
    GRAVITY,
    Coning,
    ConstantRotation,
    Flight,
    RandomMotion,
    RockingPlatform,
    Segment,
    aerobatic_show,
    aileron_roll,
    barrel_roll,
    hammerhead,
    hammerhead_loop,
    immelmann,
    level,
    loop,
    spin,
    split_s,
)

FIGURES = {
    "loop": loop,
    "aileron_roll": aileron_roll,
    "barrel_roll": barrel_roll,
    "immelmann": immelmann,
    "split_s": split_s,
    "hammerhead": hammerhead,
    "spin": spin,
}


def trajectories():
    flights = {name: Flight([level(1.0), fig(), level(1.0)]) for name, fig in FIGURES.items()}
    return {
        "constant": ConstantRotation([0.3, -0.5, 0.8], duration=5.0, q0=sd.from_euler([0.2, 0.1, 0.3], "ZYX")),
        "coning": Coning(np.radians(5.0), 2.0, duration=3.0),
        "random": RandomMotion(duration=20.0, seed=5),
        "rocking": RockingPlatform(duration=30.0),
        "hammerhead_loop": hammerhead_loop(),
        **flights,
    }


TRAJECTORIES = trajectories()


def body_rate_by_finite_difference(traj, t, d=1e-6):
    q = traj.attitude(t)
    dq = (traj.attitude(t + d) - traj.attitude(t - d)) / (2 * d)
    return 2 * quat.multiply(quat.conjugate(q), dq)[:, 1:]


@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_rate_is_the_derivative_of_the_attitude(name):
    traj = TRAJECTORIES[name]
    t = np.linspace(1e-3, traj.duration - 1e-3, 200)
    fd = body_rate_by_finite_difference(traj, t)
    np.testing.assert_allclose(traj.rate(t), fd, atol=5e-8)
    np.testing.assert_allclose(np.linalg.norm(traj.attitude(t), axis=-1), 1, atol=1e-15)


@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_increments_are_the_integral_of_the_rate(name):
    traj = TRAJECTORIES[name]
    t = np.sort(np.random.default_rng(1).uniform(0, traj.duration, 12))
    inc = traj.increments(t)
    # flights are piecewise: tell quad where the pieces join (segment starts, ends of the ramps)
    joints = []
    if isinstance(traj, Flight):
        for start, seg in zip(traj.starts, traj.segments, strict=False):
            joints += [start, start + seg.ramp, start + seg.duration - seg.ramp]
    for k in (0, 5, 10):
        inside = sorted({x for x in joints if t[k] < x < t[k + 1]}) or None
        for c in range(3):
            expected, _ = quad(
                lambda s, c=c: traj.rate(np.array([s]))[0, c], t[k], t[k + 1], epsabs=1e-15, limit=500, points=inside
            )
            assert inc[k, c] == pytest.approx(expected, abs=2e-13)


@pytest.mark.parametrize("name", ["random", "rocking", "hammerhead_loop", "loop", "spin", "immelmann"])
def test_specific_force_is_the_kinematics(name):
    """f_b = Cᵀ (a - g) with a the second derivative of position; for flights a = d/dt (C v_b) by differences."""
    traj = TRAJECTORIES[name]
    t = np.linspace(0.05, traj.duration - 0.05, 60)
    q = traj.attitude(t)
    a = traj.acceleration(t)
    expected = quat.rotate(quat.conjugate(q), a - np.array([0.0, 0.0, GRAVITY]))
    np.testing.assert_allclose(traj.specific_force(t), expected, atol=1e-12)
    if isinstance(traj, Flight):
        d = 1e-5

        def velocity(s):
            _, idx, local = traj._locate(s)
            v = np.array([traj.segments[i].airspeed(np.array([x]))[0][0] for i, x in zip(idx, local, strict=True)])
            return quat.rotate(traj.attitude(s), np.stack([v, 0 * v, 0 * v], axis=-1))

        np.testing.assert_allclose(a, (velocity(t + d) - velocity(t - d)) / (2 * d), atol=1e-5)


def test_at_rest_the_accelerometer_reads_plus_g_up():
    still = ConstantRotation([0.0, 0.0, 0.0], duration=1.0, q0=sd.from_euler([0.7, 0.3, -0.4], "ZYX"))
    f = still.specific_force([0.5])[0]
    up_in_body = quat.rotate(quat.conjugate(sd.from_euler([0.7, 0.3, -0.4], "ZYX")), [0.0, 0.0, -1.0])
    np.testing.assert_allclose(f, GRAVITY * up_in_body, atol=1e-12)


def test_coning_truth_agrees_with_dop853():
    """Issue 4: the coning closed form agrees with a high-order ODE solution within 1e-12 (math.md: 5.3e-14)."""
    cone = Coning(np.radians(10.0), 1.5, duration=10.0)

    def rhs(t, q):
        w = cone.rate(np.array([t]))[0]
        return 0.5 * quat.multiply(q, np.r_[0.0, w])

    t_eval = np.linspace(0, 10, 101)
    sol = solve_ivp(rhs, (0, 10), cone.attitude([0.0])[0], method="DOP853", rtol=1e-13, atol=1e-15, t_eval=t_eval)
    assert rotation_angle(sol.y.T, cone.attitude(t_eval)).max() <= 1e-12


def test_random_motion_truth_agrees_with_dop853():
    motion = RandomMotion(duration=5.0, seed=11, rate_scale=2.0)

    def rhs(t, q):
        return 0.5 * quat.multiply(q, np.r_[0.0, motion.rate(np.array([t]))[0]])

    t_eval = np.linspace(0, 5, 51)
    sol = solve_ivp(rhs, (0, 5), motion.attitude([0.0])[0], method="DOP853", rtol=1e-13, atol=1e-15, t_eval=t_eval)
    assert rotation_angle(sol.y.T, motion.attitude(t_eval)).max() <= 1e-11


@pytest.mark.parametrize("name", [n for n in TRAJECTORIES if n not in ("coning", "random", "rocking")])
@pytest.mark.parametrize("rate", [100.0, 137.0])
def test_exact_method_reproduces_flights_from_increments(name, rate):
    """Issue 4: noise-free readings, the matching integrator reproduces the truth within 1e-10 over the whole figure.
    Rotations about body-fixed axes commute, so exp of exact increments is exact; 137 Hz puts samples across
    segment boundaries, where the rate and three derivatives vanish."""
    traj = TRAJECTORIES[name]
    t = np.arange(0, traj.duration, 1 / rate)
    q = sd.integrate(traj.increments(t), input="increment", method="exact", q0=traj.attitude(t[:1])[0])
    assert rotation_angle(q, traj.attitude(t)).max() <= 1e-10


@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_exact_method_reproduces_any_motion_from_rotation_vectors(name):
    traj = TRAJECTORIES[name]
    t = np.arange(0, traj.duration, 0.01)
    q = sd.integrate(traj.rotation_vectors(t), input="increment", method="exact", q0=traj.attitude(t[:1])[0])
    assert rotation_angle(q, traj.attitude(t)).max() <= 1e-10


@pytest.mark.parametrize("name", ["coning", "random", "rocking"])
def test_fourth_order_methods_converge_on_general_motion(name):
    traj = TRAJECTORIES[name]
    errors = []
    for h in (0.004, 0.002):
        t = np.arange(0, traj.duration, h)
        q = sd.integrate(traj.increments(t), input="increment", method="coning2", q0=traj.attitude(t[:1])[0])
        errors.append(rotation_angle(q[4:], traj.attitude(t[4:])).max())
    assert errors[1] < errors[0] / 12  # fourth order: 16x per halving


def test_hammerhead_goes_through_the_vertical_and_reverses():
    flight = Flight([level(2.0), hammerhead(12.0), level(2.0)])
    ypr = sd.as_euler(flight.attitude([1.0, 5.0, 11.0, 15.0]), "ZYX", degrees=True, yaw_range="positive")
    np.testing.assert_allclose(ypr[0], [0, 0, 0], atol=1e-9)
    assert ypr[1, 1] == pytest.approx(90.0, abs=1e-6)  # vertical climb
    assert ypr[2, 1] == pytest.approx(-90.0, abs=1e-6)  # vertical dive
    np.testing.assert_allclose(ypr[3], [180, 0, 0], atol=1e-9)  # level, heading reversed


@pytest.mark.parametrize(
    ("figure", "final_ypr"),
    [
        (loop, [0, 0, 0]),
        (aileron_roll, [0, 0, 0]),
        (barrel_roll, [0, 0, 0]),
        (immelmann, [180, 0, 0]),
        (split_s, [180, 0, 0]),
    ],
)
def test_figures_end_where_they_should(figure, final_ypr):
    flight = Flight(figure())
    ypr = sd.as_euler(flight.attitude([flight.duration]), "ZYX", degrees=True, yaw_range="positive")[0]
    assert rotation_angle(sd.from_euler(ypr, "ZYX", degrees=True), sd.from_euler(final_ypr, "ZYX", degrees=True)) < 1e-9


def test_rate_is_continuous_across_segments():
    flight = aerobatic_show()
    for boundary in flight.starts[1:-1]:
        before = flight.rate([boundary - 1e-9])
        after = flight.rate([boundary + 1e-9])
        np.testing.assert_allclose(before, after, atol=1e-12)


def test_matches_scipy_composition():
    """A flight's attitude equals scipy's composition of the segment rotations."""
    segs = [Segment((1, 2, 3), 1.2, 2.0, 0.5), Segment((0, 1, 0), -0.7, 1.0, 0.2)]
    flight = Flight(segs)
    end = Rotation.from_rotvec(np.array([1, 2, 3]) / np.sqrt(14) * 1.2) * Rotation.from_rotvec([0, -0.7, 0])
    assert rotation_angle(flight.attitude([3.0])[0], end.as_quat(scalar_first=True)) < 1e-14


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"axis": (0, 0, 0), "angle": 1.0}, "axis"),
        ({"duration": -1.0}, "duration"),
        ({"ramp": 2.0, "duration": 1.0}, "ramp"),
        ({"angle": np.nan}, "angle"),
        ({"speed": (10.0,)}, "speed"),
    ],
)
def test_bad_segments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Segment(**kwargs)


def test_times_outside_the_trajectory_are_rejected():
    with pytest.raises(ValueError, match=r"t must lie in \[0, 5\]"):
        ConstantRotation([1.0, 0, 0], duration=5.0).attitude([6.0])
    with pytest.raises(ValueError, match="segments must be"):
        Flight([])
