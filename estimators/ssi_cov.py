"""Covariance-driven stochastic subspace identification (SSI-COV) with a stabilisation diagram.

Peeters & De Roeck (1999), "Reference-based stochastic subspace identification for output-only modal analysis",
Mechanical Systems and Signal Processing 13(6). For outputs ``y_k`` (``p`` channels) and reference channels
``y_k^ref`` (``r`` of them, a subset of the outputs):

1. Output correlations ``R_l = E[y_{k+l} y_k^ref^T]`` (``p x r``), estimated as ``sum_k y_{k+l} y_k^ref^T`` over all
   pairs inside one record, pooled over records and divided by the number of pairs (never across a record
   boundary). The sums come from FFT cross-correlations of blocks of the record (overlap-save), exact to round-off.
2. Block Toeplitz matrix ``T`` (``p i x r i``, ``i`` = ``block_rows``): block ``(a, b)`` is ``R_{i + a - b}`` (lags
   ``1 .. 2i - 1``). In theory ``T = O_i Gamma_i`` (observability times reversed controllability matrix).
3. SVD ``T = U S V^T``; for model order ``n``: ``O = U_n S_n^(1/2)``, ``C`` = its first block row and ``A`` the
   least-squares solution of the shift equation ``O[:-p] A = O[p:]`` (one QR for all orders).
4. Eigen-decomposition ``A psi = mu psi``; continuous poles ``lambda = ln(mu) / dt``; damped frequency
   ``Im(lambda) / 2 pi`` (Hz, the convention of :class:`estimators.hankel_dmd.HankelDMD` and of the surrogate's
   modal analysis; SSI papers often quote ``|lambda| / 2 pi``, larger by ``1 / sqrt(1 - zeta^2)``), damping ratio
   ``-Re(lambda) / |lambda|`` and mode shape ``C psi``.
5. Stabilisation diagram: a pole of order ``n`` is stable if, against its nearest pole of the next lower order in
   ``orders``, its frequency moved by less than ``freq_tol`` (1 %), its damping by less than ``damping_tol``
   (5 %, relative) and its shape MAC exceeds ``min_mac`` (0.98), with ``harmonic_damping <= zeta < max_damping``.
6. Stable poles are clustered over all orders (average linkage on ``|df| / f + 1 - MAC``); a cluster with stable
   poles at ``min_stable`` orders or more is a mode, reported by its medians (one pole per order).

A forced harmonic (rotor 1P/3P) in the response is a pole on the unit circle: its frequency and shape are as stable
as a mode's, but its damping scatters around zero, so the relative damping criterion never holds. Such poles
(``|zeta| < harmonic_damping``, frequency and shape stable) are clustered separately and reported as
:attr:`SSICov.harmonics_` and as ``"harmonic"`` rows of :meth:`SSICov.mode_table`, never as modes.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from numbers import Integral, Real

import numpy as np
import scipy.fft as sfft
import scipy.linalg as sla
from scipy.cluster.hierarchy import fcluster, linkage

from .validation import (
    MAX_ABS,
    as_records,
    check_fitted,
    check_int,
    check_number,
    constant_channels_across,
    split_at_nonfinite,
)

__all__ = ["SSICov", "correlation_sums"]

_FFT_CHUNK_BYTES = 32 * 2**20  # working-set cap for one batch of block spectra


# ------------------------------------------------------------------------------------------------ correlations
def correlation_sums(Y: np.ndarray, ref: np.ndarray, max_lag: int) -> np.ndarray:
    """Lagged cross-product sums ``S[l] = sum_{k=0}^{N-1-l} y_{k+l} ref_k^T`` for ``l = 0 .. max_lag``.

    Computed with FFTs of blocks of the record (each block of ``ref`` against the stretch of ``y`` it can reach),
    the block spectra multiplied and summed in the frequency domain, and one inverse FFT per channel pair:
    O(N p log B + N p r) work and O(B p r) memory, exact to round-off.

    Parameters
    ----------
    Y : ndarray (n_samples, p)
        Outputs (float64, finite).
    ref : ndarray (n_samples, r)
        Reference channels, same number of samples.
    max_lag : int
        Largest lag (samples), ``0 <= max_lag < n_samples``.

    Returns
    -------
    ndarray (max_lag + 1, p, r)
        Sums (not means): divide lag ``l`` by ``n_samples - l`` for the unbiased correlation estimate.

    Examples
    --------
    >>> import numpy as np
    >>> y = np.random.default_rng(0).standard_normal((1000, 2))
    >>> S = correlation_sums(y, y[:, :1], 3)
    >>> bool(np.isclose(S[2, 1, 0], y[2:, 1] @ y[:-2, 0]))
    True
    """
    Y = np.asarray(Y, dtype=float)
    ref = np.asarray(ref, dtype=float)
    if Y.ndim != 2 or ref.ndim != 2 or ref.shape[0] != Y.shape[0]:
        raise ValueError(f"Y and ref must be 2-D with the same number of samples, got {Y.shape} and {ref.shape}")
    N, p = Y.shape
    r = ref.shape[1]
    max_lag = check_int("max_lag", max_lag)
    if max_lag < 0 or max_lag >= N:
        raise ValueError(f"max_lag must be in [0, {N - 1}] for {N} samples, got {max_lag}")
    if N * (max_lag + 1) <= 2**16:  # tiny problem: direct products
        return np.stack([Y[lag:].T @ ref[: N - lag] for lag in range(max_lag + 1)])
    B = max(2048, 8 * (max_lag + 1))  # block length of ref
    L = sfft.next_fast_len(B + max_lag, real=True)
    n_blocks = -(-N // B)
    ypad = np.zeros((n_blocks * B + L, p))
    ypad[:N] = Y
    rpad = np.zeros((n_blocks * B, r))
    rpad[:N] = ref
    n_freq = L // 2 + 1
    acc = np.zeros((n_freq, p, r), dtype=complex)
    per = max(1, _FFT_CHUNK_BYTES // (16 * n_freq * (p + r)))  # blocks per batch
    yseg = np.lib.stride_tricks.sliding_window_view(ypad, (L, p))[::B, 0]  # (n_blocks + ..., L, p), views
    for start in range(0, n_blocks, per):
        stop = min(start + per, n_blocks)
        # frequency-major spectra (nf, nb, channels) of y[bB : bB + L] and of ref[bB : (b + 1) B] (zero-padded)
        Fy = sfft.rfft(yseg[start:stop].transpose(1, 0, 2), L, axis=0, workers=-1)
        Fr = sfft.rfft(rpad[start * B : stop * B].reshape(stop - start, B, r).transpose(1, 0, 2), L, axis=0, workers=-1)
        # sum over blocks of Y(f) conj(R(f)): a batched (p x nb) @ (nb x r) product per frequency
        acc += np.matmul(Fy.transpose(0, 2, 1), np.conj(Fr))
    # circular correlation of length L >= B + max_lag has no wrap-around for lags 0 .. max_lag
    return sfft.irfft(acc, L, axis=0, workers=-1)[: max_lag + 1]


# ------------------------------------------------------------------------------------------------ helpers
def _normalise_shapes(V: np.ndarray) -> np.ndarray:
    """Scale each column to unit max modulus, its largest component real and positive."""
    if V.size == 0:
        return V.astype(complex)
    k = np.argmax(np.abs(V), axis=0)
    piv = V[k, np.arange(V.shape[1])]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = V / np.where(piv == 0, 1.0, piv)
    return out


def _mac_matrix(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """MAC between the columns of A and B (complex), as an (n_a, n_b) array."""
    num = np.abs(A.conj().T @ B) ** 2
    den = np.real(np.einsum("ij,ij->j", A.conj(), A))[:, None] * np.real(np.einsum("ij,ij->j", B.conj(), B))[None]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / den, 0.0)


# ------------------------------------------------------------------------------------------------ estimator
class SSICov:
    """Covariance-driven stochastic subspace identification with an automatic stabilisation diagram.

    Parameters
    ----------
    dt : float
        Sampling interval (s).
    block_rows : int or float
        Number of block rows ``i`` of the Toeplitz matrix (an int; correlation lags ``1 .. 2i - 1``, in units of
        ``lag_step`` samples, are used), or the lag span ``i dt lag_step`` in seconds (a float, rounded). A rule of
        thumb is ``i >= fs / (2 f_min lag_step)`` for the lowest frequency of interest ``f_min``. The SVD costs
        O(p r^2 i^3), independent of the record length: use ``lag_step`` or fewer ``ref_channels`` on heavily
        oversampled or many-channel records.
    orders : iterable of int
        Model orders of the stabilisation diagram (each in ``1 .. min(block_rows * n_ref, (block_rows - 1) * p)``),
        sorted and de-duplicated.
        Stability is judged against the next lower order in this list.
    ref_channels : sequence of int, optional
        Indices of the reference channels (default: all channels). Fewer references make ``T`` smaller
        (``p i x r i``) and the SVD cheaper; choose channels where every mode of interest is visible.
    freq_tol : float
        Stability: largest relative frequency change against the lower order (default 1 %).
    damping_tol : float
        Stability: largest relative damping change (default 5 %).
    min_mac : float
        Stability: smallest MAC with the matched pole of the lower order (default 0.98).
    max_damping : float
        Poles with damping ratio outside ``[harmonic_damping, max_damping)`` are never stable (default 20 %).
    cluster_distance : float
        Largest average-linkage distance ``|f_a - f_b| / max(f_a, f_b) + 1 - MAC`` inside one cluster of stable
        poles (default 0.05).
    min_stable : int or float
        Smallest number of orders at which a cluster must hold a stable pole to count as a mode: an int, or a
        fraction of ``len(orders)`` (default 0.25).
    freq_range_hz : (float, float), optional
        Report only modes whose frequency lies in ``[low, high]`` (Hz), e.g. the pass band of a band-pass filter.
    harmonic_damping : float
        Poles with ``|zeta|`` below this (default 0.2 %) whose frequency and shape are stable are forced harmonics
        (rotor 3P: a sharp, undamped line), reported in :attr:`harmonics_`, not as modes. Damping alone cannot tell
        an extremely lightly damped mode from a harmonic; :func:`estimators.hankel_dmd.harmonic_candidates` also
        checks phase locking.
    lag_step : int
        Use the correlations at lags that are multiples of ``lag_step`` samples only: the identification then runs
        at the interval ``dt * lag_step`` (like decimating by ``lag_step``) while every sample still enters the
        correlation estimates. For heavily oversampled records (the seed paper's 80 Hz for modes below 5 Hz):
        ``lag_step = 4`` makes the block Toeplitz matrix 4 times shorter for the same lag span. Frequencies above
        ``1 / (2 dt lag_step)`` alias, so band-limit the data below that first. Default 1.
    missing : {"raise", "split"}
        NaN in the data: ``"raise"`` a ``ValueError`` naming channels and samples; ``"split"`` the record at every
        sample with a NaN and use the finite pieces as separate records (pieces shorter than
        ``lag_step * (2 block_rows - 1) + 1`` samples are dropped; ``n_records_`` and ``n_dropped_samples_`` say
        what happened).
    demean : bool
        Subtract each record's (piece's) channel means before correlating (default True).

    Attributes
    ----------
    frequencies_hz_ : ndarray (n_modes,)
        Damped natural frequencies of the selected modes (Hz; cluster medians), ascending, all positive.
    damping_ratios_ : ndarray (n_modes,)
        Damping ratios (-; cluster medians).
    modes_ : ndarray (p, n_modes) complex
        Mode shapes ``C psi`` of the pole of each cluster nearest its medians, scaled to unit max modulus with the
        largest component real and positive (units of the channels, relative).
    poles_ : ndarray (n_modes,) complex
        Continuous-time poles (1/s) rebuilt from the medians: ``-zeta w_n + i 2 pi f`` with ``w_n = 2 pi f /
        sqrt(1 - zeta^2)``.
    n_stable_ : ndarray (n_modes,) of int
        Number of orders at which each mode has a stable pole.
    min_stable_ : int
        Orders at which a cluster of stable poles had to hold one to count as a mode (``min_stable`` resolved).
    harmonics_ : list of dict
        Forced harmonic lines, ascending in frequency: ``frequency_hz``, ``damping_ratio`` (medians; near zero),
        ``n_stable`` (orders at which the line is present), ``shape`` (``p`` complex, normalised),
        ``frequency_iqr_hz`` and ``damping_iqr``.
    stabilization_ : list of dict
        One dict per order (ascending): ``order``; ``frequencies_hz``, ``damping_ratios``, ``poles`` (complex,
        1/s), ``modes`` (``p x k`` complex, normalised) of its ``k`` positive-frequency poles; boolean arrays
        ``stable_frequency``, ``stable_damping``, ``stable_mode`` (each criterion against the lower order;
        all False at the lowest order), ``stable`` (all three and ``harmonic_damping <= zeta < max_damping``) and
        ``harmonic`` (frequency and shape stable, ``|zeta| < harmonic_damping``); ``mode`` (index into
        :attr:`frequencies_hz_` of the selected mode a stable pole belongs to, -1 otherwise) and ``line`` (index
        into :attr:`harmonics_` of the harmonic line a pole belongs to, -1 otherwise). A stable pole with
        ``mode == -1`` passed the criteria against the lower order but belongs to no mode (its cluster holds
        stable poles at fewer than ``min_stable`` orders, or lies outside ``freq_range_hz``). Plot e.g.
        ``ax.plot(row["frequencies_hz"][row["mode"] >= 0], [row["order"]] * (row["mode"] >= 0).sum(), "k.")``.
    singular_values_ : ndarray (min(p, r) * i,)
        Singular values of the block Toeplitz matrix (a gap suggests the model order).
    correlations_ : ndarray (2 i, p, r)
        Estimated output correlations ``R_l`` for lags ``0 .. 2i - 1`` (channel units squared).
    block_rows_ : int
    orders_ : ndarray of int
    ref_channels_ : ndarray of int
    dt_ : float
    n_features_in_ : int
        Number of channels ``p``.
    n_samples_ : int
        Samples used (all records).
    n_records_ : int
    n_dropped_samples_ : int
        Samples not used because of NaN (``missing="split"``).

    Raises
    ------
    ValueError
        From :meth:`fit`: NaN/inf (channels and samples listed), a record shorter than the largest lag
        ``lag_step * (2 block_rows - 1) + 1``, an order larger than ``block_rows * n_ref`` or ``(block_rows - 1) * p``,
        constant channels, bad reference channels or tolerances.

    Notes
    -----
    SSI-COV assumes stationary white-noise excitation. A forced harmonic (rotor 1P/3P) appears as an undamped pole
    with a stable frequency and shape; it is reported in :attr:`harmonics_`. Coloured excitation (a broad wave or
    turbulence spectrum, the band-pass filter's own poles) can give heavily damped stable poles that are no
    structural mode: judge them by ``damping_ratio`` and ``n_stable``. Channels of different units should be
    standardised first (:func:`estimators.preprocess.preprocess`) or the SVD weighs them by their units.

    Examples
    --------
    Two modes (0.5 Hz, 2 %; 1.3 Hz, 1 %) driven by white noise, seen by three sensors:

    >>> import numpy as np
    >>> from scipy import signal
    >>> dt, rng = 0.05, np.random.default_rng(0)
    >>> n = 20000
    >>> q = []
    >>> for f, z in [(0.5, 0.02), (1.3, 0.01)]:
    ...     w = 2 * np.pi * f
    ...     b, a = signal.cont2discrete(([1.0], [1.0, 2 * z * w, w * w]), dt, method="impulse")[:2]
    ...     q.append(signal.lfilter(np.ravel(b), a, rng.standard_normal(n)))
    >>> Y = np.c_[q[0], q[1]] @ np.array([[1.0, 0.5, -0.8], [0.4, -1.0, 0.9]]) * 1e3
    >>> ssi = SSICov(dt, block_rows=30, orders=range(2, 31, 2)).fit(Y)
    >>> [f"{f:.2f} Hz" for f in ssi.frequencies_hz_]
    ['0.50 Hz', '1.30 Hz']
    >>> [row["kind"] for row in ssi.mode_table()]
    ['structural', 'structural']
    """

    def __init__(
        self,
        dt: float,
        block_rows: int | float = 60,
        orders: Iterable[int] = range(2, 81, 2),
        ref_channels: Iterable[int] | None = None,
        *,
        freq_tol: float = 0.01,
        damping_tol: float = 0.05,
        min_mac: float = 0.98,
        max_damping: float = 0.2,
        cluster_distance: float = 0.05,
        min_stable: int | float = 0.25,
        freq_range_hz: tuple[float, float] | None = None,
        harmonic_damping: float = 0.002,
        lag_step: int = 1,
        missing: str = "raise",
        demean: bool = True,
    ) -> None:
        self.dt = dt
        self.block_rows = block_rows
        self.orders = orders
        self.ref_channels = ref_channels
        self.freq_tol = freq_tol
        self.damping_tol = damping_tol
        self.min_mac = min_mac
        self.max_damping = max_damping
        self.cluster_distance = cluster_distance
        self.min_stable = min_stable
        self.freq_range_hz = freq_range_hz
        self.harmonic_damping = harmonic_damping
        self.lag_step = lag_step
        self.missing = missing
        self.demean = demean

    # ------------------------------------------------------------------------------------------ arguments
    def _resolve_block_rows(self, dt: float) -> int:
        i = self.block_rows
        if isinstance(i, bool):
            raise ValueError(f"block_rows must be an int (block rows) or a float (seconds), got {i!r}")
        if isinstance(i, Integral):
            return check_int("block_rows", i, minimum=2)
        if isinstance(i, Real):
            secs = check_number("block_rows (seconds)", i, positive=True)
            n = int(round(secs / dt))
            if n < 2:
                raise ValueError(f"block_rows = {secs} s is less than two block rows at dt * lag_step = {dt} s")
            return n
        raise ValueError(f"block_rows must be an int (block rows) or a float (seconds), got {i!r}")

    def _resolve_refs(self, p: int) -> np.ndarray:
        if self.ref_channels is None:
            return np.arange(p)
        if isinstance(self.ref_channels, (str, bytes)):
            raise ValueError(f"ref_channels must be a sequence of channel indices, got {self.ref_channels!r}")
        try:
            refs = list(self.ref_channels)
        except TypeError as exc:
            raise ValueError(f"ref_channels must be a sequence of channel indices, got {self.ref_channels!r}") from exc
        if not refs:
            raise ValueError("ref_channels must list at least one channel (or be None for all channels)")
        out = [check_int(f"ref_channels[{k}]", c, minimum=0, maximum=p - 1) for k, c in enumerate(refs)]
        if len(set(out)) != len(out):
            raise ValueError(f"ref_channels must not repeat a channel, got {out}")
        return np.array(out, dtype=int)

    def _resolve_orders(self, i: int, n_ref: int, p: int) -> np.ndarray:
        if isinstance(self.orders, Integral) and not isinstance(self.orders, bool):
            orders = [check_int("orders", self.orders, minimum=1)]
        elif isinstance(self.orders, (str, bytes)) or not isinstance(self.orders, Iterable):
            raise ValueError(f"orders must be an iterable of positive ints, got {self.orders!r}")
        else:
            orders = [check_int(f"orders[{k}]", n, minimum=1) for k, n in enumerate(self.orders)]
        if not orders:
            raise ValueError("orders must list at least one model order")
        orders = np.unique(orders)
        if orders[-1] > i * n_ref:
            raise ValueError(
                f"orders go up to {int(orders[-1])}, but block_rows * n_ref = {i} * {n_ref} = {i * n_ref} is the "
                f"largest possible order (the rank of the {n_ref * i}-column block Toeplitz matrix); raise "
                "block_rows or lower the orders"
            )
        if orders[-1] > (i - 1) * p:
            raise ValueError(
                f"orders go up to {int(orders[-1])}, but (block_rows - 1) * p = {(i - 1) * p} is the largest order "
                "the shift equation of the observability matrix can determine; raise block_rows or lower the orders"
            )
        return orders

    def _check_tolerances(self) -> dict[str, float]:
        tol = {
            "freq_tol": check_number("freq_tol", self.freq_tol, positive=True),
            "damping_tol": check_number("damping_tol", self.damping_tol, positive=True),
            "min_mac": check_number("min_mac", self.min_mac, nonneg=True),
            "max_damping": check_number("max_damping", self.max_damping, positive=True),
            "cluster_distance": check_number("cluster_distance", self.cluster_distance, positive=True),
            "harmonic_damping": check_number("harmonic_damping", self.harmonic_damping, nonneg=True),
        }
        if tol["min_mac"] > 1:
            raise ValueError(f"min_mac must be in [0, 1], got {self.min_mac!r}")
        return tol

    def _min_stable(self, n_orders: int) -> int:
        m = self.min_stable
        if isinstance(m, Integral) and not isinstance(m, bool):
            return check_int("min_stable", m, minimum=1)
        if isinstance(m, Real) and not isinstance(m, bool):
            frac = check_number("min_stable (fraction of the orders)", m, low=0.0)
            if frac > 1:
                raise ValueError(f"min_stable as a fraction of the orders must be in (0, 1], got {m!r}")
            return max(1, math.ceil(frac * n_orders))
        raise ValueError(f"min_stable must be an int or a fraction in (0, 1], got {m!r}")

    def _freq_range(self) -> tuple[float, float]:
        if self.freq_range_hz is None:
            return 0.0, math.inf
        fr = self.freq_range_hz
        if not isinstance(fr, (tuple, list)) or len(fr) != 2:
            raise ValueError(f"freq_range_hz must be a pair (low_hz, high_hz), got {fr!r}")
        lo = check_number("freq_range_hz[0]", fr[0], nonneg=True)
        hi = check_number("freq_range_hz[1]", fr[1], positive=True)
        if not lo < hi:
            raise ValueError(f"freq_range_hz must have low < high, got {fr!r}")
        return lo, hi

    def _records(self, Y: object, i: int, step: int) -> tuple[list[np.ndarray], int]:
        if self.missing not in ("raise", "split"):
            raise ValueError(f"missing must be 'raise' or 'split', got {self.missing!r}")
        split = self.missing == "split"
        records = as_records(Y, "Y", allow_nan=split, min_samples=1, max_abs=MAX_ABS)
        need = step * (2 * i - 1) + 1  # the largest lag plus one
        dropped = 0
        if split:
            pieces, dropped = split_at_nonfinite(records, need)
            if not pieces:
                raise ValueError(
                    f"Y has no finite stretch of at least {need} samples (lag_step * (2 block_rows - 1) + 1; "
                    "missing='split' dropped all)"
                )
            records = pieces
        for k, rec in enumerate(records):
            if rec.shape[0] < need:
                name = "Y" if len(records) == 1 else f"Y[{k}]"
                raise ValueError(
                    f"{name} has {rec.shape[0]} samples; block_rows = {i} (lag_step = {step}) needs at "
                    f"least lag_step * (2 block_rows - 1) + 1 = {need} (the largest lag plus one), and many times "
                    "more for usable correlation estimates"
                )
        const = constant_channels_across(records)
        if const.size:
            raise ValueError(
                f"Y has constant channel(s) {const.tolist()}: they carry no dynamics and make the correlation "
                "matrices singular (a dead or saturated sensor?); remove them before fitting"
            )
        return records, dropped

    # ------------------------------------------------------------------------------------------------ fit
    def fit(self, Y: object) -> SSICov:
        """Identify modes from one record or a list of records.

        Parameters
        ----------
        Y : array_like (n_samples, p) or list of such arrays
            Time-major output-only data (any units; standardise mixed units first). Records in a list are
            correlated separately and their lagged-product sums pooled: no product spans two records.

        Returns
        -------
        self
        """
        dt_raw = check_number("dt", self.dt, positive=True)
        step = check_int("lag_step", self.lag_step, minimum=1)
        dt = dt_raw * step  # sampling interval of the identified model
        i = self._resolve_block_rows(dt)
        tol = self._check_tolerances()
        f_lo, f_hi = self._freq_range()
        max_lag = step * (2 * i - 1)  # lags 0, step, ..., step (2i - 1) are used
        records, dropped = self._records(Y, i, step)
        p = records[0].shape[1]
        refs = self._resolve_refs(p)
        r = refs.size
        orders = self._resolve_orders(i, r, p)
        min_stable = self._min_stable(orders.size)

        # 1. correlations R_l, l = 0 .. 2i - 1 (in steps of lag_step samples), pooled over records
        S = np.zeros((2 * i, p, r))
        counts = np.zeros(2 * i)
        lags = step * np.arange(2 * i)
        for y in records:
            if self.demean:
                y = y - y.mean(axis=0)
            S += correlation_sums(y, y[:, refs], max_lag)[lags]
            counts += y.shape[0] - lags
        R = S / counts[:, None, None]

        # 2. block Toeplitz: block (a, b) = R_{i + a - b}
        a = np.arange(i)
        T = R[i + a[:, None] - a[None, :]].transpose(0, 2, 1, 3).reshape(p * i, r * i)
        if not np.isfinite(T).all():
            raise ValueError("the output correlations are not finite (overflow: rescale Y)")

        # 3. SVD and shift structure, one QR for all orders
        try:
            U, s, _ = sla.svd(T, full_matrices=False, check_finite=False)
        except (np.linalg.LinAlgError, ValueError):  # pragma: no cover - gesdd failure, retry with gesvd
            U, s, _ = sla.svd(T, full_matrices=False, check_finite=False, lapack_driver="gesvd")
        if s[0] <= 0:
            raise ValueError("the block Toeplitz matrix of Y is zero (no correlated output)")
        n_max = int(orders[-1])
        n_num = int(np.count_nonzero(s > s[0] * max(T.shape) * np.finfo(float).eps))
        O = U[:, :n_max] * np.sqrt(s[:n_max])
        Q, Rq = np.linalg.qr(O[:-p])
        M = Q.T @ O[p:]

        rows = []
        for n in orders:
            n = int(n)
            if n > n_num:  # beyond the numerical rank: the shift equation is singular
                rows.append(self._empty_row(n, p))
                continue
            A = sla.solve_triangular(Rq[:n, :n], M[:n, :n], check_finite=False)
            if not np.isfinite(A).all():  # rank-deficient shift equation at this order
                rows.append(self._empty_row(n, p))
                continue
            mu, psi = np.linalg.eig(A)
            with np.errstate(divide="ignore", invalid="ignore"):
                lam = np.log(mu.astype(complex)) / dt
            # positive-frequency member of each complex pair (real eigenvalues do not oscillate)
            keep = np.isfinite(lam) & (mu.imag > 1e-12 * np.abs(mu))
            lam = lam[keep]
            shapes = _normalise_shapes(O[:p, :n] @ psi[:, keep])
            order = np.argsort(lam.imag)
            lam, shapes = lam[order], shapes[:, order]
            rows.append(
                {
                    "order": n,
                    "poles": lam,
                    "frequencies_hz": lam.imag / (2 * np.pi),
                    "damping_ratios": -lam.real / np.abs(lam),
                    "modes": shapes,
                }
            )
        self._stability(rows, tol)
        modes = self._cluster(rows, "stable", tol["cluster_distance"], min_stable, (f_lo, f_hi))
        harmonics = self._cluster(rows, "harmonic", tol["cluster_distance"], min_stable, (f_lo, f_hi))
        for idx, m in enumerate(modes):
            for k, j in m.pop("members"):
                rows[k]["mode"][j] = idx
        for idx, h in enumerate(harmonics):
            for k, j in h.pop("members"):
                rows[k]["line"][j] = idx

        self.dt_ = dt_raw
        self.lag_step_ = step
        self.block_rows_ = i
        self.orders_ = orders
        self.ref_channels_ = refs
        self.n_features_in_ = p
        self.n_samples_ = int(sum(y.shape[0] for y in records))
        self.n_records_ = len(records)
        self.n_dropped_samples_ = dropped
        self.correlations_ = R
        self.singular_values_ = s
        self.stabilization_ = rows
        self.frequencies_hz_ = np.array([m["frequency_hz"] for m in modes])
        self.damping_ratios_ = np.array([m["damping_ratio"] for m in modes])
        self.n_stable_ = np.array([m["n_stable"] for m in modes], dtype=int)
        self.min_stable_ = int(min_stable)
        self.modes_ = np.stack([m["shape"] for m in modes], axis=1) if modes else np.zeros((p, 0), complex)
        wd = 2 * np.pi * self.frequencies_hz_
        z = self.damping_ratios_
        self.poles_ = -z * wd / np.sqrt(1 - z**2) + 1j * wd
        self._spread = [(m["frequency_iqr_hz"], m["damping_iqr"]) for m in modes]
        self.harmonics_ = [
            {k: h[k] for k in ("frequency_hz", "damping_ratio", "n_stable", "shape", "frequency_iqr_hz", "damping_iqr")}
            for h in harmonics
        ]
        return self

    @staticmethod
    def _empty_row(n: int, p: int) -> dict:
        return {
            "order": n,
            "poles": np.zeros(0, complex),
            "frequencies_hz": np.zeros(0),
            "damping_ratios": np.zeros(0),
            "modes": np.zeros((p, 0), complex),
        }

    @staticmethod
    def _stability(rows: list[dict], tol: dict[str, float]) -> None:
        """Add the stability flags to each order's row (in place), against the next lower order."""
        prev = None
        for row in rows:
            f, z, V = row["frequencies_hz"], row["damping_ratios"], row["modes"]
            k = f.size
            sf = np.zeros(k, bool)
            sd = np.zeros(k, bool)
            sm = np.zeros(k, bool)
            if prev is not None and k and prev["frequencies_hz"].size:
                fp, zp = prev["frequencies_hz"], prev["damping_ratios"]
                df = np.abs(f[:, None] - fp[None, :]) / fp[None, :]
                mac = _mac_matrix(V, prev["modes"])
                j = np.argmin(df + (1.0 - mac), axis=1)  # nearest pole of the lower order
                idx = np.arange(k)
                sf = df[idx, j] < tol["freq_tol"]
                with np.errstate(divide="ignore", invalid="ignore"):
                    sd = np.abs(z - zp[j]) < tol["damping_tol"] * np.abs(zp[j])
                sm = mac[idx, j] > tol["min_mac"]
            structural = (z >= tol["harmonic_damping"]) & (z < tol["max_damping"])
            row["stable_frequency"] = sf
            row["stable_damping"] = sd
            row["stable_mode"] = sm
            row["stable"] = sf & sd & sm & structural
            row["harmonic"] = sf & sm & (np.abs(z) < tol["harmonic_damping"])
            row["mode"] = np.full(k, -1, dtype=int)
            row["line"] = np.full(k, -1, dtype=int)
            prev = row

    @staticmethod
    def _cluster(
        rows: list[dict], flag: str, distance: float, min_stable: int, band: tuple[float, float]
    ) -> list[dict]:
        """Cluster the flagged poles of all orders; one mode per cluster with such poles at >= min_stable orders."""
        where = [(k, j) for k, row in enumerate(rows) for j in np.flatnonzero(row[flag])]
        if len(where) < max(1, min_stable):
            return []
        f = np.array([rows[k]["frequencies_hz"][j] for k, j in where])
        z = np.array([rows[k]["damping_ratios"][j] for k, j in where])
        V = np.stack([rows[k]["modes"][:, j] for k, j in where], axis=1)
        order_of = np.array([rows[k]["order"] for k, _ in where])
        if f.size == 1:
            labels = np.ones(1, dtype=int)
        else:
            D = np.abs(f[:, None] - f[None, :]) / np.maximum(f[:, None], f[None, :]) + (1.0 - _mac_matrix(V, V))
            D = np.clip((D + D.T) / 2, 0.0, None)
            np.fill_diagonal(D, 0.0)
            tri = D[np.triu_indices(f.size, 1)]
            labels = fcluster(linkage(tri, method="average"), t=distance, criterion="distance")
        modes = []
        for lab in np.unique(labels):
            members = np.flatnonzero(labels == lab)
            # one pole per order: the one nearest the cluster's median frequency
            fmed = np.median(f[members])
            chosen = []
            for n in np.unique(order_of[members]):
                at = members[order_of[members] == n]
                chosen.append(at[np.argmin(np.abs(f[at] - fmed))])
            chosen = np.array(chosen)
            if chosen.size < min_stable:
                continue
            fm, zm = float(np.median(f[chosen])), float(np.median(z[chosen]))
            if not band[0] <= fm <= band[1]:
                continue
            rep = chosen[np.argmin(np.abs(f[chosen] - fm) / fm + np.abs(z[chosen] - zm) / max(abs(zm), 1e-6))]
            q25f, q75f = np.percentile(f[chosen], [25, 75])
            q25z, q75z = np.percentile(z[chosen], [25, 75])
            modes.append(
                {
                    "frequency_hz": fm,
                    "damping_ratio": zm,
                    "n_stable": int(chosen.size),
                    "shape": V[:, rep],
                    "frequency_iqr_hz": float(q75f - q25f),
                    "damping_iqr": float(q75z - q25z),
                    "members": [where[c] for c in chosen],
                }
            )
        modes.sort(key=lambda m: m["frequency_hz"])
        return modes

    # ------------------------------------------------------------------------------------------- mode table
    def mode_table(self) -> list[dict]:
        """One row per selected mode and per forced harmonic line, sorted by frequency.

        Returns
        -------
        list of dict
            Keys ``index`` (column of :attr:`modes_`; ``None`` for a harmonic, see :attr:`harmonics_`),
            ``frequency_hz``, ``damping_ratio`` (cluster medians), ``n_stable`` (orders with a stable pole in the
            cluster), ``n_orders`` (orders in the diagram), ``frequency_iqr_hz`` and ``damping_iqr``
            (interquartile ranges over the cluster: the scatter over model orders, not a confidence interval) and
            ``kind``: ``"structural"`` or ``"harmonic"`` (an undamped forced line such as rotor 3P).
        """
        check_fitted(self, "frequencies_hz_")
        n_orders = int(self.orders_.size)
        out = [
            {
                "index": k,
                "frequency_hz": float(f),
                "damping_ratio": float(z),
                "n_stable": int(self.n_stable_[k]),
                "n_orders": n_orders,
                "frequency_iqr_hz": self._spread[k][0],
                "damping_iqr": self._spread[k][1],
                "kind": "structural",
            }
            for k, (f, z) in enumerate(zip(self.frequencies_hz_, self.damping_ratios_, strict=True))
        ]
        for h in self.harmonics_:
            out.append(
                {
                    "index": None,
                    "frequency_hz": float(h["frequency_hz"]),
                    "damping_ratio": float(h["damping_ratio"]),
                    "n_stable": int(h["n_stable"]),
                    "n_orders": n_orders,
                    "frequency_iqr_hz": float(h["frequency_iqr_hz"]),
                    "damping_iqr": float(h["damping_iqr"]),
                    "kind": "harmonic",
                }
            )
        out.sort(key=lambda row: row["frequency_hz"])
        return out
