"""
Wahba's problem: the attitude covariance against a Monte Carlo cloud
====================================================================

Three known directions within 30° of one another (say three stars in one field of view) are measured in the
body frame with a small random error: each measured direction is the true one turned by a random rotation
perpendicular to it, σ = 0.5° about each of the two perpendicular axes (Shuster's QUEST measurement model).
:func:`strapdown.rotations.wahba.davenport` solves 4000 such epochs at once, and with ``return_covariance=True`` it also
returns Shuster's covariance of the attitude error ``δθ = as_rotvec(q_est* ⊗ q_true)`` (body frame):
``P = σ² (Σ (I - b bᵀ))⁻¹`` for equal weights.

The figure projects the cloud of errors onto three planes and draws the 1σ, 2σ and 3σ ellipses of P over it:
about 39 %, 86 % and 99 % of a two-dimensional Gaussian fall inside them.  With the directions this close
together the rotation about their common axis (here near body z) is the poorly observed one: the long axis.
"""

import matplotlib.pyplot as plt
import numpy as np

import strapdown as sd
from strapdown import quaternion as quat
from strapdown import wahba

rng = np.random.default_rng(7)
sigma = np.radians(0.5)
n = 4000
q_true = sd.from_euler([40.0, 10.0, -5.0], "ZYX", degrees=True)
reference = np.array([[0.0, 0.0, 1.0], [0.5, 0.0, 0.87], [0.2, 0.3, 0.93]])  # within 30° of one another
reference /= np.linalg.norm(reference, axis=1, keepdims=True)
body_true = quat.rotate(quat.conjugate(q_true), reference)  # (3, 3): the directions seen by the body

# each measured direction: the true one turned by sigma-sized rotations about two axes perpendicular to it
e1 = np.cross(body_true, [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
e2 = np.cross(body_true, e1)
turn = sigma * (rng.standard_normal((n, 3, 1)) * e1 + rng.standard_normal((n, 3, 1)) * e2)
body = quat.rotate(sd.from_rotvec(turn), np.broadcast_to(body_true, (n, 3, 3)))

q_est, cov = wahba.davenport(body, reference, return_covariance=True)  # (n, 4), (n, 3, 3)
P = sigma**2 * cov[0]  # equal unit weights: scale by sigma² (the covariance is nearly the same every epoch)
dtheta = sd.as_rotvec(quat.multiply(quat.conjugate(q_est), q_true))  # body-frame error, rad

sample_cov = np.cov(dtheta.T)
print("predicted standard deviations [deg]:", np.degrees(np.sqrt(np.diag(P))).round(4))
print("Monte Carlo standard deviations [deg]:", np.degrees(np.sqrt(np.diag(sample_cov))).round(4))
d2 = np.einsum("ni,ij,nj->n", dtheta, np.linalg.inv(P), dtheta)
print(f"mean squared Mahalanobis distance: {d2.mean():.3f} (3 for a correct covariance)")

# %%
fig, axes = plt.subplots(1, 3, figsize=(13, 4.4), constrained_layout=True)
angle = np.linspace(0, 2 * np.pi, 200)
for ax, (i, j) in zip(axes, [(0, 1), (0, 2), (1, 2)], strict=True):
    x, y = np.degrees(dtheta[:, i]), np.degrees(dtheta[:, j])
    ax.plot(x, y, ".", ms=2, alpha=0.35, color="C0", label="Monte Carlo errors")
    block = np.degrees(np.degrees(P[np.ix_([i, j], [i, j])]))  # rad² to deg²
    values, vectors = np.linalg.eigh(block)
    circle = np.stack([np.cos(angle), np.sin(angle)])
    for k, colour in zip((1, 2, 3), ("C1", "C2", "C3"), strict=True):
        ellipse = vectors @ (k * np.sqrt(values)[:, None] * circle)
        inside = np.mean(np.einsum("ni,ij,nj->n", np.c_[x, y], np.linalg.inv(block), np.c_[x, y]) <= k**2)
        ax.plot(*ellipse, color=colour, lw=1.8, label=f"{k}σ of P ({inside:.0%} inside)")
    ax.set_xlabel(f"δθ_{'xyz'[i]} [deg]")
    ax.set_ylabel(f"δθ_{'xyz'[j]} [deg]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")
fig.suptitle("Davenport's q-method on three directions, σ = 0.5°: Shuster's covariance against 4000 trials")
plt.show()
