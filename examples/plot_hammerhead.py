"""
Gajda's hammerhead: every propagation method through the vertical
=================================================================

Gajda (1988) concluded that (3a) the Euler-angle method fails at the vertical, (3b) quaternions have no
singular attitude, so their error does not depend on where the flight starts, and (3c) the quaternion
algorithm is fast enough for on-board use.  :func:`strapdown.evaluate.compare.compare` puts all three to the test on a
hammerhead followed by a loop, with an ideal delta-angle gyro at 100 Hz: the table reports each method's
largest error, its error from an oblique start, the steps it spent near its singular set and its cost per step.

The figures come from :func:`strapdown.evaluate.figures.comparison_figures` (``strapdown compare --out`` writes the
same ones): the angles, with the stretches near the vertical shaded where yaw and roll are not defined, and the
error of every method, one panel per family.
"""

import matplotlib.pyplot as plt

from strapdown.evaluate.compare import compare
from strapdown.evaluate.figures import comparison_figures
from strapdown.simulate import hammerhead_loop, sample

data = sample(hammerhead_loop(), 100.0, gyro="increment")
result = compare(data, timing_repeats=1, title="hammerhead + loop, ideal delta-angle gyro at 100 Hz")
print(result.table())

# %%
# ``exact`` integrates the delta-angles of a rotation about body-fixed axes without any error but rounding;
# the Euler-angle method stops at the first vertical climb (red line), and Gajda's other classic baselines
# carry the truncation error of their integrator.
figures = comparison_figures(result)
plt.show()
