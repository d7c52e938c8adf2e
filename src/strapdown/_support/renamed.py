"""Keyword arguments renamed since release 0.1, still accepted under their old names (private).

Release 0.1 named the gyro ``gyr`` in the estimators and calibrations and ``gyro`` everywhere else; the library
now says ``gyro`` (and ``acc``, ``mag``) everywhere (docs/architecture.md, "One vocabulary").  A call with the old
keyword still works, with a ``DeprecationWarning`` that names the new one.
"""

from __future__ import annotations

import functools
import warnings


def renamed(**new_of_old: str):
    """Decorate a function so that each old keyword (``gyr=``) is passed on as its new one (``gyro=``).

    Parameters
    ----------
    **new_of_old : str
        Old keyword -> new keyword.

    Returns
    -------
    callable
        The decorator; the function keeps its signature (``inspect.signature`` follows ``__wrapped__``).

    Examples
    --------
    >>> import warnings
    >>> from strapdown._support.renamed import renamed
    >>> @renamed(gyr="gyro")
    ... def f(gyro):
    ...     return gyro
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     f(gyr=1), caught[0].category.__name__
    (1, 'DeprecationWarning')
    """

    def decorate(fn):
        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            for old, new in new_of_old.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(f"{fn.__qualname__}() got both {old}= and {new}= ({old} is the old name)")
                    warnings.warn(f"{fn.__qualname__}(): {old}= is now {new}=", DeprecationWarning, stacklevel=2)
                    kwargs[new] = kwargs.pop(old)
            return fn(*args, **kwargs)

        return wrapper

    return decorate
