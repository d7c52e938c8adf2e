"""Cayley-Klein parameters: the 2×2 complex SU(2) matrix of a rotation.

With the Pauli matrices σ1, σ2, σ3 and the identification ``i = -iσ1, j = -iσ2, k = -iσ3`` (the Rowe patent,
eqs. 12-13A) a quaternion ``q = w + x i + y j + z k`` becomes

    U = w σ0 - i (x σ1 + y σ2 + z σ3) = [[w - iz, -y - ix], [y - ix, w + iz]] = [[α, β], [-β̄, ᾱ]],

so ``α = w - iz`` and ``β = -y - ix`` are the Cayley-Klein parameters (Gajda §1 lists them among the
four-parameter methods).  The map is an algebra homomorphism, ``U(p ⊗ q) = U(p) U(q)``, and a vector v rotates as
``U (v·σ) U† = (C v)·σ`` with ``C = as_matrix(q)``.  A unit quaternion gives a unitary U with det U = 1.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["as_cayley_klein", "from_cayley_klein"]


def as_cayley_klein(q, *, check: bool = True) -> np.ndarray:
    """SU(2) matrices ``[[α, β], [-β̄, ᾱ]]`` of unit quaternions.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions of any non-zero norm; they are normalised first.

    Returns
    -------
    numpy.ndarray, shape (..., 2, 2), complex
        complex64 for float32 input, complex128 otherwise.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_cayley_klein
    >>> u = as_cayley_klein([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])    # 90 deg about z
    >>> bool(np.allclose(u, np.diag([np.exp(-1j * np.pi / 4), np.exp(1j * np.pi / 4)])))
    True
    """
    q = _v.rotations(q, "q", check=check)
    q = q / np.sqrt(np.einsum("...i,...i->...", q, q))[..., None]
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    ctype = np.complex64 if q.dtype == np.float32 else np.complex128
    out = np.empty((*q.shape[:-1], 2, 2), dtype=ctype)
    out[..., 0, 0] = w - 1j * z
    out[..., 0, 1] = -y - 1j * x
    out[..., 1, 0] = y - 1j * x
    out[..., 1, 1] = w + 1j * z
    return out


def from_cayley_klein(u, *, atol: float = 1e-6, check: bool = True) -> np.ndarray:
    """Unit quaternions from SU(2) matrices.

    Parameters
    ----------
    u : array_like, shape (..., 2, 2), complex
        Matrices of the form ``[[α, β], [-β̄, ᾱ]]`` with ``|α|² + |β|² = 1``.
    atol : float
        Tolerance of the structure and unit-determinant checks.
    check : bool
        Reject NaN, infinities and matrices that are not in SU(2) within ``atol`` (default).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``w = Re(α)``, ``x = -Im(β)``, ``y = -Re(β)``, ``z = -Im(α)``, each averaged over the two entries that
        carry it, then normalised.  No sign is chosen: ``U`` and ``-U`` give ``q`` and ``-q``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_cayley_klein, from_cayley_klein
    >>> from_cayley_klein(as_cayley_klein([0.5, 0.5, 0.5, 0.5]))
    array([0.5, 0.5, 0.5, 0.5])
    """
    u = np.asarray(u)
    if u.ndim < 2 or u.shape[-2:] != (2, 2):
        raise ValueError(f"u must have shape (..., 2, 2) (SU(2) matrices), got shape {u.shape}")
    if u.dtype.kind not in "fciub":
        raise ValueError(f"u must be numeric, got dtype {u.dtype}")
    if check and not np.isfinite(u).all():
        raise ValueError(f"u{_v.first_index(~np.isfinite(u))} is not finite; u must hold finite numbers")
    a, b, c, d = u[..., 0, 0], u[..., 0, 1], u[..., 1, 0], u[..., 1, 1]
    real = np.float32 if u.dtype in (np.complex64, np.float32) else np.float64
    q = np.empty((*u.shape[:-2], 4), dtype=real)
    q[..., 0] = 0.5 * (a.real + d.real)
    q[..., 1] = -0.5 * (b.imag + c.imag)
    q[..., 2] = 0.5 * (c.real - b.real)
    q[..., 3] = 0.5 * (d.imag - a.imag)
    if check:
        # Distance from the SU(2) form [[α, β], [-β̄, ᾱ]] and from det = 1.
        form = np.maximum(np.abs(d - np.conj(a)), np.abs(c + np.conj(b)))
        det_err = np.abs(a * d - b * c - 1)
        bad = ~((form <= atol) & (det_err <= atol))
        if bad.any():
            raise ValueError(
                f"u{_v.first_index(bad)} is not in SU(2) (form error {form[bad][0]:.3g}, |det - 1| = "
                f"{det_err[bad][0]:.3g}, atol={atol:g})"
            )
    return q / np.sqrt(np.einsum("...i,...i->...", q, q))[..., None]
