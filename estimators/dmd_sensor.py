"""``HankelDMDSensor``: the seed paper's rolling-horizon Hankel-DMD virtual sensor, causal and streaming.

Offline, a :class:`~estimators.hankel_dmd.HankelDMD` model (eigenvalues ``mu`` and delay-embedded modes
``Phi``, ``p d x r``) is identified on z-scored training records. Online (seed paper, Section 2.4 and its
Algorithm 1), the sensor alternates calibration and prediction:

* **calibrate** every ``update_interval`` seconds: the modal amplitudes ``b`` are the least-squares fit of
  ``Phi`` to the delay window of the **past** ``d`` samples (oldest first, ending with the current one), using
  only the rows of ``Phi`` that belong to live (channel, sample) entries of the window -- the paper's sparse
  basis ``Phi_sparse = S Phi``;
* **predict** until the next calibration: ``y_hat[k + j] = Re(Phi_last diag(mu^j) b)`` with ``Phi_last`` the
  newest delay block of the modes.

The paper calibrates on the window that *starts* at the current sample, i.e. on the next ``d`` samples: that
look-ahead needs the future and is available here only as the explicitly named offline smoother
``causal=False`` (:meth:`HankelDMDSensor.reconstruct` only).

The least-squares problem is regularised towards the amplitudes propagated from the previous calibration,
``min ||Phi_S b - h_S||^2 + lambda ||b - b_pred||^2``, with ``lambda`` a fixed fraction (``ridge``) of the
mean eigenvalue of the full-window normal matrix, so a well-observed window is fitted by its data and a window
with few live channels (or with the sensors just coming back) stays close to the prediction instead of blowing
up. The factorisation of each window pattern is cached, so a changed mask costs one ``r x r`` solve (milliseconds)
once, and nothing afterwards. When the whole window is lost the sensor propagates open-loop (``open_loop`` is
True and ``n_open_loop_`` counts the samples), with eigenvalues outside the unit circle pulled onto it so the
prediction cannot diverge.

Signals in and out are in physical units; inside, each channel is centred and scaled with its training mean
and standard deviation. There is no band-pass: a causal filter would delay the estimate, and the slow platform
motion is part of what a fatigue engineer needs back.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
import scipy.linalg as sla

from .hankel_dmd import HankelDMD
from .screening import FaultScreen, make_screen
from .validation import MAX_ABS, apply_masks, as_2d_float, as_records, as_sample, check_fitted, check_number

__all__ = ["HankelDMDSensor"]

_CACHE_SIZE = 128  # window patterns whose factorisation is kept
_GATE_ITERATIONS = 6  # refits of the trimmed least squares per calibration
_MIN_RESIDUAL = 1e-3  # floor of the gate's residual scale (z-score units: 0.1 % of a channel's std)


class HankelDMDSensor:
    """Virtual sensor: rolling-horizon Hankel-DMD reconstruction of lost channels from the live ones.

    Follows the virtual-sensor protocol of :mod:`estimators.baseline`: :meth:`fit`, :meth:`reset`,
    :meth:`update` (one sample), :meth:`reconstruct` (a whole record, identical to streaming).

    Parameters
    ----------
    delays : int or float
        Delay depth ``d``: samples (int) or seconds (float). Default 60 samples (0.75 s at 80 Hz).
    rank : int, float or "auto"
        DMD truncation rank (see :class:`~estimators.hankel_dmd.HankelDMD`). Default 90, the seed paper's
        extended basis.
    update_interval : float
        Time between calibrations (s); rounded to whole samples (at least one). May be changed after
        :meth:`fit` (it takes effect at the next :meth:`reset`, which :meth:`reconstruct` calls): a sweep over
        intervals needs one fit.
    dt : float
        Sample interval (s).
    causal : bool
        ``True`` (default): calibrate on the past window; streaming with :meth:`update`. ``False``: the seed
        paper's look-ahead variant, an offline smoother that calibrates on the *next* ``d`` samples; only
        :meth:`reconstruct` runs it.
    ridge : float
        Regularisation towards the propagated amplitudes, as a fraction of the mean eigenvalue of the normal
        matrix of a fully live window (-).
    gate_sigma : float or None
        Spike and stuck-sensor gate, in units of each channel's training residual (:attr:`residual_std_`).
        Each calibration is a trimmed least-squares fit: window entries whose residual exceeds the gate are
        left out and the window fitted again, re-admitting entries the new fit explains, until the kept set is
        stable (at most six refits). A channel that reads exactly the same value throughout the window is
        flat-lined (stuck) and left out as well. The gate never removes more than half of a window's live
        entries (then the model, not the data, is off, and the untrimmed fit is used), and its residual scale is
        at least 0.1 % of the channel's standard deviation. ``None`` switches the gate off.
    passthrough : bool
        Return live channels as measured (default) rather than as the model reconstructs them. The model's
        value of a live channel jumps a little at each calibration; the measurement does not (but a spike or a
        stuck value on a live channel then passes through: the gate protects only the lost channels).
    method : str
        Solver of the offline DMD (``"auto"``, ``"dense"``, ``"gram"``, ``"randomized"``).
    screen : bool or FaultScreen
        Fault screening of live channels (:class:`estimators.screening.FaultScreen`, shared by every sensor): a
        flat-lined (stuck), spiking or out-of-range channel that still reports live is treated as lost at that
        sample (estimated, not passed through) and reported in :attr:`rejected_`. True (default): default
        settings; False: off; a ``FaultScreen``: its settings.

    Attributes
    ----------
    dmd_ : HankelDMD
        The identified model (on z-scored data).
    mean_, scale_ : ndarray (n_channels,)
        Training mean and standard deviation of each channel (channel units).
    residual_std_ : ndarray (n_channels,)
        RMS of the one-window reconstruction residual of each channel on the training data (z-score units).
    n_channels_ : int
    delays_ : int
    update_samples_ : int
        Samples between calibrations (set by :meth:`reset`).
    n_open_loop_ : int
        Samples of the last stream estimated with no live data in the window (pure prediction).
    n_calibrations_ : int
        Calibrations in the last stream.
    n_gated_ : int
        Window entries rejected by the gate in the last stream, summed over calibrations (an entry stays in the
        window for ``delays`` samples, so one spike may be counted at several calibrations).
    cache_info_ : dict
        ``hits``, ``misses`` and ``size`` of the window-pattern cache.
    screen_ : FaultScreen
        The fitted fault screen; its ``counts_`` say why channels were rejected.
    rejected_ : ndarray of bool (n_channels,)
        Live channels rejected by the screen at the latest sample.
    rejected_samples_ : ndarray of bool (n_samples, n_channels)
        After :meth:`reconstruct`: :attr:`rejected_` of every sample.

    Examples
    --------
    >>> import numpy as np
    >>> dt = 0.0125
    >>> t = np.arange(8000) * dt
    >>> rng = np.random.default_rng(0)
    >>> q = np.c_[np.sin(2 * np.pi * 0.5 * t), np.sin(2 * np.pi * 1.7 * t + 1.0)]
    >>> Y = q @ np.array([[1.0, 0.5, -0.3], [0.2, -1.0, 0.8]]) + 0.01 * rng.standard_normal((8000, 3))
    >>> sensor = HankelDMDSensor(delays=40, rank=4, update_interval=1.0, dt=dt).fit(Y[:6000])
    >>> mask = np.array([True, True, False])  # channel 2 lost
    >>> est = sensor.reconstruct(np.where(mask, Y[6000:], np.nan), mask)
    >>> bool(np.corrcoef(est[:, 2], Y[6000:, 2])[0, 1] > 0.99)
    True
    """

    def __init__(
        self,
        delays: int | float = 60,
        rank: int | float | str = 90,
        update_interval: float = 1.0,
        dt: float = 0.0125,
        causal: bool = True,
        *,
        ridge: float = 1e-5,
        gate_sigma: float | None = 8.0,
        passthrough: bool = True,
        method: str = "auto",
        screen: bool | FaultScreen = True,
    ) -> None:
        self.delays = delays
        self.rank = rank
        self.update_interval = update_interval
        self.dt = dt
        self.causal = causal
        self.ridge = ridge
        self.gate_sigma = gate_sigma
        self.passthrough = passthrough
        self.method = method
        self.screen = screen

    # ------------------------------------------------------------------------------------------------ fit
    def fit(self, Y: object, mask: object = None) -> HankelDMDSensor:
        """Identify the Hankel-DMD model on training records.

        Parameters
        ----------
        Y : array_like (n_samples, n_channels) or list of such records
            Training data in channel units; NaN marks missing samples.
        mask : array_like of bool or list of them, optional
            False marks further missing samples: one mask for all records or one per record, each of the
            record's shape or ``(n_channels,)`` (:func:`estimators.validation.apply_masks`).
            Records are split at missing samples (no Hankel column spans
            a gap).

        Returns
        -------
        self
        """
        dt = check_number("dt", self.dt, positive=True)
        check_number("update_interval", self.update_interval, positive=True)
        ridge = check_number("ridge", self.ridge, nonneg=True)
        if self.gate_sigma is not None:
            check_number("gate_sigma", self.gate_sigma, positive=True)
        if not isinstance(self.causal, (bool, np.bool_)):
            raise ValueError(f"causal must be True or False, got {self.causal!r}")
        records = apply_masks(as_records(Y, "Y", allow_nan=True, min_samples=2, max_abs=MAX_ABS), mask)
        self.screen_ = make_screen(self.screen, records)
        p = records[0].shape[1]
        finite = np.concatenate(records, axis=0)
        ok = np.isfinite(finite)
        counts = ok.sum(axis=0)
        if np.any(counts < 2):
            raise ValueError(f"channels {np.flatnonzero(counts < 2).tolist()} have fewer than 2 finite training "
                             "samples")
        mean = np.where(ok, finite, 0.0).sum(axis=0) / counts
        var = np.where(ok, (finite - mean) ** 2, 0.0).sum(axis=0) / counts
        scale = np.sqrt(var)
        if np.any(scale <= 1e-12 * np.maximum(np.abs(mean), 1.0)):
            raise ValueError(f"channels {np.flatnonzero(scale <= 1e-12 * np.maximum(np.abs(mean), 1.0)).tolist()} "
                             "are constant in the training data")
        Z = [(r - mean) / scale for r in records]
        dmd = HankelDMD(delays=self.delays, rank=self.rank, dt=dt, method=self.method, missing="split")
        dmd.fit(Z)
        d = dmd.delays_
        self.dmd_ = dmd
        self.dt_ = dt
        self.mean_, self.scale_ = mean, scale
        self.n_channels_ = p
        self.delays_ = d
        mu = dmd.eigenvalues_
        self._mu = mu
        self._mu_open = np.where(np.abs(mu) > 1.0, mu / np.abs(mu), mu)
        Phi = dmd.hankel_modes_
        self._phi = Phi
        self._phi_last = np.ascontiguousarray(Phi[(d - 1) * p :])
        self._phi_first = np.ascontiguousarray(Phi[:p])
        self.residual_std_ = self._training_residual(Z, d)
        self._rstd_rows = np.tile(np.maximum(self.residual_std_, _MIN_RESIDUAL), d)
        lam = ridge * float(np.real(np.einsum("ij,ij->", Phi.conj(), Phi))) / Phi.shape[1]
        self._lambda = lam
        self._psi, self._conv, self._ridge_c = _real_basis(Phi, mu, lam)
        self._cache: OrderedDict[bytes, tuple[np.ndarray, tuple]] = OrderedDict()
        self._hits = self._misses = 0
        self.reset()
        return self

    def _training_residual(self, Z: list[np.ndarray], d: int) -> np.ndarray:
        """RMS residual of the newest sample of each window after a full-window least-squares fit (z units)."""
        p = Z[0].shape[1]
        pinv = np.linalg.pinv(self._phi)
        sse, n = np.zeros(p), 0
        for z in Z:
            z = z[np.isfinite(z).all(axis=1)] if not np.isfinite(z).all() else z
            if z.shape[0] < d + 1:
                continue
            step = max(1, (z.shape[0] - d) // 400)  # a few hundred windows per record are plenty
            starts = np.arange(0, z.shape[0] - d + 1, step)
            H = np.stack([z[s : s + d].reshape(-1) for s in starts], axis=1)
            fit = (self._phi_last @ (pinv @ H)).real
            sse += np.sum((fit - H[(d - 1) * p :]) ** 2, axis=1)
            n += starts.size
        return np.sqrt(sse / max(n, 1))

    # ----------------------------------------------------------------------------------------- streaming
    def reset(self) -> None:
        """Start a new stream: empty window, zero amplitudes (the estimate is the training mean until data)."""
        check_fitted(self, "dmd_")
        interval = check_number("update_interval", self.update_interval, positive=True)
        self.update_samples_ = max(1, int(round(interval / self.dt_)))
        d, p = self.delays_, self.n_channels_
        self._zbuf = np.zeros((d, p))
        self._live = np.zeros((d, p), dtype=bool)
        self._pos = 0  # ring-buffer slot of the next sample
        self._k = 0  # samples seen
        self._b = np.zeros(self._mu.size, dtype=complex)  # amplitudes of the window ending at the current sample
        self._open = True
        self.n_open_loop_ = 0
        self.n_calibrations_ = 0
        self.n_gated_ = 0
        self.screen_.reset()

    @property
    def rejected_(self) -> np.ndarray:
        """Live channels rejected by the fault screen at the latest sample."""
        check_fitted(self, "dmd_")
        return self.screen_.rejected_.copy()

    @property
    def rejected_samples_(self) -> np.ndarray:
        """After :meth:`reconstruct`: the channels the fault screen rejected at every sample."""
        check_fitted(self, "dmd_")
        return getattr(self.screen_, "rejected_samples_", None)

    @property
    def open_loop(self) -> bool:
        """True if the last estimate was pure prediction (no live data in the last calibration window)."""
        return bool(getattr(self, "_open", True))

    @property
    def cache_info_(self) -> dict:
        return {"hits": self._hits, "misses": self._misses, "size": len(self._cache)}

    def _check_sample(self, y: object, mask: object) -> tuple[np.ndarray, np.ndarray]:
        y, m = as_sample(y, mask, self.n_channels_)
        live = np.isfinite(y) if m is None else m & np.isfinite(y)
        return y, live

    def _solver(self, live_rows: np.ndarray) -> tuple[np.ndarray, tuple]:
        """(rows, Cholesky factor of ``Psi_S^T Psi_S + D``) for a window pattern; cached by pattern."""
        key = np.packbits(live_rows).tobytes()
        hit = self._cache.get(key)
        if hit is not None:
            self._hits += 1
            self._cache.move_to_end(key)
            return hit
        self._misses += 1
        rows = np.flatnonzero(live_rows)
        A = self._psi[rows]
        G = A.T @ A
        G[np.diag_indices_from(G)] += self._ridge_c
        try:
            cho = sla.cho_factor(G, lower=True, check_finite=False)
        except np.linalg.LinAlgError:  # pragma: no cover - positive definite for ridge > 0
            cho = sla.cho_factor(G + np.eye(G.shape[0]) * 1e-12 * np.trace(G), lower=True, check_finite=False)
        entry = (rows, cho)
        self._cache[key] = entry
        if len(self._cache) > _CACHE_SIZE:
            self._cache.popitem(last=False)
        return entry

    def _solve(self, flat: np.ndarray, h_all: np.ndarray, c_pred: np.ndarray) -> np.ndarray:
        rows, cho = self._solver(flat)
        return sla.cho_solve(cho, self._psi[rows].T @ h_all[rows] + self._ridge_c * c_pred, check_finite=False)

    def _calibrate(self, window: np.ndarray, live: np.ndarray, b_pred: np.ndarray) -> tuple[np.ndarray, bool]:
        """Amplitudes fitted to a window (d, p) with its live flags; (b, open_loop)."""
        flat = live.reshape(-1)
        if not flat.any():
            return b_pred, True
        if self._lambda == 0.0 and flat.sum() < self._mu.size:
            # without regularisation an under-determined window would be fitted exactly and blow up
            raise ValueError("ridge = 0 and fewer live window entries than modes; use ridge > 0")
        h_all = window.reshape(-1)
        if self.gate_sigma is not None:
            # a channel that reads exactly the same value throughout the window is stuck (flat-lined), not live
            n_live = live.sum(axis=0)
            vals = np.where(live, window, np.nan)
            with np.errstate(invalid="ignore"):
                flatline = (n_live >= 2) & (np.nanmax(vals, axis=0, initial=-np.inf) == np.nanmin(vals, axis=0,
                                                                                              initial=np.inf))
            if flatline.any():
                self.n_gated_ += int(n_live[flatline].sum())
                live = live & ~flatline
                flat = live.reshape(-1)
                if not flat.any():
                    return b_pred, True
        c_pred = _b_to_c(b_pred, self._conv)
        c = self._solve(flat, h_all, c_pred)
        if self.gate_sigma is not None:
            # trimmed least squares: refit on the entries the current fit explains, re-admitting any that the
            # new fit explains again, until the set is stable
            live_rows = np.flatnonzero(flat)
            psi_live, h_live, rstd_live = self._psi[live_rows], h_all[live_rows], self._rstd_rows[live_rows]
            keep = np.ones(live_rows.size, dtype=bool)
            c_all = c
            for _ in range(_GATE_ITERATIONS):
                ok = np.abs(psi_live @ c - h_live) <= self.gate_sigma * rstd_live
                if np.array_equal(ok, keep):
                    break
                keep = ok
                if not keep.any():
                    break
                sel = np.zeros_like(flat)
                sel[live_rows[keep]] = True
                c = self._solve(sel, h_all, c_pred)
            if keep.sum() < 0.5 * keep.size:  # the gate never removes most of the window: the model is off
                keep[:] = True
                c = c_all
            self.n_gated_ += int((~keep).sum())
        b = _c_to_b(c, self._conv, self._mu.size)
        return b, False

    def update(self, y: object, mask: object = None) -> np.ndarray:
        """One sample in, the full channel vector out (causal).

        Parameters
        ----------
        y : array_like (n_channels,)
            The sample in channel units; ignored (NaN is fine) where ``mask`` is False. A NaN where ``mask`` is
            True is a dropout.
        mask : array_like of bool (n_channels,), optional
            True = channel available. Default: the finite entries of ``y``.

        Returns
        -------
        ndarray (n_channels,)
            Estimate of every channel at this sample (channel units).
        """
        check_fitted(self, "dmd_")
        if not self.causal:
            raise ValueError("causal=False is the look-ahead offline smoother; it needs the future and has no "
                             "update(): use reconstruct()")
        y, live = self._check_sample(y, mask)
        live = self.screen_.screen(np.where(live, y, np.nan), live)
        z = np.where(live, (np.where(live, y, 0.0) - self.mean_) / self.scale_, 0.0)
        self._zbuf[self._pos] = z
        self._live[self._pos] = live
        self._pos = (self._pos + 1) % self.delays_
        b_pred = self._b * (self._mu if not self._open else self._mu_open) if self._k > 0 else self._b
        if self._k % self.update_samples_ == 0:
            order = np.r_[self._pos : self.delays_, 0 : self._pos]  # oldest first
            self._b, self._open = self._calibrate(self._zbuf[order], self._live[order], b_pred)
            self.n_calibrations_ += 1
        else:
            self._b = b_pred
        if self._open:
            self.n_open_loop_ += 1
        self._k += 1
        est = (self._phi_last @ self._b).real * self.scale_ + self.mean_
        if self.passthrough:
            est[live] = y[live]
        return est

    # -------------------------------------------------------------------------------------------- batch
    def reconstruct(self, Y: object, mask: object = None) -> np.ndarray:
        """Reconstruct a whole record: the same numbers as :meth:`reset` then :meth:`update` per sample.

        With ``causal=False`` this is the look-ahead smoother of the seed paper: at every calibration the
        amplitudes are fitted to the window of the *next* ``d`` samples and propagated forward from its first
        sample.

        Parameters
        ----------
        Y : array_like (n_samples, n_channels)
            Record in channel units (NaN where missing).
        mask : array_like of bool (n_samples, n_channels) or (n_channels,), optional
            True = available (one row applies to every sample). Default: the finite entries of ``Y``.

        Returns
        -------
        ndarray (n_samples, n_channels)
        """
        check_fitted(self, "dmd_")
        self.reset()
        p, d, nu = self.n_channels_, self.delays_, self.update_samples_
        Y = as_2d_float(Y, "Y", allow_nan=True, n_channels=p)
        if np.isinf(Y).any():
            raise ValueError("Y must not hold ±inf (NaN marks missing samples)")
        live = np.isfinite(Y)
        if mask is not None:
            m = np.asarray(mask)
            if m.shape not in (Y.shape, (p,)):
                raise ValueError(f"mask must have the shape of Y {Y.shape} or ({p},), got {m.shape}")
            live &= m.astype(bool)
        live = self.screen_.screen_block(Y, live)
        n = Y.shape[0]
        Z = np.where(live, (np.where(live, Y, 0.0) - self.mean_) / self.scale_, 0.0)
        out = np.empty((n, p))
        b = self._b
        open_ = True
        n_open = 0
        for k0 in range(0, n, nu):
            k1 = min(n, k0 + nu)
            if self.causal:
                lo = k0 - d + 1
                window = np.zeros((d, p))
                wlive = np.zeros((d, p), dtype=bool)
                a = max(lo, 0)
                window[a - lo :] = Z[a : k0 + 1]
                wlive[a - lo :] = live[a : k0 + 1]
                mu_prev = self._mu_open if open_ else self._mu
                b_pred = b * mu_prev if k0 > 0 else b
                b, open_ = self._calibrate(window, wlive, b_pred)
                rows = self._phi_last
            else:
                hi = min(n, k0 + d)
                window = np.zeros((d, p))
                wlive = np.zeros((d, p), dtype=bool)
                window[: hi - k0] = Z[k0:hi]
                wlive[: hi - k0] = live[k0:hi]
                b_pred = b * (self._mu_open if open_ else self._mu) ** nu if k0 > 0 else b
                b, open_ = self._calibrate(window, wlive, b_pred)
                rows = self._phi_first
            mu = self._mu_open if open_ else self._mu
            j = np.arange(k1 - k0)
            powers = mu[None, :] ** j[:, None]
            out[k0:k1] = ((powers * b) @ rows.T).real
            if open_:
                n_open += k1 - k0
            if self.causal:
                b = b * mu ** (k1 - k0 - 1)  # amplitudes at the last sample of the block
            self.n_calibrations_ += 1
        self.n_open_loop_ = n_open
        self._open = open_
        out = out * self.scale_ + self.mean_
        if self.passthrough:
            out[live] = Y[live]
        return out



# ------------------------------------------------------------------------------------------- real basis
def _real_basis(Phi: np.ndarray, mu: np.ndarray, lam: float) -> tuple[np.ndarray, tuple, np.ndarray]:
    """Real basis ``Psi`` of the modes of real data, the index maps between ``b`` and ``c``, and the ridge.

    A real signal has conjugate amplitudes on conjugate modes, so ``Phi b = Psi c`` with real ``c``: a real mode
    contributes column ``Re(phi)`` with ``c = Re(b)``; a pair ``(phi, conj(phi))`` contributes ``Re(phi)`` and
    ``-Im(phi)`` with ``c = 2 (Re(b), Im(b))``. The ridge ``lam |b - b_pred|^2`` becomes ``sum D (c - c_pred)^2``
    with ``D = lam`` for a real mode and ``lam / 2`` for each column of a pair. Real arithmetic makes a new
    window pattern four times cheaper to factorise.
    """
    r = mu.size
    tol = 1e-9 * max(1.0, float(np.max(np.abs(mu))))
    assigned = np.zeros(r, dtype=bool)
    real_idx, first, second = [], [], []
    for j in range(r):
        if assigned[j]:
            continue
        assigned[j] = True
        if abs(mu[j].imag) <= tol:
            real_idx.append(j)
            continue
        cand = np.flatnonzero(~assigned)
        k = int(cand[np.argmin(np.abs(mu[cand] - np.conj(mu[j])))]) if cand.size else -1
        if k < 0 or abs(mu[k] - np.conj(mu[j])) > 1e-6 * max(1.0, abs(mu[j])):
            raise ValueError("the DMD eigenvalues are not in conjugate pairs (complex training data?)")
        assigned[k] = True
        first.append(j if mu[j].imag > 0 else k)
        second.append(k if mu[j].imag > 0 else j)
    real_idx, first, second = (np.asarray(v, dtype=int) for v in (real_idx, first, second))
    n_r, n_p = real_idx.size, first.size
    psi = np.concatenate([Phi[:, real_idx].real, Phi[:, first].real, -Phi[:, first].imag], axis=1)
    ridge = np.concatenate([np.full(n_r, lam), np.full(2 * n_p, lam / 2)])
    return np.ascontiguousarray(psi), (real_idx, first, second), ridge


def _b_to_c(b: np.ndarray, conv: tuple) -> np.ndarray:
    real_idx, first, _ = conv
    return np.concatenate([b[real_idx].real, 2.0 * b[first].real, 2.0 * b[first].imag])


def _c_to_b(c: np.ndarray, conv: tuple, r: int) -> np.ndarray:
    real_idx, first, second = conv
    n_r, n_p = real_idx.size, first.size
    b = np.empty(r, dtype=complex)
    b[real_idx] = c[:n_r]
    b[first] = 0.5 * (c[n_r : n_r + n_p] + 1j * c[n_r + n_p :])
    b[second] = np.conj(b[first])
    return b
