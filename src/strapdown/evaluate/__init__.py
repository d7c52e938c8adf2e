"""How good an attitude is: error metrics, the BROAD benchmark, comparisons of methods (floor 5).

* :mod:`.metrics`: error quaternions, total/heading/inclination errors, RMSE (with the heading offset removed);
* :mod:`.broad`: the BROAD trials (Laidig et al. 2021) and their reference results;
* :mod:`.evaluation`: an estimator of :data:`strapdown.fusion.ESTIMATORS` over trials, and grid searches;
* :mod:`.compare`: integration methods against a simulated truth (Gajda's comparison), with its table;
* :mod:`.figures`: the figures of comparisons and attitude series (matplotlib, the ``plot`` extra).

Imports the estimation floor (:mod:`strapdown.fusion`, :mod:`strapdown.calibrate`) and below.
"""

from .._support.lazy import exports

# submodules and names imported when first used
__getattr__, __dir__, _names = exports(
    __name__, {"evaluation": ("ESTIMATORS", "Evaluation", "GridSearch", "TrialResult", "evaluate", "grid_search")}
)
__all__ = sorted([*_names, *["broad", "compare", "evaluation", "figures", "metrics"]])
