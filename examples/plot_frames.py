"""
Frames and axes
===============

strapdown names every frame by three letters.  A reference frame uses N, E, S, W, U (up) and D (down), a body
frame F (forward), B, R (right), L, U and D.  An attitude quaternion ``q`` maps body vectors to the reference
frame, ``v_ref = q ⊗ v_body ⊗ q*``, so the columns of ``as_matrix(q)`` are the body axes seen from the
reference frame.  At zero attitude the forward axis points north and the right axis east.

The pictures draw everything in one display basis (east to the right, north into the page, up), computed with
:func:`strapdown.frame_matrix` and :func:`strapdown.as_matrix`, not by hand.
"""

import matplotlib.pyplot as plt
import numpy as np

import strapdown as sd

TO_DISPLAY = sd.frame_matrix("NED", "ENU")  # the display basis is ENU: x east, y north, z up


def draw_triad(ax, axes_ned, labels, colours, origin=(0.0, 0.0, 0.0), length=1.0, style="-"):
    """Arrows for three axes given by their NED coordinates (columns)."""
    for k in range(3):
        v = TO_DISPLAY @ axes_ned[:, k] * length
        ax.quiver(*origin, *v, color=colours[k], arrow_length_ratio=0.12, lw=2, linestyle=style)
        ax.text(*(np.asarray(origin) + 1.12 * v), labels[k], color=colours[k], fontsize=11, weight="bold")


def draw_aircraft(ax, q_ned):
    """A paper aeroplane in body axes FRD, turned by q into NED and drawn in the display basis."""
    body = np.array([[1.0, 0, 0], [-0.6, 0, 0], [-0.2, 0.7, 0], [0.2, 0, 0], [-0.2, -0.7, 0], [-0.6, 0, -0.25]])
    pts = (TO_DISPLAY @ sd.as_matrix(q_ned) @ body.T).T * 0.8
    for a, b in [(0, 1), (2, 3), (3, 4), (2, 1), (4, 1), (1, 5)]:
        ax.plot(*pts[[a, b]].T, color="0.3", lw=1.5)


def setup(ax, title):
    ax.set_xlim(-1.2, 1.2)
    ax.set_ylim(-1.2, 1.2)
    ax.set_zlim(-1.2, 1.2)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=22, azim=-60)
    ax.set_axis_off()
    ax.set_title(title, fontsize=10)


fig = plt.figure(figsize=(13, 4.6), constrained_layout=True)

ax = fig.add_subplot(1, 3, 1, projection="3d")
ned = np.eye(3)  # N, E, D in NED coordinates
enu = sd.frame_matrix("ENU", "NED")  # columns: E, N, U in NED coordinates
draw_triad(ax, ned, ["N", "E", "D"], ["C0", "C1", "C2"])
draw_triad(ax, enu, ["E", "N", "U"], ["C1", "C0", "C3"], length=0.6, style="--")
setup(ax, "reference frames NED (solid) and ENU (dashed)")

ax = fig.add_subplot(1, 3, 2, projection="3d")
q0 = sd.quaternion.identity()
draw_triad(ax, ned, ["N", "E", "D"], ["0.7"] * 3, length=1.0)
draw_triad(ax, sd.as_matrix(q0), ["F", "R", "D"], ["C0", "C1", "C2"], length=0.7)
draw_aircraft(ax, q0)
setup(ax, "zero attitude in NED: body F, R, D = N, E, D")

ax = fig.add_subplot(1, 3, 3, projection="3d")
q = sd.from_euler([30.0, 10.0, 20.0], "ZYX", degrees=True)  # yaw 30° east of north, nose 10° up, right wing down
draw_triad(ax, ned, ["N", "E", "D"], ["0.7"] * 3, length=1.0)
draw_triad(ax, sd.as_matrix(q), ["F", "R", "D"], ["C0", "C1", "C2"], length=0.7)
draw_aircraft(ax, q)
setup(ax, "yaw 30°, pitch 10°, roll 20° (ZYX): columns of as_matrix(q)")
plt.show()

# %%
# The body's forward axis in the reference frame is the first column of ``as_matrix(q)``, or ``rotate(q, F)``:
forward = sd.quaternion.rotate(q, [1.0, 0.0, 0.0])
print("forward axis in NED:", forward.round(4))
print("heading:", np.degrees(np.arctan2(forward[1], forward[0])).round(2), "deg east of north")
print("elevation:", np.degrees(np.arcsin(-forward[2])).round(2), "deg above the horizon")

# %%
# The same attitude in ENU/FLU, the robotics convention, is another quaternion for the same physical
# orientation; :func:`strapdown.change_frame` converts, and the forward axis comes out the same direction:
q_enu = sd.change_frame(q, ref_from="NED", ref_to="ENU", body_from="FRD", body_to="FLU")
print("forward axis in ENU:", sd.quaternion.rotate(q_enu, [1.0, 0.0, 0.0]).round(4))
print("the same vector taken from NED to ENU:", (sd.frame_matrix("NED", "ENU") @ forward).round(4))
