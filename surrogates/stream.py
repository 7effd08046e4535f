"""Step-by-step simulation with actions and bounded memory: the engine behind the Gymnasium environment.

:class:`StreamingSimulator` advances the same compiled stepper as :func:`surrogates.simulate`, a few samples at a
time, with collective-pitch and generator-torque offsets held between calls. Forcing is synthesised in chunks
(default 600 s): each chunk is an independent FFT realisation, and consecutive chunks are joined over an
overlap (default 30 s) with power-complementary weights ``cos``/``sin`` of a quarter period, so the joined
forcing is continuous and keeps its variance and spectrum (up to a spectral leakage of the overlap's length).
Memory is therefore independent of the episode length. Sensor noise is produced sample by sample (white plus
AR(1) coloured with its state carried).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np
from scipy.signal import lfilter

from .channels import ALL_CHANNELS
from .load_cases import LoadCase
from .model import INPUT_BLOCKS, N_INPUT, N_STATE, FOWTModel
from .simulate import N_EX, Simulator, elastodyn_platform_angles

__all__ = ["StreamingSimulator"]


@numba.njit(cache=True, nogil=True)
def _noisy_sample(truth, e, white, ar, gain, state, out):
    """One noisy sample: ``state = ar state + gain e[0, 0]`` (in place) and ``out = truth + white e[1] + state``,
    channel by channel in the order numpy evaluates those expressions (``truth``, ``out``: (1, n); ``e``:
    (2, 1, n))."""
    for c in range(truth.shape[1]):
        s = ar * state[c] + gain[c] * e[0, 0, c]
        state[c] = s
        out[0, c] = truth[0, c] + white[c] * e[1, 0, c] + s


class StreamingSimulator:
    """Advance the surrogate in small steps with actions, forcing streamed in crossfaded chunks.

    Parameters
    ----------
    model : FOWTModel
    case : int or LoadCase or None
    dt : float
        Output sample time (s).
    chunk_seconds : float
        Length of each forcing realisation (s).
    overlap_seconds : float
        Crossfade between consecutive realisations (s).
    warmup_seconds : float
        Simulated (and discarded) at every reset, from the static equilibrium.
    forcing : callable, optional
        Replayed forcing instead of the synthesised one: ``forcing(k0, n)`` returns ``(u_ex, vel, blade)`` at
        internal steps ``k0 ... k0 + n`` from the reset (:class:`surrogates.replay_stream.ReplayForcing`), asked
        for one chunk at a time without crossfade; its ``steps_available`` bounds :meth:`advance`.

    Examples
    --------
    >>> import numpy as np, surrogates
    >>> sim = surrogates.StreamingSimulator(surrogates.FOWTModel(), 7)
    >>> y0 = sim.reset(seed=1)
    >>> noisy, truth = sim.advance(80, action=np.zeros(2))
    >>> truth.shape
    (80, 55)
    """

    def __init__(self, model: FOWTModel, case: int | LoadCase | None, dt: float = 0.0125,
                 chunk_seconds: float = 600.0, overlap_seconds: float = 30.0, warmup_seconds: float = 30.0,
                 forcing: Callable[[int, int], tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None) -> None:
        self.sim = Simulator(model, case, dt)
        self.forcing = forcing
        self._k_next = 0  # internal step (from the reset) of the next chunk of replayed forcing
        for name, value in (("chunk_seconds", chunk_seconds), ("overlap_seconds", overlap_seconds)):
            if not np.isfinite(value) or value <= 0:
                raise ValueError(f"{name} must be positive and finite, got {value!r}")
        if not np.isfinite(warmup_seconds) or warmup_seconds < 0:
            raise ValueError(f"warmup_seconds must be finite and >= 0, got {warmup_seconds!r}")
        if overlap_seconds >= chunk_seconds:
            raise ValueError("overlap_seconds must be shorter than chunk_seconds")
        self.dt = self.sim.dt
        self.substeps = self.sim.substeps
        self.chunk = int(round(chunk_seconds / self.sim.dt_int))
        self.overlap = max(1, int(round(overlap_seconds / self.sim.dt_int)))
        self.warmup = int(round(warmup_seconds / self.dt))
        self.channels = list(ALL_CHANNELS)
        self._white, self._col = model.noise.std(self.channels)
        self._ar = math.exp(-self.dt / max(model.noise.correlation_time, 1e-9))
        self._ar_gain = math.sqrt(1.0 - self._ar**2) * self._col
        self._noisy = bool(np.any(self._white) or np.any(self._col))
        self._cd = np.ascontiguousarray(np.hstack([self.sim.cy, self.sim.dy]))  # outputs of [x | u]
        self._seq: np.random.SeedSequence | None = None

    # ---------------------------------------------------------------------------------------------- forcing
    def _raw_chunk(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        assert self._seq is not None
        child = self._seq.spawn(1)[0]
        u_ex, vel, _, blade = self.sim.forcing(self.chunk + self.overlap, child)
        return u_ex, vel, blade

    def _next_chunk(self) -> None:
        """Make the next `chunk` steps of forcing (plus one sample for the hold), crossfaded with the previous."""
        if self.forcing is not None:  # replayed inputs are continuous: the next window as it is
            u, v, b = self.forcing(self._k_next, self.chunk)
            self._k_next += self.chunk
            self._u, self._vel, self._blade = (np.ascontiguousarray(a) for a in (u, v, b))
            self._exo = self.sim.exogenous(self._u)
            self._k = 0
            return
        u_new, v_new, b_new = self._raw_chunk()
        if self._tail is not None:
            tail_u, tail_v, tail_b = self._tail
            n = self.overlap
            theta = 0.5 * np.pi * (np.arange(n) + 0.5) / n
            c, s = np.cos(theta), np.sin(theta)
            hub_w = INPUT_BLOCKS["hub_wind"].start
            mean = np.zeros(N_EX)
            mean[0] = 1.0
            if self.sim.case is not None and self.sim.case.wind_speed > 0:
                mean[hub_w] = self.sim.case.wind_speed  # crossfade the turbulence, not the mean wind
                mean[INPUT_BLOCKS["shear"]] = self.sim.mean_shear  # and the disc gradients' mean
            u_head = (tail_u - mean) * c[:, None] + (u_new[:n] - mean) * s[:, None] + mean
            v_head = tail_v * c[:, None, None] + v_new[:n] * s[:, None, None]
            if b_new.shape[0]:
                w_mean = self.sim.case.wind_speed
                b_head = (tail_b - w_mean) * c[:, None] + (b_new[:n] - w_mean) * s[:, None] + w_mean
                b_new = np.concatenate([b_head.astype(np.float32), b_new[n:]])
            u_new = np.concatenate([u_head, u_new[n:]])
            v_new = np.concatenate([v_head, v_new[n:]])
        # keep `chunk + 1` samples for this chunk; the rest is the tail to crossfade into the next one
        self._u = np.ascontiguousarray(u_new[: self.chunk + 1])
        self._vel = np.ascontiguousarray(v_new[: self.chunk + 1])
        self._blade = np.ascontiguousarray(b_new[: self.chunk + 1])
        self._exo = self.sim.exogenous(self._u)
        self._tail = (u_new[self.chunk: self.chunk + self.overlap], v_new[self.chunk: self.chunk + self.overlap],
                      b_new[self.chunk: self.chunk + self.overlap])
        self._k = 0

    # ------------------------------------------------------------------------------------------------- API
    def reset(self, seed: int | np.random.SeedSequence | None = None) -> np.ndarray:
        """Start again from the static equilibrium (then ``warmup_seconds`` of simulation).

        Parameters
        ----------
        seed : int or SeedSequence
            Seeds forcing, rotor azimuth and noise.

        Returns
        -------
        ndarray (55,)
            Noise-free channel values at the first sample after the warm-up.
        """
        self._seq = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
        psi_seq, noise_seq = self._seq.spawn(2)
        self._noise_rng = np.random.default_rng(noise_seq)
        self._ar_state = self._col * self._noise_rng.standard_normal(len(self.channels))
        self.psi = float(np.random.default_rng(psi_seq).uniform(0.0, 2.0 * np.pi))
        self.x, self.ctrl = self.sim.initial_state(None)
        self.psi_start = self.psi  # rad, the rotor azimuth before the warm-up
        self.time = 0.0
        self._tail = None
        self._k_next = 0
        self._next_chunk()
        self._x_hist = np.zeros((1, N_STATE))
        self._u_hist = np.zeros((1, N_INPUT - N_EX))
        if self.warmup:
            self.advance(self.warmup, np.zeros(2), noise=False)
        self.time = 0.0
        return self.output()

    def output(self) -> np.ndarray:
        """Noise-free channel values at the current state (55,), with zero actions and current forcing."""
        x_hist = np.zeros((1, N_STATE))
        u_hist = np.zeros((1, N_INPUT - N_EX))
        self.sim.advance(self.x.copy(), self.ctrl.copy(), self.psi, self._k, 1, 1, self._exo, self._u, np.zeros(2),
                         self._vel, self._blade, x_hist, u_hist, 0)
        return self.sim.outputs(x_hist, self._u[self._k: self._k + 1], u_hist)[0]

    def advance(self, n_samples: int, action: np.ndarray, noise: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Advance ``n_samples`` output samples holding ``action``.

        Parameters
        ----------
        n_samples : int
            Output samples to produce (each ``dt``).
        action : ndarray (2,)
            Collective-pitch offset (rad) and generator-torque offset (N·m, low-speed shaft).
        noise : bool
            Return noisy channels too (else the noisy array is the truth).

        Returns
        -------
        noisy, truth : ndarray (n_samples, 55)
            Channel values at the start of each sample interval.
        """
        act = np.ascontiguousarray(action, dtype=float)
        sim = self.sim
        if self.forcing is not None and n_samples * self.substeps > self.steps_left:
            raise ValueError(f"the replayed inputs end {self.steps_left * sim.dt_int:g} s ahead: cannot advance "
                             f"{n_samples * self.dt:g} s")
        # one buffer [x | exogenous u | per-step u] per output sample, so the outputs are a single product
        buf = np.empty((n_samples, self._cd.shape[1]))
        out_x = buf[:, :N_STATE]
        out_u = buf[:, N_STATE + N_EX:]
        done = 0
        while done < n_samples:
            room = (self.chunk - self._k) // self.substeps
            if room <= 0:
                self._next_chunk()
                continue
            m = min(room, n_samples - done)
            buf[done: done + m, N_STATE: N_STATE + N_EX] = self._u[self._k: self._k + m * self.substeps: self.substeps]
            self.psi = sim.advance(self.x, self.ctrl, self.psi, self._k, m * self.substeps, self.substeps,
                                   self._exo, self._u, act, self._vel, self._blade, out_x,
                                   out_u, done)
            self._k += m * self.substeps
            done += m
        self.time += n_samples * self.dt
        truth = buf @ self._cd.T
        elastodyn_platform_angles(truth, sim._i_roll, sim._i_pitch, sim._i_yaw,  # as simulate() reports them
                                  sim.system.mean_pitch)
        if not noise or not self._noisy:
            return truth, truth
        e = self._noise_rng.standard_normal((2, n_samples, len(self.channels)))
        # AR(1) coloured part x_i = a x_{i-1} + sqrt(1 - a^2) sigma e_i, its state carried between calls
        if n_samples == 1:  # the environment's usual step: the same arithmetic as below, in one compiled call
            noisy = np.empty_like(truth)
            _noisy_sample(truth, e, self._white, self._ar, self._ar_gain, self._ar_state, noisy)
            return noisy, truth
        if n_samples <= 8:
            colored = np.empty((n_samples, len(self.channels)))
            state = self._ar_state
            for i in range(n_samples):
                state = self._ar * state + self._ar_gain * e[0, i]
                colored[i] = state
        else:
            colored, _ = lfilter([1.0], [1.0, -self._ar], self._ar_gain * e[0], axis=0,
                                 zi=(self._ar * self._ar_state)[None, :])
        self._ar_state = colored[-1].copy()
        return truth + self._white * e[1] + colored, truth

    @property
    def state(self) -> np.ndarray:
        """Current state vector (N_STATE,), a copy."""
        return self.x.copy()

    @property
    def steps_left(self) -> int:
        """Internal steps the replayed ``forcing`` still covers (a very large number without one)."""
        if self.forcing is None:
            return 2**62
        return int(self.forcing.steps_available) - (self._k_next - self.chunk + self._k)  # type: ignore[attr-defined]
