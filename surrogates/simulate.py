"""Time-domain simulation of :class:`~surrogates.model.FOWTModel`: forcing synthesis and a compiled stepper.

The linear part is integrated exactly: the continuous system is discretised once per (model, case, step) with
the matrix exponential, with a first-order hold on the precomputed forcing (waves, wind: piecewise linear
between samples, exact for it) and a zero-order hold on what is evaluated per step (nonlinear effects, rotor
harmonics, actions). The nonlinear and harmonic loads are evaluated explicitly from the state at the start of
each step in a numba kernel; with the internal step at most 0.025 s this is accurate and stable (their time
scales are the wave and platform periods). Forcing is synthesised in the frequency domain (FFT), see
:mod:`surrogates.waves` and :mod:`surrogates.wind`.

Randomness: the integer ``seed`` feeds a ``numpy.random.SeedSequence`` whose children seed the waves, the wind,
the rotor's initial azimuth and the sensor noise -- the same seed gives the same bytes.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numba
import numpy as np
import scipy.linalg as sla

from .channels import ALL_CHANNELS, UNITS
from .load_cases import LoadCase
from .model import INPUT_BLOCKS, N_INPUT, N_STATE, FOWTModel, LinearSystem, _as_case
from .mooring import mooring_table
from .oc3 import RHO_WATER
from .record import Record
from .structure import N_DOF
from .validation import check_number
from .waves import SparGeometry, synthesize_waves
from .wind import synthesize_wind

__all__ = ["simulate", "Simulator", "MAX_INTERNAL_STEP", "MAX_SAMPLE_TIME"]

MAX_INTERNAL_STEP = 0.025
"""Largest internal integration step (s); longer sample times are subdivided."""
MAX_SAMPLE_TIME = 0.15
"""Largest sample time (s): the 2nd tower modes (up to ~2.6 Hz) must lie below the Nyquist frequency."""
N_EX = INPUT_BLOCKS["hub_wind"].stop  # exogenous (precomputed) inputs: const, wave(6), wind, elev, hub wind
N_STRIPS = 24


# ------------------------------------------------------------------------------------------------ kernel
@numba.njit(cache=True, nogil=True)
def _nonlinear_and_hub(x, k, psi, vel, strip_z, drag_coef, moor_r, moor_h, moor_v, moor_k, zf, s_moor,
                       harm, e_s, u):
    """Fill u[10:28] (actions stay as set) with hub harmonic loads and nonlinear generalised forces."""
    nd = 10
    hub0 = 12
    nl0 = 18
    for i in range(hub0, nl0 + nd):
        u[i] = 0.0
    # --- quadratic drag on the relative velocity, strip by strip
    if drag_coef.shape[0] > 0:
        for j in range(strip_z.shape[0]):
            z = strip_z[j]
            vx = x[nd + 0] + z * x[nd + 4]
            vy = x[nd + 1] - z * x[nd + 3]
            ux = vel[k, j, 0] - vx
            uy = vel[k, j, 1] - vy
            s = math.sqrt(ux * ux + uy * uy)
            fx = drag_coef[j] * s * ux
            fy = drag_coef[j] * s * uy
            u[nl0 + 0] += fx
            u[nl0 + 1] += fy
            u[nl0 + 3] += -z * fy
            u[nl0 + 4] += z * fx
    # --- catenary mooring beyond the linear tangent stiffness, at the fairlead
    if s_moor > 0.0:
        xf = x[0] + zf * x[4]
        yf = x[1] - zf * x[3]
        rho = math.sqrt(xf * xf + yf * yf)
        if rho > 1e-12:
            n = moor_r.shape[0]
            if rho >= moor_r[n - 1]:
                slope_h = (moor_h[n - 1] - moor_h[n - 2]) / (moor_r[n - 1] - moor_r[n - 2])
                slope_v = (moor_v[n - 1] - moor_v[n - 2]) / (moor_r[n - 1] - moor_r[n - 2])
                h = moor_h[n - 1] + slope_h * (rho - moor_r[n - 1])
                v = moor_v[n - 1] + slope_v * (rho - moor_r[n - 1])
            else:
                i = int(rho / moor_r[1])
                w = (rho - moor_r[i]) / (moor_r[i + 1] - moor_r[i])
                h = moor_h[i] + w * (moor_h[i + 1] - moor_h[i])
                v = moor_v[i] + w * (moor_v[i + 1] - moor_v[i])
            excess = s_moor * (h - moor_k * rho)
            fx = -excess * xf / rho
            fy = -excess * yf / rho
            u[nl0 + 0] += fx
            u[nl0 + 1] += fy
            u[nl0 + 2] += -s_moor * v
            u[nl0 + 3] += -zf * fy
            u[nl0 + 4] += zf * fx
    # --- rotor harmonics: harm = [T0, Q0, R, Omega0, a3, a6, aq, am, a1, b1, mi] (strengths applied)
    t0 = harm[0]
    if t0 != 0.0:
        omega = harm[3] + x[2 * nd]
        c1, s1 = math.cos(psi), math.sin(psi)
        c3, s3 = math.cos(3.0 * psi), math.sin(3.0 * psi)
        c6 = math.cos(6.0 * psi)
        fs = t0 * (harm[4] * c3 + harm[5] * c6 + harm[8] * c1)
        mq = harm[1] * harm[6] * c3
        tr = t0 * harm[2]
        cent = harm[10] * omega * omega
        for a in range(3):
            u[hub0 + a] += fs * e_s[a]
            u[hub0 + 3 + a] += mq * e_s[a]
        u[hub0 + 1] += cent * s1
        u[hub0 + 2] += cent * c1
        u[hub0 + 4] += tr * (harm[7] * c3 + harm[9] * c1)
        u[hub0 + 5] += tr * (harm[7] * s3 + harm[9] * s1)


@numba.njit(cache=True, nogil=True)
def _advance(x, psi, k0, n_steps, every, phi, g_rest, exo, action, vel, strip_z, drag_coef, moor_r, moor_h,
             moor_v, moor_k, zf, s_moor, harm, e_s, dt, x_hist, u_hist, out0):
    """Advance ``n_steps`` internal steps from step index ``k0``.

    ``exo[k]`` is the precomputed contribution of the exogenous inputs to ``x[k+1]``. Every ``every`` steps the
    state and the per-step inputs (actions, hub loads, nonlinear forces) are stored in ``x_hist[out0 + i]`` and
    ``u_hist[out0 + i]`` (outputs are formed from them afterwards by one matrix product). ``x`` is updated in
    place; the new rotor azimuth is returned.
    """
    n_x = x.shape[0]
    n_r = g_rest.shape[1]
    u = np.zeros(10 + n_r)
    xn = np.zeros(n_x)
    n_out = 0
    for step in range(n_steps):
        k = k0 + step
        u[10] = action[0]
        u[11] = action[1]
        _nonlinear_and_hub(x, k, psi, vel, strip_z, drag_coef, moor_r, moor_h, moor_v, moor_k, zf, s_moor,
                           harm, e_s, u)
        if step % every == 0:
            row = out0 + n_out
            for i in range(n_x):
                x_hist[row, i] = x[i]
            for i in range(n_r):
                u_hist[row, i] = u[10 + i]
            n_out += 1
        for r in range(n_x):
            acc = exo[k, r]
            for i in range(n_x):
                acc += phi[r, i] * x[i]
            for i in range(n_r):
                acc += g_rest[r, i] * u[10 + i]
            xn[r] = acc
        psi += (harm[3] + x[20]) * dt
        for r in range(n_x):
            x[r] = xn[r]
    return psi


# -------------------------------------------------------------------------------------------- discretised
@dataclass(frozen=True)
class _Discrete:
    phi: np.ndarray
    g_ex0: np.ndarray
    g_ex1: np.ndarray
    g_rest: np.ndarray


def _discretise(sys: LinearSystem, dt: float) -> _Discrete:
    """Exact discretisation: FOH on the exogenous inputs, ZOH on the rest (van Loan's block exponential)."""
    n, m = sys.A.shape[0], sys.B.shape[1]
    big = np.zeros((n + 2 * m, n + 2 * m))
    big[:n, :n] = sys.A * dt
    big[:n, n:n + m] = sys.B * dt
    big[n:n + m, n + m:] = np.eye(m)
    e = sla.expm(big)
    phi = e[:n, :n]
    gam1 = e[:n, n:n + m]  # int_0^T e^{A s} ds B
    gam2 = e[:n, n + m:]  # int_0^T e^{A (T - tau)} tau / T dtau B
    g_ex0 = np.ascontiguousarray(gam1[:, :N_EX] - gam2[:, :N_EX])
    g_ex1 = np.ascontiguousarray(gam2[:, :N_EX])
    return _Discrete(np.ascontiguousarray(phi), g_ex0, g_ex1, np.ascontiguousarray(gam1[:, N_EX:]))


class Simulator:
    """Everything that does not depend on the seed: discretised system, nonlinear-effect tables, outputs.

    Parameters
    ----------
    model : FOWTModel
    case : int or LoadCase or None
        Load case (None: parked rotor, still water, no wind).
    dt : float
        Output sample time (s), at most :data:`MAX_SAMPLE_TIME`.

    Notes
    -----
    :func:`simulate` is the usual entry point; the Gymnasium environment uses a Simulator to step the model
    in chunks with actions.
    """

    def __init__(self, model: FOWTModel, case: int | LoadCase | None, dt: float = 0.0125) -> None:
        if not isinstance(model, FOWTModel):
            raise ValueError(f"model must be a surrogates.FOWTModel, got {type(model).__name__}")
        dt = check_number("dt", dt, positive=True)
        if dt > MAX_SAMPLE_TIME:
            raise ValueError(
                f"dt={dt} s is too large: sampling must resolve the 2nd tower modes (~2.6 Hz); use dt <= "
                f"{MAX_SAMPLE_TIME} s (the paper's data are at 0.0125 s)"
            )
        self.model = model
        self.case = _as_case(case)
        self.dt = dt
        self.substeps = max(1, math.ceil(dt / MAX_INTERNAL_STEP - 1e-9))
        self.dt_int = dt / self.substeps
        self.system = model.system(self.case)
        disc = _discretise(self.system, self.dt_int)
        self.phi, self.g_ex0, self.g_ex1, self.g_rest = disc.phi, disc.g_ex0, disc.g_ex1, disc.g_rest
        self.cy = np.ascontiguousarray(self.system.C)
        self.dy = np.ascontiguousarray(self.system.D)
        eff = model.effects
        st = self.system.structure
        geo = SparGeometry()
        z, dz, diam = geo.strips(N_STRIPS)
        self.strip_z = np.ascontiguousarray(z, dtype=float)
        s_drag = eff["quadratic_drag"]
        self.drag_coef = (0.5 * RHO_WATER * geo.cd * np.asarray(diam) * np.asarray(dz) * s_drag
                          if s_drag > 0 else np.zeros(0))
        tab = mooring_table()
        self.moor_r = tab.offset.astype(float)
        self.moor_h = tab.horizontal_force.astype(float)
        self.moor_v = tab.vertical_force.astype(float)
        self.moor_k = float(st.data.mooring_stiffness[0, 0])
        self.zf = float(tab.fairlead_z)
        self.s_moor = float(eff["mooring_nonlinear"])
        self.e_s = np.ascontiguousarray(st.shaft_axis, dtype=float)
        h = model.harmonics
        op = self.system.op
        s3, s1 = eff["rotor_3p"], eff["rotor_1p"]
        self.harm = np.array([
            op.thrust if op else 0.0, op.aero_torque if op else 0.0, st.data.tip_radius,
            self.system.rotor_speed, s3 * h.thrust_3p, s3 * h.thrust_6p, s3 * h.torque_3p, s3 * h.moment_3p,
            s1 * h.thrust_1p, s1 * h.moment_1p, s1 * h.mass_imbalance,
        ])
        self.x_eq = self.system.equilibrium(self._nonlinear_static)

    # ------------------------------------------------------------------------------------------ helpers
    def _nonlinear_static(self, x: np.ndarray) -> np.ndarray:
        u = np.zeros(N_INPUT)
        vel = np.zeros((1, self.strip_z.size, 2))
        xs = x.copy()
        xs[N_DOF:] = 0.0
        harm = self.harm.copy()
        harm[0] = 0.0  # the mean of the harmonics is zero
        _nonlinear_and_hub(xs, 0, 0.0, vel, self.strip_z, self.drag_coef, self.moor_r, self.moor_h, self.moor_v,
                           self.moor_k, self.zf, self.s_moor, harm, self.e_s, u)
        return u[INPUT_BLOCKS["nonlinear"]]

    def forcing(self, n_steps: int, seed_sequence: np.random.SeedSequence) -> tuple[np.ndarray, np.ndarray, float]:
        """Exogenous inputs for ``n_steps`` internal steps (+1 sample for the hold), strip velocities, azimuth."""
        wave_ss, wind_ss, psi_ss = seed_sequence.spawn(3)
        n = n_steps + 1
        duration = n * self.dt_int
        u_ex = np.zeros((n, N_EX))
        u_ex[:, 0] = 1.0
        vel = np.zeros((n, self.strip_z.size, 2))
        lc = self.case
        if lc is not None and lc.hs > 0:
            w = synthesize_waves(lc.hs, lc.tp, lc.gamma, lc.wave_dir_deg, duration, self.dt_int,
                                 seed=int(wave_ss.generate_state(1)[0]), n_strips=N_STRIPS)
            u_ex[:, INPUT_BLOCKS["wave"]] = w.excitation[:n]
            u_ex[:, INPUT_BLOCKS["elev"].start] = w.elevation[:n]
            vel = np.ascontiguousarray(w.velocity[:n])
        if lc is not None and lc.wind_speed > 0:
            wd = synthesize_wind(lc.wind_speed, lc.turbulence_intensity, duration, self.dt_int,
                                 seed=int(wind_ss.generate_state(1)[0]))
            u_ex[:, INPUT_BLOCKS["wind"].start] = wd.rotor_effective[:n] - lc.wind_speed
            u_ex[:, INPUT_BLOCKS["hub_wind"].start] = wd.hub[:n]
        psi0 = float(np.random.default_rng(psi_ss).uniform(0.0, 2.0 * np.pi))
        return np.ascontiguousarray(u_ex), vel, psi0

    def exogenous(self, u_ex: np.ndarray) -> np.ndarray:
        """Contribution of the exogenous inputs (first-order hold) to each next state, shape (n_steps, 22)."""
        return np.ascontiguousarray(u_ex[:-1] @ self.g_ex0.T + u_ex[1:] @ self.g_ex1.T)

    def outputs(self, x_hist: np.ndarray, u_ex_out: np.ndarray, u_hist: np.ndarray) -> np.ndarray:
        """Channel values ``C x + D u`` from stored states and inputs (n, 45)."""
        return x_hist @ self.cy.T + u_ex_out @ self.dy[:, :N_EX].T + u_hist @ self.dy[:, N_EX:].T

    def add_noise(self, y: np.ndarray, seed_sequence: np.random.SeedSequence) -> np.ndarray:
        """Add white + AR(1) coloured sensor noise (model.noise) to outputs ``y`` (n, 45)."""
        white, col = self.model.noise.std(list(ALL_CHANNELS))
        if not np.any(white) and not np.any(col):
            return y
        rng = np.random.default_rng(seed_sequence)
        n = y.shape[0]
        out = y + rng.standard_normal(y.shape) * white
        if np.any(col):
            from scipy.signal import lfilter

            a = math.exp(-self.dt / max(self.model.noise.correlation_time, 1e-9))
            e = rng.standard_normal(y.shape) * col * math.sqrt(1.0 - a * a)
            colored = lfilter([1.0], [1.0, -a], e, axis=0)
            out += colored
        assert out.shape[0] == n
        return out


def simulate(
    model: FOWTModel,
    case: int | LoadCase | None,
    duration: float = 600.0,
    dt: float = 0.0125,
    seed: int | Sequence[int] = 0,
    *,
    transient: float = 60.0,
    noise: bool = True,
    return_truth: bool = False,
) -> Record | list[Record]:
    """Simulate the surrogate under a load case and return its 45 sensor channels.

    Parameters
    ----------
    model : FOWTModel
        The model (its effects, rotor harmonics and sensor noise).
    case : int or LoadCase or None
        OLC number (1-12), a :class:`LoadCase`, or None (parked, still water, no wind).
    duration : float
        Length of the returned record (s).
    dt : float
        Sample time (s); default 0.0125 s (80 Hz, as the paper's data).
    seed : int or sequence of int
        Seed of waves, wind, rotor azimuth and noise. A sequence simulates one record per seed (in parallel
        threads on all cores) and returns a list; each record equals the single-seed run bit for bit.
    transient : float
        Simulated time discarded before the record starts (s), so that the start-up from the static
        equilibrium has decayed.
    noise : bool
        Add the model's sensor noise (:class:`surrogates.SensorNoise`).
    return_truth : bool
        If True, return ``(noisy, truth)`` pairs: the noise-free record alongside (a list of pairs for a batch).

    Returns
    -------
    Record or list of Record
        Channels :data:`surrogates.channels.ALL_CHANNELS` in OpenFAST units; ``meta`` holds the load case,
        seed, dt, effects and model settings.

    Raises
    ------
    ValueError
        Non-positive or non-finite duration/dt/transient, dt too large, a bad case or model.
    """
    duration = check_number("duration", duration, positive=True)
    if not np.isfinite(transient) or transient < 0:
        raise ValueError(f"transient must be finite and >= 0 (s), got {transient!r}")
    batch = not np.isscalar(seed)
    seeds = [int(s) for s in (seed if batch else [seed])]  # type: ignore[union-attr]
    if any(s < 0 for s in seeds):
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    sim = Simulator(model, case, dt)
    n_out = int(round(duration / sim.dt))
    if n_out < 2:
        raise ValueError(f"duration={duration} s is shorter than two samples of dt={sim.dt} s")
    n_skip = int(round(transient / sim.dt))
    n_steps = (n_out + n_skip) * sim.substeps
    seqs = [np.random.SeedSequence(s) for s in seeds]
    children = [sq.spawn(2) for sq in seqs]  # forcing, noise
    n_rec = n_out + n_skip
    out_steps = np.arange(n_skip, n_rec) * sim.substeps

    def run_one(forcing_seq: np.random.SeedSequence) -> np.ndarray:
        u_ex, vel, psi0 = sim.forcing(n_steps, forcing_seq)
        x = sim.x_eq.copy()
        x_hist = np.zeros((n_rec, N_STATE))
        u_hist = np.zeros((n_rec, N_INPUT - N_EX))
        _advance(x, psi0, 0, n_steps, sim.substeps, sim.phi, sim.g_rest, sim.exogenous(u_ex), np.zeros(2), vel,
                 sim.strip_z, sim.drag_coef, sim.moor_r, sim.moor_h, sim.moor_v, sim.moor_k, sim.zf, sim.s_moor,
                 sim.harm, sim.e_s, sim.dt_int, x_hist, u_hist, 0)
        return sim.outputs(x_hist[n_skip:], u_ex[out_steps], u_hist[n_skip:])

    # FFT synthesis, the compiled stepper (nogil) and BLAS all release the GIL: a batch runs on threads
    if len(seeds) == 1:
        y_outs = [run_one(children[0][0])]
    else:
        with ThreadPoolExecutor(max_workers=min(len(seeds), os.cpu_count() or 1)) as pool:
            y_outs = list(pool.map(lambda ch: run_one(ch[0]), children))
    lc = sim.case
    t = np.arange(n_out) * sim.dt
    out: list = []
    for s, ch, truth in zip(seeds, children, y_outs, strict=True):
        if not np.all(np.isfinite(truth)):
            raise FloatingPointError("simulation diverged (non-finite outputs); please report this case and seed")
        meta = {
            "source": "surrogates.simulate",
            "case": lc.to_dict() if lc is not None else None,
            "seed": s,
            "dt": sim.dt,
            "transient": float(transient),
            "model": model.to_dict(),
            "noise": bool(noise),
        }
        noisy = sim.add_noise(truth, ch[1]) if noise else truth
        rec = Record(t, noisy, list(ALL_CHANNELS), [UNITS[c] for c in ALL_CHANNELS], meta)
        if return_truth:
            out.append((rec, Record(t, truth, list(ALL_CHANNELS), [UNITS[c] for c in ALL_CHANNELS],
                                    {**meta, "noise": False})))
        else:
            out.append(rec)
    return out if batch else out[0]

