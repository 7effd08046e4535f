"""``KalmanSensor``: an augmented Kalman filter on a linear state-space model as a virtual sensor.

The sensor estimates every output channel of a continuous-time linear model ``x' = A x + B u``,
``y = C x + D u`` (a python-control ``StateSpace``, e.g. ``surrogates.FOWTModel.linearize(case, plane="FA")``)
from whichever channels are alive, following the virtual-sensor protocol of :mod:`estimators.baseline`.

The unknown loads (wave excitation, wind) are not measured, so they join the state (augmented Kalman filter,
Lourens et al. 2012, *Mech. Syst. Signal Process.* 27, 446-460) with a first-order Gauss-Markov (AR(1)) or a
random-walk model. The augmented continuous model is discretised exactly (matrix exponential; zero-order hold
on the known inputs; Van Loan's method for the process-noise covariance). :meth:`KalmanSensor.fit` learns
everything that would otherwise be hand-tuned -- channel means, measurement noise from the high-frequency noise
floor, the relative load levels by moment matching, and the overall process-noise level by maximising the
innovation log-likelihood of the training data.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import scipy.linalg as sla
from scipy.optimize import nnls
from scipy.signal import lfilter

__all__ = ["KalmanSensor"]

_DIFF_ORDER = 4  # order of the differences used to measure the white-noise floor
_DIFF_GAIN = math.comb(2 * _DIFF_ORDER, _DIFF_ORDER)  # var(diff^k e) / var(e) for white e
_MIN_NOISE_REL = 1e-3  # measurement noise std >= this fraction of the channel's std (keeps S well conditioned)
_MIN_FORCE_REL = 1e-3  # nominal load std >= this fraction of the largest one, relative to its effect


class KalmanSensor:
    """Virtual sensor: augmented Kalman filter on a linear model, with dropouts, gating and learned noise.

    State ``z = [x, f]``: the model's states ``x`` and its unknown inputs ``f`` (loads), which follow

    * ``"ar1"`` (default): ``f' = -f / tau + w``, a first-order Gauss-Markov process with time constant ``tau``;
    * ``"random_walk"``: ``f' = w``.

    The measured channels are ``y = C x + D_f f + D_k u_k + mean + v`` (accelerations have feedthrough of the
    loads), with ``u_k`` the known inputs (zero unless given to :meth:`update`) and ``v`` white measurement
    noise. Internally the outputs are z-scored with the training statistics and the states are scaled by their
    stationary standard deviations, so that the covariances are well conditioned although the loads are
    ~1e5-1e7 N and the outputs mix m/s² and kN·m.

    Parameters
    ----------
    system : control.StateSpace or tuple (A, B, C, D)
        Continuous-time model (SI units; outputs in the units of the recorded channels, as deviations from the
        operating-point mean). Its outputs are the channels the sensor receives and returns, in that order.
    dt : float
        Sample time (s) of the data the sensor will see.
    unknown_inputs : sequence of str or int, optional
        Inputs that are unknown loads and become augmented states (names, or indices into the inputs). Default:
        every input whose name does not contain ``"offset"`` (for ``FOWTModel.linearize``: ``wave_Fx`` ...
        ``wave_Mz`` and ``wind_dev``; ``pitch_offset`` and ``torque_offset`` are known control actions). For a
        tuple system, every input.
    force_model : {"ar1", "random_walk"}
        Dynamics of the unknown loads.
    force_time_constant : float or sequence of float
        Time constant ``tau`` of the AR(1) load model (s). A sequence is a grid: :meth:`fit` picks the value of
        highest innovation likelihood. For ``"random_walk"`` it only sets the initial uncertainty and scaling.
    process_noise : float, optional
        Overall load level ``alpha`` relative to the moment-matched nominal levels (-). None (default): learned
        by :meth:`fit` by maximising the innovation log-likelihood.
    measurement_noise : float or array_like (n_outputs,), optional
        Measurement-noise standard deviation per channel (channel units). None (default): learned by
        :meth:`fit` from the high-frequency noise floor of the training data.
    gate_sigma : float or None
        Innovation gate: a live channel whose normalised innovation ``|e_i| / sqrt(S_ii)`` exceeds this is
        ignored for that sample (counted in :attr:`n_gated_`). None or ``inf`` disables gating.
    max_fit_samples : int
        Longest stretch of training data (samples, summed over records) used for the likelihood search; the
        means and noise floor use all of it.

    Attributes
    ----------
    n_channels_ : int
        Number of channels (model outputs).
    channels_ : list of str
        Output names.
    unknown_inputs_ : list of str
        Names of the inputs estimated as augmented states.
    known_inputs_ : list of str
        Names of the inputs that :meth:`update` accepts as ``u``.
    mean_ : ndarray (n_channels,)
        Training mean per channel (channel units); added back to the estimate.
    scale_ : ndarray (n_channels,)
        Training standard deviation per channel (channel units); internal z-scoring.
    measurement_noise_std_ : ndarray (n_channels,)
        Measurement-noise standard deviation per channel (channel units).
    force_std_ : ndarray (n_unknown,)
        Stationary standard deviation of each unknown load in the fitted model (input units, e.g. N, N·m, m/s).
    force_time_constant_ : float
        Time constant of the load model (s).
    process_noise_ : float
        Fitted (or given) overall load level ``alpha`` (-).
    log_likelihood_ : float
        Innovation log-likelihood per sample of the training data at the fitted parameters.
    search_ : list of dict
        Every ``(force_time_constant, process_noise, log_likelihood)`` evaluated by :meth:`fit`.
    n_gated_ : int
        Channel samples rejected by the innovation gate since :meth:`reset`.
    gated_counts_ : ndarray of int (n_channels,)
        The same, per channel.
    n_blind_ : int
        Samples since :meth:`reset` with no usable channel (pure prediction).
    std_ : ndarray (n_channels,)
        Standard deviation of the latest estimate of each channel's true (noise-free) value (channel units).
    input_estimate_ : ndarray (n_unknown,)
        Latest estimate of the unknown loads (input units; deviations from their operating-point mean).

    Notes
    -----
    Per sample, :meth:`update` takes the prior, removes the rows of ``H`` and ``R`` of lost channels (mask
    False or value NaN), gates the rest, makes the Kalman update with the remaining rows, reports the posterior
    and predicts to the next sample. With no usable channel (total blackout) the update is skipped: the
    estimate is the model's pure prediction and :attr:`std_` grows accordingly; when channels return, the
    filter recovers without a restart. The estimate returned for every channel, live or lost, is the posterior
    mean of its noise-free value. Memory is O(1) in time; the work per sample is a few small matrix products.

    Gating is per channel on the prior innovation, in one pass. A spike or a sensor stuck far from the truth is
    rejected; a stuck value within the gate still pulls the estimate. After a long blackout the prior is wide,
    so the gate is wide too.

    Examples
    --------
    >>> import numpy as np, control
    >>> sys = control.ss([[0, 1], [-4, -0.4]], [[0], [1]], [[1, 0], [0, 1]], [[0], [0]],
    ...                  inputs=["force"], outputs=["disp", "vel"])
    >>> rng = np.random.default_rng(0)
    >>> Y = rng.standard_normal((2000, 2)) * [0.1, 0.2]
    >>> ks = KalmanSensor(sys, dt=0.05, process_noise=1.0).fit(Y)
    >>> ks.reset()
    >>> est = ks.update(np.array([0.05, np.nan]), np.array([True, False]))
    >>> est.shape, bool(np.all(np.isfinite(ks.std_)))
    ((2,), True)
    """

    def __init__(
        self,
        system,
        dt: float,
        unknown_inputs: Sequence[str | int] | None = None,
        force_model: str = "ar1",
        force_time_constant: float | Sequence[float] = 1.0,
        process_noise: float | None = None,
        measurement_noise: float | Sequence[float] | None = None,
        gate_sigma: float | None = 5.0,
        max_fit_samples: int = 60_000,
    ) -> None:
        self.system = system
        self.dt = dt
        self.unknown_inputs = unknown_inputs
        self.force_model = force_model
        self.force_time_constant = force_time_constant
        self.process_noise = process_noise
        self.measurement_noise = measurement_noise
        self.gate_sigma = gate_sigma
        self.max_fit_samples = max_fit_samples

    # --------------------------------------------------------------------------------------------- model
    def _check_params(self) -> None:
        a, b, c, d, in_names, out_names = _unpack_system(self.system)
        dt = _positive_float(self.dt, "dt")
        if self.force_model not in ("ar1", "random_walk"):
            raise ValueError(f"force_model must be 'ar1' or 'random_walk', got {self.force_model!r}")
        taus = np.atleast_1d(np.asarray(self.force_time_constant, dtype=float))
        if taus.ndim != 1 or taus.size == 0 or not np.all(np.isfinite(taus)) or np.any(taus <= 0):
            raise ValueError(
                f"force_time_constant must be a positive finite number of seconds (or a non-empty sequence of "
                f"them), got {self.force_time_constant!r}"
            )
        if self.process_noise is not None:
            _positive_float(self.process_noise, "process_noise")
        if self.gate_sigma is not None and not (isinstance(self.gate_sigma, (int, float, np.number))
                                                and self.gate_sigma > 0 and not math.isnan(self.gate_sigma)):
            raise ValueError(f"gate_sigma must be a positive number, inf or None, got {self.gate_sigma!r}")
        if not isinstance(self.max_fit_samples, (int, np.integer)) or self.max_fit_samples < 100:
            raise ValueError(f"max_fit_samples must be an integer >= 100, got {self.max_fit_samples!r}")
        unknown = _resolve_unknown(self.unknown_inputs, in_names, tuple_system=not hasattr(self.system, "A"))
        self._a, self._b, self._c, self._d = a, b, c, d
        self._in_names, self._out_names = in_names, out_names
        self._dt = dt
        self._taus = taus
        self._iu = unknown
        self._ik = [i for i in range(b.shape[1]) if i not in unknown]

    def _nominal_output_variance(self, tau: float) -> np.ndarray:
        """Stationary output variance per channel (rows) for each unknown input alone at unit variance (cols)."""
        a, b, c, d = self._a, self._b, self._c, self._d
        n = a.shape[0]
        out = np.zeros((c.shape[0], len(self._iu)))
        if np.max(np.linalg.eigvals(a).real) >= 0:
            raise ValueError(
                "system: the state matrix A has eigenvalues with non-negative real part; the sensor needs a stable "
                "model (stationary responses) to scale its loads"
            )
        for j, iu in enumerate(self._iu):
            aa = np.zeros((n + 1, n + 1))
            aa[:n, :n] = a
            aa[:n, n] = b[:, iu]
            aa[n, n] = -1.0 / tau
            qq = np.zeros((n + 1, n + 1))
            qq[n, n] = 2.0 / tau
            p = sla.solve_continuous_lyapunov(aa, -qq)
            cc = np.hstack([c, d[:, [iu]]])
            out[:, j] = np.einsum("ij,jk,ik->i", cc, p, cc)
        return out

    def _build(self, tau: float, force_std: np.ndarray) -> dict:
        """Scaled, discretised augmented model for one load time constant (process noise at alpha = 1)."""
        a, b, c, d = self._a, self._b, self._c, self._d
        n, p = a.shape[0], len(self._iu)
        na = n + p
        bf = b[:, self._iu] * force_std
        df = d[:, self._iu] * force_std
        # continuous augmented model in (x, f / force_std); AR(1) for the stationary scaling in every case
        aa = np.zeros((na, na))
        aa[:n, :n] = a
        aa[:n, n:] = bf
        aa[n:, n:] = -np.eye(p) / tau
        qc = np.zeros((na, na))
        qc[n:, n:] = np.eye(p) * (2.0 / tau)
        pst = sla.solve_continuous_lyapunov(aa, -qc)
        sx = np.sqrt(np.clip(np.diag(pst)[:n], 0.0, None))
        sx = np.where(np.isfinite(sx) & (sx > 1e-300), sx, 1.0)
        if self.force_model == "random_walk":
            aa[n:, n:] = 0.0
        m = np.concatenate([sx, np.ones(p)])
        a_s = aa / m[:, None] * m[None, :]
        bk = np.zeros((na, len(self._ik)))
        bk[:n] = b[:, self._ik]
        bk /= m[:, None]
        h = np.hstack([c, df]) * m[None, :] / self.scale_[:, None]
        dk = d[:, self._ik] / self.scale_[:, None]
        # exact discretisation: ZOH on the known inputs, Van Loan for the process noise
        nk = len(self._ik)
        big = np.zeros((na + nk, na + nk))
        big[:na, :na] = a_s * self._dt
        big[:na, na:] = bk * self._dt
        e = sla.expm(big)
        f, gk = e[:na, :na], e[:na, na:]
        vl = np.zeros((2 * na, 2 * na))
        vl[:na, :na] = -a_s * self._dt
        vl[:na, na:] = qc * self._dt
        vl[na:, na:] = a_s.T * self._dt
        ev = sla.expm(vl)
        q1 = f @ ev[:na, na:]
        q1 = 0.5 * (q1 + q1.T)
        p0 = pst / m[:, None] / m[None, :]
        p0 = 0.5 * (p0 + p0.T)
        return {"tau": tau, "F": f, "Gk": gk, "H": h, "Dk": dk, "Q1": q1, "P0": p0, "sx": sx, "force_std": force_std}

    # ------------------------------------------------------------------------------------------------ fit
    def fit(self, Y, mask=None) -> KalmanSensor:
        """Learn channel means, measurement noise and load levels from training data.

        Parameters
        ----------
        Y : array_like (n_samples, n_channels) or list of them
            Training records in channel units, columns in the order of the model outputs. NaN marks missing
            samples.
        mask : array_like of bool, optional
            Same shape as ``Y`` (or ``(n_channels,)``, or a list matching a list ``Y``); False = not available.

        Returns
        -------
        KalmanSensor
            self, fitted.

        Raises
        ------
        ValueError
            Bad model or parameters, wrong channel count, mask shape, too little finite data.
        """
        self._check_params()
        records = _as_records(Y, mask, self._c.shape[0])
        n_ch = self._c.shape[0]
        # means and scales from all available data
        stacked = np.vstack(records)
        counts = np.isfinite(stacked).sum(axis=0)
        if np.any(counts < 2 * _DIFF_ORDER + 2):
            bad = np.flatnonzero(counts < 2 * _DIFF_ORDER + 2).tolist()
            raise ValueError(f"Y: channels {bad} have fewer than {2 * _DIFF_ORDER + 2} finite training samples")
        self.mean_ = np.nanmean(stacked, axis=0)
        std = np.nanstd(stacked, axis=0)
        self.scale_ = np.where(std > 0, std, 1.0)
        # measurement noise: white floor from high-order differences (signal << Nyquist contributes ~nothing)
        if self.measurement_noise is None:
            num = np.zeros(n_ch)
            den = np.zeros(n_ch)
            for r in records:
                dd = np.diff(r, n=_DIFF_ORDER, axis=0)
                ok = np.isfinite(dd)
                num += np.where(ok, dd * dd, 0.0).sum(axis=0)
                den += ok.sum(axis=0)
            noise_std = np.sqrt(num / np.maximum(den, 1) / _DIFF_GAIN)
        else:
            noise_std = np.broadcast_to(np.asarray(self.measurement_noise, dtype=float), (n_ch,)).copy()
            if not np.all(np.isfinite(noise_std)) or np.any(noise_std < 0):
                raise ValueError(f"measurement_noise must be finite and >= 0, got {self.measurement_noise!r}")
        noise_std = np.maximum(noise_std, _MIN_NOISE_REL * self.scale_)
        self.measurement_noise_std_ = noise_std
        self._r = (noise_std / self.scale_) ** 2
        # relative load levels: match the stationary output variances (minus noise) by non-negative least squares
        signal_var = np.maximum(std**2 - noise_std**2, (0.01 * std) ** 2)
        train = [(r - self.mean_) / self.scale_ for r in _trim(records, self.max_fit_samples)]
        best = None
        self.search_ = []
        for tau in self._taus:
            v = self._nominal_output_variance(float(tau))
            w = v / signal_var[:, None]
            coef, _ = nnls(w, np.ones(n_ch))
            # unit-variance load j alone would explain the data with this std; keep every load slightly alive
            alone = 1.0 / np.sqrt(np.maximum(w.mean(axis=0), 1e-300))
            force_var = np.maximum(coef, (_MIN_FORCE_REL * alone) ** 2)
            model = self._build(float(tau), np.sqrt(force_var))
            if self.process_noise is not None:
                alpha = float(self.process_noise)
                ll = _log_likelihood(model, alpha, self._r, train, self._dt)
                self.search_.append({"force_time_constant": float(tau), "process_noise": alpha,
                                     "log_likelihood": ll})
            else:
                alpha, ll = self._search_alpha(model, train, float(tau))
            if best is None or ll > best[2]:
                best = (model, alpha, ll)
        model, alpha, ll = best
        self._model = model
        self.force_time_constant_ = float(model["tau"])
        self.process_noise_ = alpha
        self.log_likelihood_ = ll
        self.force_std_ = model["force_std"] * alpha
        self.n_channels_ = n_ch
        self.channels_ = list(self._out_names)
        self.unknown_inputs_ = [self._in_names[i] for i in self._iu]
        self.known_inputs_ = [self._in_names[i] for i in self._ik]
        self._set_alpha(alpha)
        self.reset()
        return self

    def _search_alpha(self, model: dict, train: list[np.ndarray], tau: float) -> tuple[float, float]:
        """Maximise the innovation log-likelihood over log10(alpha): coarse grid, extension, parabolic step."""
        cache: dict[float, float] = {}

        def ll_at(logit: float) -> float:
            key = round(logit, 6)
            if key not in cache:
                cache[key] = _log_likelihood(model, 10.0**logit, self._r, train, self._dt)
                self.search_.append({"force_time_constant": tau, "process_noise": 10.0**logit,
                                     "log_likelihood": cache[key]})
            return cache[key]

        step = 0.5
        grid = list(np.arange(-2.0, 2.0 + 1e-9, step))
        for g in grid:
            ll_at(g)
        for _ in range(6):  # extend the grid while the maximum sits on its edge
            k_best = max(cache, key=cache.get)
            if k_best == min(cache):
                ll_at(k_best - step)
            elif k_best == max(cache):
                ll_at(k_best + step)
            else:
                break
        for h in (step, step / 4):  # parabolic refinement around the best point
            k_best = max(cache, key=cache.get)
            y0, ym, yp = ll_at(k_best), ll_at(k_best - h), ll_at(k_best + h)
            curv = ym - 2 * y0 + yp
            if curv < 0:
                shift = 0.5 * h * (ym - yp) / curv
                ll_at(k_best + float(np.clip(shift, -h, h)))
        k_best = max(cache, key=cache.get)
        return 10.0**k_best, cache[k_best]

    def _set_alpha(self, alpha: float) -> None:
        mdl = self._model
        self._F = np.ascontiguousarray(mdl["F"])
        self._Ft = np.ascontiguousarray(mdl["F"].T)
        self._Gk = mdl["Gk"]
        self._H = np.ascontiguousarray(mdl["H"])
        self._Dk = mdl["Dk"]
        self._Q = alpha**2 * mdl["Q1"]
        self._P0 = alpha**2 * mdl["P0"]
        self._rows: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        n = self._a.shape[0]
        self._unscale_f = mdl["force_std"]  # scaled load -> input units
        self._n = n

    # -------------------------------------------------------------------------------------------- streaming
    def _check_fitted(self) -> None:
        if not hasattr(self, "_model"):
            raise ValueError("this KalmanSensor is not fitted yet: call fit(Y_train) first")

    def reset(self) -> None:
        """Start a new stream: state at its mean (zero deviation), covariance at its stationary value.

        Raises
        ------
        ValueError
            If the sensor is not fitted.
        """
        self._check_fitted()
        self._x = np.zeros(self._F.shape[0])
        self._P = self._P0.copy()
        self.n_gated_ = 0
        self.gated_counts_ = np.zeros(self.n_channels_, dtype=int)
        self.n_blind_ = 0
        self.std_ = np.sqrt(np.einsum("ij,jk,ik->i", self._H, self._P, self._H)) * self.scale_
        self.input_estimate_ = np.zeros(len(self._iu))

    def _rows_for(self, live: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        key = live.tobytes()
        rows = self._rows.get(key)
        if rows is None:
            idx = np.flatnonzero(live)
            rows = (idx, np.ascontiguousarray(self._H[idx]), self._r[idx])
            if len(self._rows) < 4096:
                self._rows[key] = rows
        return rows

    def update(self, y, mask=None, *, u=None, return_std: bool = False):
        """Process one sample and return the estimate of every channel.

        Parameters
        ----------
        y : array_like (n_channels,)
            Measured values in channel units (anything, e.g. NaN, where ``mask`` is False).
        mask : array_like of bool (n_channels,), optional
            True = sensor available (default: all). A NaN where mask is True is a dropout.
        u : array_like (n_known,), optional
            Known inputs (:attr:`known_inputs_`, input units) applied from this sample to the next
            (zero-order hold); default zero.
        return_std : bool
            Also return the standard deviation of the estimate (also kept in :attr:`std_`).

        Returns
        -------
        estimate : ndarray (n_channels,)
            Posterior mean of every channel's noise-free value (channel units).
        std : ndarray (n_channels,)
            Only if ``return_std``: its standard deviation (channel units).

        Raises
        ------
        ValueError
            Unfitted sensor, wrong length of ``y``, ``mask`` or ``u``, non-finite ``u``.
        """
        self._check_fitted()
        if not hasattr(self, "_x"):
            self.reset()
        y = np.asarray(y, dtype=float)
        n_ch = self.n_channels_
        if y.shape != (n_ch,):
            raise ValueError(
                f"y must have shape ({n_ch},) (one value per model output: {n_ch} channels), got {y.shape}"
            )
        if mask is None:
            live = np.isfinite(y)
        else:
            mask = np.asarray(mask)
            if mask.shape != (n_ch,):
                raise ValueError(f"mask must have shape ({n_ch},) like y, got {mask.shape}")
            live = mask.astype(bool) & np.isfinite(y)
        uk = None
        if u is not None:
            uk = np.asarray(u, dtype=float)
            if uk.shape != (len(self._ik),) or not np.all(np.isfinite(uk)):
                raise ValueError(f"u must be {len(self._ik)} finite known inputs {self.known_inputs_}, got {u!r}")
        x, p = self._x, self._P
        if live.any():
            idx, h, r = self._rows_for(live)
            z = (y[idx] - self.mean_[idx]) / self.scale_[idx]
            if uk is not None:
                z = z - self._Dk[idx] @ uk
            pht = p @ h.T
            s = h @ pht
            s[np.diag_indices_from(s)] += r
            e = z - h @ x
            gate = self.gate_sigma
            if gate is not None and gate != math.inf:
                bad = np.abs(e) > gate * np.sqrt(np.diag(s))
                if bad.any():
                    self.n_gated_ += int(bad.sum())
                    self.gated_counts_[idx[bad]] += 1
                    keep = ~bad
                    pht, s, e = pht[:, keep], s[np.ix_(keep, keep)], e[keep]
            if e.size:
                k = np.linalg.solve(s, pht.T).T
                x = x + k @ e
                p = p - k @ pht.T
                p = 0.5 * (p + p.T)
            else:
                self.n_blind_ += 1
        else:
            self.n_blind_ += 1
        est = self._H @ x
        if uk is not None:
            est = est + self._Dk @ uk
        est = self.mean_ + self.scale_ * est
        self.std_ = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", self._H, p, self._H), 0.0)) * self.scale_
        self.input_estimate_ = x[self._n:] * self._unscale_f
        # predict to the next sample
        xn = self._F @ x
        if uk is not None:
            xn += self._Gk @ uk
        self._x = xn
        self._P = self._F @ p @ self._Ft + self._Q
        if return_std:
            return est, self.std_.copy()
        return est

    def reconstruct(self, Y, mask=None, *, U=None, return_std: bool = False):
        """Estimate a whole record by streaming it through :meth:`update` from a :meth:`reset`.

        Parameters
        ----------
        Y : array_like (n_samples, n_channels)
            Record in channel units.
        mask : array_like of bool, optional
            ``(n_samples, n_channels)`` or ``(n_channels,)`` for a fixed mask; default: the finite entries.
        U : array_like (n_samples, n_known), optional
            Known inputs per sample.
        return_std : bool
            Also return the per-sample standard deviations.

        Returns
        -------
        Y_hat : ndarray (n_samples, n_channels)
            Identical to calling :meth:`update` sample by sample.
        std : ndarray (n_samples, n_channels)
            Only if ``return_std``.
        """
        self._check_fitted()
        Y = np.asarray(Y, dtype=float)
        if Y.ndim != 2 or Y.shape[1] != self.n_channels_:
            raise ValueError(f"Y must have shape (n_samples, {self.n_channels_}), got {Y.shape}")
        if mask is None:
            mask = np.ones(Y.shape, dtype=bool)
        mask = np.asarray(mask)
        if mask.shape not in (Y.shape, (self.n_channels_,)):
            raise ValueError(f"mask must have shape {Y.shape} or ({self.n_channels_},), got {mask.shape}")
        mask = np.broadcast_to(mask.astype(bool), Y.shape)
        if U is not None:
            U = np.asarray(U, dtype=float)
            if U.shape != (Y.shape[0], len(self._ik)):
                raise ValueError(f"U must have shape ({Y.shape[0]}, {len(self._ik)}), got {U.shape}")
        self.reset()
        out = np.empty_like(Y)
        sd = np.empty_like(Y) if return_std else None
        for k in range(Y.shape[0]):
            out[k] = self.update(Y[k], mask[k], u=None if U is None else U[k])
            if sd is not None:
                sd[k] = self.std_
        return (out, sd) if return_std else out


# ------------------------------------------------------------------------------------------------- helpers
def _positive_float(value, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return v


def _unpack_system(system):
    """(A, B, C, D, input names, output names) of a continuous StateSpace or an (A, B, C, D) tuple."""
    if hasattr(system, "A") and hasattr(system, "B"):
        dt = getattr(system, "dt", 0)
        if dt not in (0, None) and dt is not False:
            raise ValueError(f"system must be continuous-time (dt=0); got a discrete system with dt={dt!r}")
        a, b, c, d = system.A, system.B, system.C, system.D
        in_names = list(getattr(system, "input_labels", [f"u[{i}]" for i in range(np.shape(b)[1])]))
        out_names = list(getattr(system, "output_labels", [f"y[{i}]" for i in range(np.shape(c)[0])]))
    elif isinstance(system, (tuple, list)) and len(system) == 4:
        a, b, c, d = system
        in_names = out_names = None
    else:
        raise ValueError("system must be a continuous control.StateSpace or a tuple (A, B, C, D)")
    try:
        a, b, c, d = (np.atleast_2d(np.asarray(m, dtype=float)) for m in (a, b, c, d))
    except (TypeError, ValueError):
        raise ValueError("system: A, B, C, D must be numeric matrices") from None
    n = a.shape[0]
    if a.shape != (n, n) or b.shape[0] != n or c.shape[1] != n or d.shape != (c.shape[0], b.shape[1]):
        raise ValueError(
            f"system: inconsistent shapes A {a.shape}, B {b.shape}, C {c.shape}, D {d.shape} "
            "(expected A (n, n), B (n, m), C (p, n), D (p, m))"
        )
    if not all(np.all(np.isfinite(m)) for m in (a, b, c, d)):
        raise ValueError("system: A, B, C, D must be finite")
    if in_names is None:
        in_names = [f"u[{i}]" for i in range(b.shape[1])]
        out_names = [f"y[{i}]" for i in range(c.shape[0])]
    return a, b, c, d, in_names, out_names


def _resolve_unknown(unknown, in_names: list[str], tuple_system: bool) -> list[int]:
    m = len(in_names)
    if unknown is None:
        idx = list(range(m)) if tuple_system else [i for i, s in enumerate(in_names) if "offset" not in s]
    else:
        if isinstance(unknown, (str, int, np.integer)):
            unknown = [unknown]
        idx = []
        for item in unknown:
            if isinstance(item, str):
                if item not in in_names:
                    raise ValueError(f"unknown_inputs: no input {item!r}; inputs are {in_names}")
                idx.append(in_names.index(item))
            elif isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < m:
                idx.append(int(item))
            else:
                raise ValueError(f"unknown_inputs: {item!r} is neither an input name nor an index in [0, {m})")
        if len(set(idx)) != len(idx):
            raise ValueError(f"unknown_inputs: duplicates in {unknown!r}")
    if not idx:
        raise ValueError("unknown_inputs: at least one unknown input is needed (the loads driving the model)")
    return sorted(idx)


def _as_records(Y, mask, n_ch: int) -> list[np.ndarray]:
    """Training data as a list of float arrays with NaN where unavailable."""
    if isinstance(Y, (list, tuple)) and len(Y) > 0 and np.ndim(Y[0]) == 2:
        ys = list(Y)
        if mask is None or (not isinstance(mask, (list, tuple))):
            masks = [mask] * len(ys)
        else:
            masks = list(mask)
            if len(masks) != len(ys):
                raise ValueError(f"mask: a list of {len(masks)} masks for {len(ys)} records")
    else:
        ys, masks = [Y], [mask]
    out = []
    for i, (yi, mi) in enumerate(zip(ys, masks, strict=True)):
        yi = np.array(yi, dtype=float)
        if yi.ndim != 2 or yi.shape[1] != n_ch:
            raise ValueError(
                f"Y: record {i} must have shape (n_samples, {n_ch}) (one column per model output), got {yi.shape}"
            )
        if mi is not None:
            mi = np.asarray(mi)
            if mi.shape not in (yi.shape, (n_ch,)):
                raise ValueError(f"mask: record {i} needs shape {yi.shape} or ({n_ch},), got {mi.shape}")
            yi[~np.broadcast_to(mi.astype(bool), yi.shape)] = np.nan
        yi[~np.isfinite(yi)] = np.nan
        out.append(yi)
    return out


def _trim(records: list[np.ndarray], max_samples: int) -> list[np.ndarray]:
    out, left = [], max_samples
    for r in records:
        if left <= 0:
            break
        out.append(r[:left])
        left -= min(left, r.shape[0])
    return out


def _log_likelihood(model: dict, alpha: float, r: np.ndarray, records: list[np.ndarray], dt: float) -> float:
    """Innovation log-likelihood per sample of the steady-state filter (missing samples: time-varying filter)."""
    f, h = model["F"], model["H"]
    q = alpha**2 * model["Q1"]
    rr = np.diag(r)
    m = h.shape[0]
    try:
        p = sla.solve_discrete_are(f.T, h.T, q, rr)
    except (np.linalg.LinAlgError, ValueError):
        return -np.inf
    s = h @ p @ h.T + rr
    try:
        cs = sla.cho_factor(s)
    except np.linalg.LinAlgError:
        return -np.inf
    k = sla.cho_solve(cs, h @ p).T  # P H' S^-1
    logdet = 2.0 * np.sum(np.log(np.diag(cs[0])))
    a_cl = f - f @ k @ h
    b_cl = f @ k
    total, count = 0.0, 0
    for yr in records:
        n = yr.shape[0]
        burn = min(int(round(20.0 / dt)), n // 10)
        if np.all(np.isfinite(yr)):
            e = yr - _steady_state_predictions(a_cl, b_cl, yr) @ h.T
            e = e[burn:]
            quad = np.einsum("ij,ij->i", e, sla.cho_solve(cs, e.T).T)
            total += -0.5 * float(np.sum(quad)) - 0.5 * (logdet + m * math.log(2 * math.pi)) * e.shape[0]
            count += e.shape[0]
        else:
            x = np.zeros(f.shape[0])
            pp = model["P0"] * alpha**2
            for i in range(n):
                live = np.isfinite(yr[i])
                if live.any():
                    hl = h[live]
                    pht = pp @ hl.T
                    sl = hl @ pht + np.diag(r[live])
                    e = yr[i, live] - hl @ x
                    try:
                        c = sla.cho_factor(sl)
                    except np.linalg.LinAlgError:
                        return -np.inf
                    if i >= burn:
                        total += -0.5 * (float(e @ sla.cho_solve(c, e)) + 2.0 * np.sum(np.log(np.diag(c[0])))
                                         + live.sum() * math.log(2 * math.pi))
                        count += 1
                    kk = sla.cho_solve(c, pht.T).T
                    x = x + kk @ e
                    pp = pp - kk @ pht.T
                x = f @ x
                pp = f @ pp @ f.T + q
    return total / max(count, 1)


def _steady_state_predictions(a_cl: np.ndarray, b_cl: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Prior state means of a steady-state filter ``x[k+1] = a_cl x[k] + b_cl y[k]``, ``x[0] = 0`` (n_samples, n).

    Decoupled into first-order modal recursions run by ``lfilter`` when ``a_cl`` is well diagonalisable;
    otherwise a plain loop.
    """
    n_s, n = y.shape[0], a_cl.shape[0]
    lam, vec = np.linalg.eig(a_cl)
    if np.linalg.cond(vec) < 1e6:
        w = np.linalg.solve(vec, b_cl @ y.T)
        xi = np.empty_like(w)
        for i in range(n):
            xi[i] = lfilter([0.0, 1.0], [1.0, -lam[i]], w[i])
        return np.ascontiguousarray((vec @ xi).real.T)
    xs = np.empty((n_s, n))
    x = np.zeros(n)
    for i in range(n_s):
        xs[i] = x
        x = a_cl @ x + b_cl @ y[i]
    return xs
