"""Hankel (time-delay) exact DMD for long multichannel records, without building the Hankel matrix.

A record ``Y`` (``n_samples x p``) is delay-embedded with ``d`` delays: Hankel column ``k`` is
``[y_k; y_{k+1}; ...; y_{k+d-1}]`` (``p d`` rows, row ``i p + c`` = channel ``c`` at delay ``i``), as in the seed
paper (Section 2.3) and PyDMD's ``HankelDMD``. With ``X = H[:, :-1]`` and ``X' = H[:, 1:]``, exact DMD
truncates the SVD ``X = U S V^T`` to rank ``r``, forms ``A~ = U^T X' V S^-1``, takes its eigenpairs
``A~ W = W diag(mu)`` and the (exact) DMD modes ``Phi = X' V S^-1 W``.

Three interchangeable solvers give the same eigenvalues:

``"dense"``
    The textbook path: materialise ``H`` and take a thin SVD. Memory O(p d N). For small problems and as the
    reference in tests.
``"gram"``
    Uses the Hankel structure. Only the row-space Gram ``G = X X^T`` and the cross-Gram ``G' = X' X^T`` (both
    ``p d x p d``) are needed: ``U, S^2`` from ``eigh(G)``, and ``X' V S^-1 = G' U S^-2``. Their blocks are lagged
    correlations of the channels: block ``(i, j)`` of ``Z Z^T`` (``Z`` the ``d+1``-delay Hankel of the snapshot
    pairs) is ``sum_k y_{k+i} y_{k+j}^T``, so the first block row comes from FFT cross-correlations
    (O(p^2 N log N)) with exact edge corrections, and every other block from the one above-left by adding one
    outer product and removing another. Memory O((p d)^2), independent of the record length.
``"randomized"``
    For long delays (``p d`` in the tens of thousands) where even ``G`` does not fit: a randomized range finder
    (Halko, Martinsson & Tropp 2011) with power iterations, whose only access to ``X`` is through products
    ``X @ V`` and ``X^T @ U`` computed as FFT correlations of the channels, in chunks. Memory O(p d r + N r).

Rank: an int, an energy fraction in (0, 1), or ``"auto"``: the Gavish & Donoho (2014) optimal hard threshold
for an unknown noise level, ``tau = omega(beta) * median(singular values)`` with ``beta`` the aspect ratio
``min(p d, n) / max(p d, n)`` of ``X`` and ``omega(beta) ~= 0.56 beta^3 - 0.95 beta^2 + 1.82 beta + 1.43``
(within 1 % of the exact value ``lambda*(beta) / sqrt(median of Marchenko-Pastur)`` for all ``beta``).
"""

from __future__ import annotations

import math
import warnings
from numbers import Integral, Real

import numpy as np
import scipy.fft as sfft
import scipy.linalg as sla

from .validation import (
    MAX_ABS,
    as_2d_float,
    as_records,
    check_fitted,
    check_int,
    check_number,
    constant_channels_across,
    split_at_nonfinite,
)

__all__ = ["HankelDMD", "harmonic_candidates", "svht_omega", "svht_rank"]

_EPS = np.finfo(float).eps
_FFT_CHUNK_BYTES = 16 * 2**20  # working-set cap for one batch of FFT correlations
_METHODS = ("auto", "dense", "gram", "randomized")


# ----------------------------------------------------------------------------------------------- rank selection
def svht_omega(beta: float) -> float:
    """Gavish-Donoho coefficient ``omega(beta)`` of the optimal hard threshold for an unknown noise level.

    Parameters
    ----------
    beta : float
        Aspect ratio ``min(m, n) / max(m, n)`` of the matrix, in (0, 1].

    Returns
    -------
    float
        ``0.56 beta^3 - 0.95 beta^2 + 1.82 beta + 1.43`` (Gavish & Donoho 2014, eq. 5; within 1 % of the exact
        ``lambda*(beta) / sqrt(mu_beta)``).
    """
    beta = check_number("beta", beta, positive=True)
    if beta > 1:
        raise ValueError(f"beta must be in (0, 1], got {beta}")
    return 0.56 * beta**3 - 0.95 * beta**2 + 1.82 * beta + 1.43


def svht_rank(singular_values: object, shape: tuple[int, int], *, floor: float = 0.0) -> int:
    """Rank kept by the Gavish-Donoho optimal hard threshold (unknown noise level).

    Parameters
    ----------
    singular_values : array_like
        All ``min(shape)`` singular values of the matrix (any order).
    shape : (int, int)
        Shape of the matrix the singular values belong to.
    floor : float
        Singular values at or below this absolute level never count (round-off).

    Returns
    -------
    int
        Number of singular values above ``omega(beta) * median``, at least 1.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> low = rng.standard_normal((200, 3)) @ rng.standard_normal((3, 500))
    >>> s = np.linalg.svd(low + 0.1 * rng.standard_normal((200, 500)), compute_uv=False)
    >>> svht_rank(s, (200, 500))
    3
    """
    s = np.sort(np.asarray(singular_values, dtype=float).ravel())[::-1]
    m, n = (int(v) for v in shape)
    if s.size == 0 or m < 1 or n < 1:
        raise ValueError(f"need singular values and a valid shape, got {s.size} values and shape {shape}")
    beta = min(m, n) / max(m, n)
    tau = max(svht_omega(beta) * float(np.median(s)), float(floor))
    return max(1, int(np.count_nonzero(s > tau)))


# ------------------------------------------------------------------------------------------- Hankel structure
def _hankel(y: np.ndarray, rows: int) -> np.ndarray:
    """Dense Hankel matrix (rows * p x n - rows + 1) of one record; row ``i p + c`` = channel c at delay i."""
    n_cols = y.shape[0] - rows + 1
    win = np.lib.stride_tricks.sliding_window_view(y, (rows, y.shape[1]))[:, 0]  # (n_cols, rows, p)
    return np.ascontiguousarray(win.reshape(n_cols, -1).T)


def _lagged_products(y: np.ndarray, n: int, max_lag: int) -> np.ndarray:
    """``B[l] = sum_{k<n} y_k y_{k+l}^T`` for ``l = 0..max_lag`` (needs ``n + max_lag <= len(y)``): (L+1, p, p)."""
    N, p = y.shape
    if max_lag < 8:  # a few skinny GEMMs beat the FFT
        return np.stack([y[:n].T @ y[lag : lag + n] for lag in range(max_lag + 1)])
    # full correlations C(l) = sum_{t <= N-1-l} y_t y_{t+l}^T for lags -max_lag..max_lag via one FFT per pair
    L = sfft.next_fast_len(N + max_lag, real=True)
    F = sfft.rfft(y, L, axis=0, workers=-1)
    C = np.empty((max_lag + 1, p, p))
    per = max(1, _FFT_CHUNK_BYTES // (3 * L * 8))  # channel pairs per inverse FFT batch
    pairs = np.array([(a, b) for a in range(p) for b in range(a, p)])
    for start in range(0, len(pairs), per):
        ia, ib = pairs[start : start + per].T
        c = sfft.irfft(np.conj(F[:, ia]) * F[:, ib], L, axis=0, workers=-1)
        C[:, ia, ib] = c[: max_lag + 1]  # lags 0..max_lag: sum_t y_a[t] y_b[t+l]
        C[:, ib, ia] = np.concatenate([c[:1], c[L - max_lag :][::-1]])  # sum_t y_b[t] y_a[t+l] = lag -l of (a, b)
    # exact edge correction: remove the pairs with t >= n (there are N - l - n of them per lag)
    tail = y[n:]
    for lag in range(max_lag + 1):
        k = N - lag - n
        if k > 0:
            C[lag] -= tail[:k].T @ y[n + lag : n + lag + k]
    return C


def _extended_gram(y: np.ndarray, d: int) -> np.ndarray:
    """``Z Z^T`` for the (d+1)-delay Hankel ``Z`` of the ``n = N - d`` snapshot pairs of one record.

    ``X X^T = ZZ[:pd, :pd]`` and ``X' X^T = ZZ[p:, :pd]``. Equals the dense product to round-off.
    """
    N, p = y.shape
    n = N - d
    B0 = _lagged_products(y, n, d)  # block (0, l)
    ZZ = np.empty((d + 1, p, d + 1, p))
    for lag in range(d + 1):
        m = d + 1 - lag  # number of blocks on this block diagonal
        blocks = np.empty((m, p, p))
        blocks[0] = B0[lag]
        if m > 1:
            # block(i+1, i+1+l) = block(i, i+l) - y_i y_{i+l}^T + y_{i+n} y_{i+n+l}^T
            delta = np.einsum("ip,iq->ipq", y[n : n + m - 1], y[n + lag : n + lag + m - 1])
            delta -= np.einsum("ip,iq->ipq", y[: m - 1], y[lag : lag + m - 1])
            np.cumsum(delta, axis=0, out=delta)
            blocks[1:] = B0[lag] + delta
        idx = np.arange(m)
        ZZ[idx, :, idx + lag, :] = blocks
        if lag:
            ZZ[idx + lag, :, idx, :] = blocks.transpose(0, 2, 1)
    return ZZ.reshape((d + 1) * p, (d + 1) * p)


class _HankelProducts:
    """Products with the (virtual) Hankel matrices ``X`` (shift 0) and ``X'`` (shift 1) of a list of records.

    ``X`` is ``p d x n_total`` with the snapshot columns of all records side by side (never across a boundary).
    """

    def __init__(self, records: list[np.ndarray], d: int) -> None:
        self.d = d
        self.p = records[0].shape[1]
        self.parts = []  # (column offset, n, L, {shift: rfft of the shifted record})
        offset = 0
        for y in records:
            n = y.shape[0] - d
            L = sfft.next_fast_len(n + d - 1, real=True)
            spectra = {s: sfft.rfft(y[s : s + n + d - 1], L, axis=0, workers=-1) for s in (0, 1)}
            self.parts.append((offset, n, L, spectra))
            offset += n
        self.n_total = offset

    def _chunk(self, L: int) -> int:
        return max(1, _FFT_CHUNK_BYTES // (3 * (L // 2 + 1) * 16 * self.p))

    def matmat(self, V: np.ndarray, shift: int = 0) -> np.ndarray:
        """``X @ V`` (shift 0) or ``X' @ V`` (shift 1); V is (n_total, l), result (p d, l)."""
        d, p = self.d, self.p
        out = np.zeros((d, p, V.shape[1]))
        for offset, n, L, spectra in self.parts:
            Fa = spectra[shift][:, :, None]
            step = self._chunk(L)
            for j in range(0, V.shape[1], step):
                Fv = np.conj(sfft.rfft(V[offset : offset + n, j : j + step], L, axis=0, workers=-1))
                # out[i, c, j] = sum_k V[k, j] y[k + shift + i, c]: a cross-correlation, first d lags
                out[:, :, j : j + step] += sfft.irfft(Fa * Fv[:, None, :], L, axis=0, workers=-1)[:d]
        return out.reshape(d * p, V.shape[1])

    def rmatmat(self, U: np.ndarray, shift: int = 0) -> np.ndarray:
        """``X^T @ U`` (shift 0) or ``X'^T @ U``; U is (p d, l), result (n_total, l)."""
        d, p = self.d, self.p
        U3 = U.reshape(d, p, U.shape[1])
        out = np.empty((self.n_total, U.shape[1]))
        for offset, n, L, spectra in self.parts:
            Fa = spectra[shift]
            step = self._chunk(L)
            for j in range(0, U.shape[1], step):
                Fu = sfft.rfft(U3[:, :, j : j + step], L, axis=0, workers=-1)  # (L/2+1, p, chunk)
                # out[k, j] = sum_c sum_i U[i, c, j] y[k + shift + i, c]
                acc = np.einsum("fcj,fc->fj", np.conj(Fu), Fa)
                out[offset : offset + n, j : j + step] = sfft.irfft(acc, L, axis=0, workers=-1)[:n]
        return out


def _phase_locking(records: list[np.ndarray], Phi: np.ndarray, mu: np.ndarray, d: int, seed: int) -> np.ndarray:
    """Phase-locking value of each mode's coordinate over the training records, in [0, 1].

    The modal coordinates ``q_j(k)`` (least-squares expansion of Hankel column ``k`` in the modes) are evaluated at
    up to 2048 random columns per record. A forced harmonic is a constant-amplitude phasor rotating at its
    frequency for the whole record; a randomly excited mode's phase wanders and a free decay's amplitude fades.
    Value: ``max_w |mean_k q_j(k) e^{-i w k}| / rms_k |q_j(k)|`` (the share of the coordinate's RMS that one
    steady line explains), ``w`` scanned within 4 frequency bins (``1 / record length``) of the mode's DMD
    frequency, averaged over records weighted by the number of columns used.
    """
    P, r = Phi.shape
    Qf, Rf = np.linalg.qr(Phi)
    Qr, Qi = np.ascontiguousarray(Qf.real.T), np.ascontiguousarray(Qf.imag.T)  # real GEMMs on the real columns
    rng = np.random.default_rng(seed)
    grid = np.linspace(-4.0, 4.0, 81)
    total = np.zeros(r)
    weight = 0
    for y in records:
        m_cols = y.shape[0] - d + 1
        M = min(m_cols, 2048)
        ks = np.sort(rng.choice(m_cols, M, replace=False))
        windows = np.lib.stride_tricks.sliding_window_view(y, (d, y.shape[1]))[:, 0]
        q = np.empty((r, M), dtype=complex)
        step = max(1, 2**20 // P)  # columns per batch (8 MB)
        for j in range(0, M, step):
            cols = windows[ks[j : j + step]].reshape(-1, P).T
            q[:, j : j + step] = sla.solve_triangular(Rf, (Qr @ cols) - 1j * (Qi @ cols))
        norm = np.sqrt(M * np.sum(np.abs(q) ** 2, axis=1))
        # demodulate at each mode's frequency, then scan +-4 bins: |sum_k q e^{-i w_j k} e^{-i delta k}|
        demod = q * np.exp(-1j * np.outer(np.angle(mu), ks))
        coherent = np.abs(demod @ np.exp(-1j * np.outer(ks, 2 * np.pi * grid / m_cols))).max(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            total += M * np.where(norm > 0, coherent / norm, 0.0)
        weight += M
    return total / weight


# ------------------------------------------------------------------------------------------------- estimator
class HankelDMD:
    """Hankel (time-delay) exact dynamic mode decomposition of multichannel records.

    Parameters
    ----------
    delays : int or float
        Delay depth ``d``: an int is a number of samples (the seed paper's ``d`` in [45, 75]), a float a duration
        in seconds (needs ``dt``; rounded to whole samples). ``d = 1`` is plain DMD.
    rank : int, float or "auto"
        Truncation rank ``r``: an int; a float in (0, 1) = smallest rank whose singular values hold that fraction of
        ``||X||_F^2``; ``"auto"`` = Gavish-Donoho optimal hard threshold (unknown noise, beta of the Hankel matrix).
        ``"auto"`` and fractions need the whole spectrum (``"dense"`` or ``"gram"``).
    dt : float, optional
        Sampling interval (s). Without it, frequencies are in cycles per sample and ``dt_ = 1``.
    method : {"auto", "dense", "gram", "randomized"}
        Solver (see the module notes). ``"auto"``: ``"gram"`` if its matrices fit in ``exact_svd_max_bytes``, else
        ``"randomized"``.
    exact_svd_max_bytes : int
        Memory budget (bytes) for the exact solvers; ``"auto"`` falls back to ``"randomized"`` above it and an
        explicit ``"dense"``/``"gram"`` beyond it is refused with a clear error.
    missing : {"raise", "split"}
        NaN in the data: ``"raise"`` a ``ValueError`` naming channels and samples; ``"split"`` the record at every
        sample with a NaN and fit the finite pieces as separate records (pieces shorter than ``delays + 2``
        samples are dropped; ``n_records_`` and ``n_dropped_samples_`` say what happened).
    n_oversamples, n_power_iter, random_state : int
        Randomized solver: extra sketch columns, power iterations, seed.

    Attributes
    ----------
    eigenvalues_ : ndarray (r,) complex
        Discrete-time DMD eigenvalues ``mu`` (per sample), sorted by frequency, each conjugate pair positive first.
    continuous_eigenvalues_ : ndarray (r,) complex
        ``log(mu) / dt`` (1/s).
    frequencies_hz_ : ndarray (r,)
        ``Im(lambda) / 2 pi`` (Hz; signed, conjugates have opposite signs).
    damping_ratios_ : ndarray (r,)
        ``-Re(lambda) / |lambda|`` (-).
    modes_ : ndarray (p, r) complex
        Physical mode shapes: the first ``p`` rows of the DMD modes.
    hankel_modes_ : ndarray (p d, r) complex
        Full (delay-embedded) exact DMD modes ``Phi``, unit-norm columns scaled as PyDMD's (``X' V S^-1 W``).
    amplitudes_ : ndarray (r,) complex
        ``b`` = least-squares fit of ``hankel_modes_`` to the first Hankel column of the first record.
    mode_energies_ : ndarray (r,)
        Share of the training data's energy carried by each mode (sums to 1): mean square of its coefficient in
        the least-squares modal expansion of all snapshots, times the squared norm of its mode.
    phase_locking_ : ndarray (r,)
        Phase locking of each mode's coordinate over the training records, in [0, 1]: the share of its RMS that
        one steady (constant amplitude and phase) line explains. Near 1 for a forced harmonic; small for a
        randomly excited mode (its phase wanders on the time scale ``1 / (zeta omega)``) and for a free decay
        that fades within the record. See :meth:`mode_table`.
    singular_values_ : ndarray
        All singular values of ``X`` the solver computed (all of them for dense/gram, the sketch's for randomized).
    rank_ : int
        Rank used.
    reduced_operator_ : ndarray (r, r)
        ``A~`` in the basis of the leading left singular vectors.
    basis_ : ndarray (p d, r)
        Those leading left singular vectors ``U`` (orthonormal columns): ``h ~ U a`` for a Hankel column ``h``, and
        ``a[k+1] ~ A~ a[k]`` is the real linear (Koopman) model that :attr:`eigenvalues_` diagonalise.
    dt_ : float
    delays_ : int
    method_ : str
        Solver used.
    n_features_in_ : int
        Number of channels ``p``.
    n_snapshots_ : int
        Number of snapshot pairs used (columns of ``X``, all records).
    n_records_ : int
    n_dropped_samples_ : int
        Samples not used because of NaN (``missing="split"``).

    Raises
    ------
    ValueError
        From :meth:`fit` on NaN/inf (channels and samples listed), a record shorter than ``delays + 2``, a rank
        larger than ``min(p d, n_snapshots)``, constant channels, a float ``delays`` without ``dt``, or a
        solver that does not fit in memory.

    Notes
    -----
    A requested rank above the numerical rank of ``X`` (exactly low-rank synthetic data) is lowered to it with a
    ``RuntimeWarning``; ``rank_`` reports the rank used.

    Examples
    --------
    >>> import numpy as np
    >>> dt = 0.0125
    >>> t = np.arange(4000) * dt
    >>> env = np.exp(-0.02 * np.pi * t)  # 0.5 Hz, 2 % damping
    >>> Y = np.c_[env * np.cos(np.pi * t), -0.5 * env * np.cos(np.pi * t), env * np.sin(np.pi * t)]
    >>> dmd = HankelDMD(delays=40, rank=2, dt=dt).fit(Y)
    >>> print(f"{dmd.frequencies_hz_[0]:.4f} Hz, zeta = {dmd.damping_ratios_[0]:.4f}")
    0.5000 Hz, zeta = 0.0200
    >>> dmd.mode_table()[0]["kind"]
    'structural'
    """

    def __init__(
        self,
        delays: int | float = 60,
        rank: int | float | str = "auto",
        dt: float | None = None,
        method: str = "auto",
        exact_svd_max_bytes: int = 256 * 2**20,
        missing: str = "raise",
        n_oversamples: int = 10,
        n_power_iter: int = 2,
        random_state: int | None = 0,
    ) -> None:
        self.delays = delays
        self.rank = rank
        self.dt = dt
        self.method = method
        self.exact_svd_max_bytes = exact_svd_max_bytes
        self.missing = missing
        self.n_oversamples = n_oversamples
        self.n_power_iter = n_power_iter
        self.random_state = random_state

    # ------------------------------------------------------------------------------------------ arguments
    def _resolve_delays(self, dt: float | None) -> int:
        d = self.delays
        if isinstance(d, bool):
            raise ValueError(f"delays must be an int (samples) or a float (seconds), got {d!r}")
        if isinstance(d, Integral):
            return check_int("delays", d, minimum=1)
        if isinstance(d, Real):
            secs = check_number("delays (seconds)", d, positive=True)
            if dt is None:
                raise ValueError(f"delays = {d!r} is a float, i.e. seconds: give dt, or pass an int number of samples")
            n = int(round(secs / dt))
            if n < 1:
                raise ValueError(f"delays = {secs} s is less than one sample at dt = {dt} s")
            return n
        raise ValueError(f"delays must be an int (samples) or a float (seconds), got {d!r}")

    def _check_rank_spec(self) -> int | float | str:
        r = self.rank
        if isinstance(r, str):
            if r != "auto":
                raise ValueError(f"rank must be an int, a float in (0, 1) or 'auto', got {r!r}")
            return r
        if isinstance(r, Integral) and not isinstance(r, bool):
            return check_int("rank", r, minimum=1)
        if isinstance(r, Real) and not isinstance(r, bool):
            return check_number("rank (energy fraction)", r, low=0.0, high=1.0)
        raise ValueError(f"rank must be an int, a float in (0, 1) or 'auto', got {r!r}")

    def _records(self, Y: object, d: int) -> tuple[list[np.ndarray], int]:
        if self.missing not in ("raise", "split"):
            raise ValueError(f"missing must be 'raise' or 'split', got {self.missing!r}")
        split = self.missing == "split"
        records = as_records(Y, "Y", allow_nan=split, min_samples=1, max_abs=MAX_ABS)
        dropped = 0
        if split:
            pieces, dropped = split_at_nonfinite(records, d + 2)
            if not pieces:
                raise ValueError(
                    f"Y has no finite stretch of at least delays + 2 = {d + 2} samples (missing='split' dropped all)"
                )
            records = pieces
        for i, rec in enumerate(records):
            if rec.shape[0] < d + 2:
                name = "Y" if len(records) == 1 else f"Y[{i}]"
                raise ValueError(
                    f"{name} has {rec.shape[0]} samples; delays = {d} needs at least delays + 2 = {d + 2} "
                    "(one delay window plus two snapshots)"
                )
        const = constant_channels_across(records)
        if const.size:
            raise ValueError(
                f"Y has constant channel(s) {const.tolist()}: they carry no dynamics and make the Hankel matrix "
                "singular (a dead or saturated sensor?); remove them before fitting"
            )
        return records, dropped

    def _choose_method(self, P: int, n_total: int) -> str:
        if self.method not in _METHODS:
            raise ValueError(f"method must be one of {_METHODS}, got {self.method!r}")
        budget = check_int("exact_svd_max_bytes", self.exact_svd_max_bytes, minimum=1)
        gram_bytes = 3 * 8 * (P + self.n_features_in_) ** 2
        dense_bytes = 3 * 8 * P * (n_total + 1) + 8 * min(P, n_total) ** 2
        if self.method == "auto":
            return "gram" if gram_bytes <= budget else "randomized"
        if self.method == "gram" and gram_bytes > budget:
            raise ValueError(
                f"method='gram' needs about {gram_bytes / 2**20:.0f} MiB for p*d = {P} > exact_svd_max_bytes = "
                f"{budget / 2**20:.0f} MiB; use method='randomized' (or raise exact_svd_max_bytes)"
            )
        if self.method == "dense" and dense_bytes > budget:
            raise ValueError(
                f"method='dense' needs about {dense_bytes / 2**20:.0f} MiB for a {P} x {n_total} Hankel matrix > "
                f"exact_svd_max_bytes = {budget / 2**20:.0f} MiB; use method='gram' or 'randomized'"
            )
        return self.method

    def _pick_rank(self, spec: int | float | str, s: np.ndarray, shape: tuple[int, int], floor: float) -> int:
        n_num = int(np.count_nonzero(s > floor))
        if n_num == 0:
            raise ValueError("the Hankel matrix of Y is numerically zero")
        if spec == "auto":
            return svht_rank(s, shape, floor=floor)
        if isinstance(spec, float):
            e = np.cumsum(s**2) / np.sum(s**2)
            r = int(np.searchsorted(e, spec) + 1)
        else:
            r = int(spec)
        if r > n_num:
            warnings.warn(
                f"rank {r} exceeds the numerical rank {n_num} of the Hankel matrix; using rank {n_num}",
                RuntimeWarning,
                stacklevel=3,
            )
            r = n_num
        return r

    # --------------------------------------------------------------------------------------------- solvers
    def _solve_dense(self, records, d, spec):
        X = np.concatenate([_hankel(y[:-1], d) for y in records], axis=1)
        try:
            U, s, Vt = np.linalg.svd(X, full_matrices=False)
        except np.linalg.LinAlgError as exc:  # pragma: no cover - LAPACK non-convergence
            raise ValueError(f"SVD of the Hankel matrix did not converge: {exc}") from exc
        r = self._pick_rank(spec, s, X.shape, max(X.shape) * _EPS * s[0])
        del X
        Xp = np.concatenate([_hankel(y[1:], d) for y in records], axis=1)
        XpV = Xp @ Vt[:r].T
        return s, U[:, :r], s[:r], XpV

    def _solve_gram(self, records, d, spec):
        p = self.n_features_in_
        P = p * d
        ZZ = _extended_gram(records[0], d)
        for y in records[1:]:
            ZZ += _extended_gram(y, d)
        G = ZZ[:P, :P]
        n_total = sum(y.shape[0] - d for y in records)
        k = min(P, n_total)
        try:
            lam_all = sla.eigh(G, eigvals_only=True, check_finite=False)[::-1]
        except (np.linalg.LinAlgError, ValueError) as exc:  # pragma: no cover
            raise ValueError(f"eigen-decomposition of the Hankel Gram matrix failed: {exc}") from exc
        s = np.sqrt(np.clip(lam_all[:k], 0.0, None))
        floor = math.sqrt(4 * P * _EPS) * s[0]  # the Gram matrix squares the condition number
        r = self._pick_rank(spec, s, (P, n_total), floor)
        try:
            lam, U = sla.eigh(G, subset_by_index=[P - r, P - 1], check_finite=False)
        except (np.linalg.LinAlgError, ValueError) as exc:  # pragma: no cover
            raise ValueError(f"eigen-decomposition of the Hankel Gram matrix failed: {exc}") from exc
        lam, U = lam[::-1], U[:, ::-1]
        s_r = np.sqrt(np.clip(lam, 0.0, None))
        s[:r] = s_r
        # X' V S^-1 with V = X^T U S^-1  ->  (X' X^T) U S^-2
        XpV = (ZZ[p:, :P] @ U) / s_r
        return s, U, s_r, XpV

    def _solve_randomized(self, records, d, spec):
        if not isinstance(spec, int):
            raise ValueError(
                f"rank={spec!r} needs the whole singular spectrum, which method='randomized' does not compute; "
                "give an int rank (e.g. rank=24), or use method='gram' if the Gram matrix fits"
            )
        ops = _HankelProducts(records, d)
        P, n = d * self.n_features_in_, ops.n_total
        n_power = check_int("n_power_iter", self.n_power_iter, minimum=0)
        ell = min(spec + check_int("n_oversamples", self.n_oversamples, minimum=0), P, n)
        rng = np.random.default_rng(self.random_state)
        Q, _ = np.linalg.qr(ops.matmat(rng.standard_normal((n, ell))))
        for _ in range(n_power):
            Qn, _ = np.linalg.qr(ops.rmatmat(Q))
            Q, _ = np.linalg.qr(ops.matmat(Qn))
        Bt = ops.rmatmat(Q)  # (Q^T X)^T, n x ell
        Vb, s, Ubt = np.linalg.svd(Bt, full_matrices=False)
        r = self._pick_rank(spec, s, (P, n), max(P, n) * _EPS * s[0])
        U = Q @ Ubt[:r].T
        XpV = ops.matmat(Vb[:, :r], shift=1)
        return s, U, s[:r], XpV

    # ------------------------------------------------------------------------------------------------ fit
    def fit(self, Y: object) -> HankelDMD:
        """Identify the DMD eigenvalues and modes of one record or a list of records.

        Parameters
        ----------
        Y : array_like (n_samples, p) or list of such arrays
            Time-major data, usually band-passed and z-scored (:func:`estimators.preprocess`). Records in a list
            are delay-embedded separately and their snapshot pairs pooled: no Hankel column spans two records.

        Returns
        -------
        self
        """
        if self.dt is not None:
            dt = check_number("dt", self.dt, positive=True)
        else:
            dt = None
        d = self._resolve_delays(dt)
        spec = self._check_rank_spec()
        records, dropped = self._records(Y, d)
        p = records[0].shape[1]
        self.n_features_in_ = p
        P = p * d
        n_total = sum(y.shape[0] - d for y in records)
        if isinstance(spec, int) and spec > min(P, n_total):
            raise ValueError(
                f"rank = {spec} is larger than possible: the {P} x {n_total} Hankel matrix (p*delays x snapshots) "
                f"has at most {min(P, n_total)} singular values"
            )
        method = self._choose_method(P, n_total)
        solver = {"dense": self._solve_dense, "gram": self._solve_gram, "randomized": self._solve_randomized}
        s_all, U, s, XpV = solver[method](records, d, spec)
        r = U.shape[1]

        Atilde = (U.T @ XpV) / s
        if not np.isfinite(Atilde).all():
            raise ValueError("the reduced DMD operator is not finite (rank too high for the data's numerical rank?)")
        try:
            mu, W = np.linalg.eig(Atilde)
        except np.linalg.LinAlgError as exc:  # pragma: no cover
            raise ValueError(f"eigen-decomposition of the reduced DMD operator failed: {exc}") from exc
        Phi = (XpV / s) @ W

        order = np.lexsort((-np.abs(mu), mu.imag < 0, np.abs(np.angle(mu))))
        mu, Phi = mu[order], Phi[:, order]

        x0 = records[0][:d].reshape(-1)
        b = np.linalg.lstsq(Phi, x0, rcond=None)[0]
        coef = np.linalg.lstsq(Phi, U * s, rcond=None)[0]  # modal coordinates of the projected snapshots
        energy = np.sum(np.abs(Phi) ** 2, axis=0) * np.sum(np.abs(coef) ** 2, axis=1)
        total = energy.sum()

        self.dt_ = 1.0 if dt is None else dt
        self.delays_ = d
        self.method_ = method
        self.rank_ = r
        self.singular_values_ = s_all
        self.reduced_operator_ = Atilde
        self.basis_ = U
        self.eigenvalues_ = mu
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = np.log(mu) / self.dt_
        self.continuous_eigenvalues_ = lam
        self.frequencies_hz_ = np.where(np.isfinite(lam), lam.imag, 0.0) / (2 * np.pi)
        absl = np.abs(lam)
        with np.errstate(divide="ignore", invalid="ignore"):
            zeta = np.where(absl > 0, -lam.real / absl, 0.0)
        self.damping_ratios_ = np.where(np.isfinite(lam), zeta, 1.0)
        self.hankel_modes_ = Phi
        self.modes_ = Phi[:p]
        self.amplitudes_ = b
        self.mode_energies_ = energy / total if total > 0 else np.full(r, 1.0 / r)
        self.phase_locking_ = _phase_locking(records, Phi, mu, d, seed=0)
        self.n_snapshots_ = n_total
        self.n_records_ = len(records)
        self.n_dropped_samples_ = dropped
        self._n_first = records[0].shape[0]
        self._last_window = records[-1][-d:].copy()
        return self

    # ------------------------------------------------------------------------------------------ forecasting
    def _evolve(self, rows: np.ndarray, b: np.ndarray, powers: np.ndarray) -> np.ndarray:
        """``Re(rows @ diag(b) @ mu^k)`` for the integer powers k, in time chunks; returns (len(powers), n_rows)."""
        mu = self.eigenvalues_
        out = np.empty((powers.size, rows.shape[0]))
        logmu = np.log(mu.astype(complex))
        step = 8192
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for i in range(0, powers.size, step):
                k = powers[i : i + step, None]
                V = np.where(mu == 0, (k == 0).astype(complex), np.exp(k * logmu))
                out[i : i + step] = ((V * b) @ rows.T).real
        return out

    def predict(self, n_steps: int, initial: object = None) -> np.ndarray:
        """Forecast the samples that follow a window of ``delays_`` samples.

        The modal amplitudes are the least-squares fit of :attr:`hankel_modes_` to the delay-embedded window (the
        past only: causal); the forecast is the last delay block of the modes evolved by ``mu^k``.

        Parameters
        ----------
        n_steps : int
            Number of future samples.
        initial : array_like (n >= delays_, p), optional
            Recent samples, oldest first, in the units the model was fitted on; the last ``delays_`` rows are used.
            Default: the last ``delays_`` samples of the (last) training record.

        Returns
        -------
        ndarray (n_steps, p)
            Samples ``1..n_steps`` after the last sample of the window.
        """
        check_fitted(self, "eigenvalues_")
        n_steps = check_int("n_steps", n_steps, minimum=0)
        d, p = self.delays_, self.n_features_in_
        if initial is None:
            window = self._last_window
        else:
            window = as_2d_float(initial, "initial", min_samples=d, n_channels=p)[-d:]
        b = np.linalg.lstsq(self.hankel_modes_, window.reshape(-1), rcond=None)[0]
        return self._evolve(self.hankel_modes_[(d - 1) * p :], b, np.arange(1, n_steps + 1))

    def reconstruct(self, n_samples: int | None = None) -> np.ndarray:
        """Free-run reconstruction ``y_k = Re(sum_j phi_j mu_j^k b_j)`` from :attr:`amplitudes_` (seed paper eq.).

        Parameters
        ----------
        n_samples : int, optional
            Length; default the length of the first training record.

        Returns
        -------
        ndarray (n_samples, p)
        """
        check_fitted(self, "eigenvalues_")
        n = self._n_first if n_samples is None else check_int("n_samples", n_samples, minimum=0)
        return self._evolve(self.modes_, self.amplitudes_, np.arange(n))

    # ------------------------------------------------------------------------------------------- mode table
    def mode_table(
        self,
        *,
        harmonic_damping: float = 0.01,
        min_phase_locking: float = 0.8,
        max_damping: float = 0.2,
        min_energy: float | None = None,
    ) -> list[dict]:
        """One row per mode (a conjugate pair, or a real eigenvalue), sorted by frequency, with a label.

        Parameters
        ----------
        harmonic_damping : float
            Largest ``|zeta|`` of a forced harmonic (default 1 %). A strong line comes out at ``|zeta|`` of a few
            0.01 %; a weak one, mixed with broadband response, at a few 0.1 %.
        min_phase_locking : float
            Smallest :attr:`phase_locking_` of a forced harmonic (default 0.8; randomly excited modes of a record
            many correlation times long score below 0.5, a forced line above 0.95).
        max_damping : float
            Largest damping ratio accepted as structural (default 20 %).
        min_energy : float, optional
            Energy share below which a (non-harmonic) mode is noise. Default: a fifth of an equal share,
            ``0.2 / n_rows``.

        Returns
        -------
        list of dict
            Keys ``frequency_hz`` (>= 0), ``damping_ratio``, ``energy`` (share of the pair, summing to 1 over all
            rows), ``phase_locking``, ``kind`` and ``index`` (position in :attr:`eigenvalues_` of the
            positive-frequency member).

        Notes
        -----
        The rule, in order:

        1. ``"noise"`` if the mode does not oscillate (real eigenvalue: frequency 0 or Nyquist) or grows
           (``zeta < -harmonic_damping``);
        2. ``"harmonic"`` if it is phase-locked over the record (``phase_locking >= min_phase_locking``) and
           (nearly) undamped (``|zeta| < harmonic_damping``): a deterministic line, whatever its energy;
        3. ``"noise"`` if it carries less than ``min_energy`` or decays faster than ``max_damping``;
        4. ``"structural"`` otherwise.

        Damping alone does not tell a harmonic from a structural mode: DMD of a randomly excited response
        underestimates damping, badly so for long delays (its eigenvalues then crowd onto the unit circle), but
        the phase of a randomly excited mode wanders while a forced line keeps its phase for the whole record.
        On a record not much longer than a mode's correlation time ``1 / (zeta omega)`` the two cannot be told
        apart; :func:`harmonic_candidates` also checks that a line is stable over several delays.
        """
        check_fitted(self, "eigenvalues_")
        hd = check_number("harmonic_damping", harmonic_damping, positive=True)
        md = check_number("max_damping", max_damping, positive=True)
        mpl = check_number("min_phase_locking", min_phase_locking, nonneg=True)
        mu = self.eigenvalues_
        real = np.abs(mu.imag) <= 1e-12 * np.maximum(np.abs(mu), 1e-300)
        rows = []
        used = np.zeros(mu.size, dtype=bool)
        for i in range(mu.size):
            if used[i] or (not real[i] and mu[i].imag < 0):
                continue
            used[i] = True
            energy = float(self.mode_energies_[i])
            if not real[i]:
                cand = np.flatnonzero(~used & (mu.imag < 0) & ~real)
                if cand.size:
                    j = cand[np.argmin(np.abs(mu[cand] - np.conj(mu[i])))]
                    used[j] = True
                    energy += float(self.mode_energies_[j])
            rows.append(
                {
                    "index": int(i),
                    "frequency_hz": float(abs(self.frequencies_hz_[i])),
                    "damping_ratio": float(self.damping_ratios_[i]),
                    "energy": energy,
                    "phase_locking": float(self.phase_locking_[i]),
                    "_real": bool(real[i]),
                }
            )
        floor = 0.2 / len(rows) if min_energy is None else check_number("min_energy", min_energy, nonneg=True)
        for row in rows:
            z = row["damping_ratio"]
            if row.pop("_real") or not np.isfinite(z) or z < -hd:
                row["kind"] = "noise"
            elif row["phase_locking"] >= mpl and abs(z) < hd:
                row["kind"] = "harmonic"
            elif row["energy"] < floor or z > md:
                row["kind"] = "noise"
            else:
                row["kind"] = "structural"
        rows.sort(key=lambda row: (row["frequency_hz"], row["index"]))
        return rows


def harmonic_candidates(
    Y: object,
    dt: float,
    delays: tuple[int, ...] = (45, 60, 75),
    rank: int | float | str = 24,
    *,
    harmonic_damping: float = 0.01,
    min_phase_locking: float = 0.8,
    freq_rtol: float = 0.01,
    **kwargs: object,
) -> list[dict]:
    """Forced harmonics: lines that stay undamped at the same frequency whatever the delay depth.

    A structural mode's identified damping and frequency move with the delay ``d``; a forced sinusoid (rotor 3P)
    stays on the unit circle and phase-locked. Fits one :class:`HankelDMD` per delay and keeps the lines labelled
    ``"harmonic"`` by :meth:`HankelDMD.mode_table` at every delay, at the same frequency (within ``freq_rtol``).

    Parameters
    ----------
    Y : array_like (n_samples, p) or list of records
    dt : float
        Sampling interval (s).
    delays : tuple of int
        Delay depths to compare (samples); the seed paper uses 45-75.
    rank : int, float or "auto"
        Rank for every fit.
    harmonic_damping, min_phase_locking : float
        Passed to :meth:`HankelDMD.mode_table`.
    freq_rtol : float
        Relative frequency tolerance when matching lines across delays.
    **kwargs
        Passed to :class:`HankelDMD` (``method``, ...).

    Returns
    -------
    list of dict
        ``frequency_hz`` (mean over delays), ``frequency_spread_hz`` (max - min), ``damping_ratios`` (one per
        delay), ``energy`` (mean share), ``phase_locking`` (smallest over delays), sorted by frequency.
    """
    if not delays:
        raise ValueError("delays must list at least one delay depth")
    tables = [
        HankelDMD(delays=d, rank=rank, dt=dt, **kwargs)
        .fit(Y)
        .mode_table(harmonic_damping=harmonic_damping, min_phase_locking=min_phase_locking)
        for d in delays
    ]
    out = []
    for row in (r for r in tables[0] if r["kind"] == "harmonic"):
        f0 = row["frequency_hz"]
        matches = [row]
        for table in tables[1:]:
            near = [r for r in table if r["kind"] == "harmonic" and abs(r["frequency_hz"] - f0) <= freq_rtol * f0]
            if not near:
                break
            matches.append(min(near, key=lambda r, f0=f0: abs(r["frequency_hz"] - f0)))
        if len(matches) == len(tables):
            f = [m["frequency_hz"] for m in matches]
            out.append(
                {
                    "frequency_hz": float(np.mean(f)),
                    "frequency_spread_hz": float(np.ptp(f)),
                    "damping_ratios": [m["damping_ratio"] for m in matches],
                    "energy": float(np.mean([m["energy"] for m in matches])),
                    "phase_locking": float(min(m["phase_locking"] for m in matches)),
                }
            )
    return sorted(out, key=lambda r: r["frequency_hz"])
