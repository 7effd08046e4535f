"""Replay a measured record through the surrogate and score it sample by sample, against the linear bound.

:func:`replay_record` drives :func:`surrogates.simulate` with a record's measured wave elevation (``Wave1Elev``)
and wind (its ``Wind1VelX``, or a richer wind given beside it: an OpenFAST reference ``*.inflow.npz`` or a
TurbSim ``.bts`` full field), under the record's own conditions (a ``<run>.case.json`` sidecar, else estimated
from the record), starting from the record's first sample (platform position, tower-top deflection, rotor speed).

:func:`replay_scores` compares the replay with the record channel by channel and band by band:

* ``r2``: the coefficient of determination of the surrogate's series against the record's, after both are
  band-passed (zero-phase FFT mask) and their own means removed, ``1 - sum (y - y_hat)^2 / sum (y - mean y)^2``;
* ``bound``: the fraction of the record's variance in the band that is linearly explained by the two inputs,
  wave elevation and rotor-averaged wind: the **multiple coherence** ``gamma^2(f) = S_yx S_xx^-1 S_xy / S_yy``
  (Welch cross-spectra of the record itself, :func:`multiple_coherence`) averaged over the band with weights
  ``S_yy`` (:func:`coherence_bound`). A model driven by these inputs cannot exceed it with linear dynamics; a
  nonlinear model may.

Examples
--------
>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> x = rng.standard_normal((20000, 2))
>>> y = x[:, 0] + 0.5 * x[:, 1] + 0.5 * rng.standard_normal(20000)
>>> round(coherence_bound(y, x, fs=10.0, band=(0.0, 5.0), segment_s=100.0), 1)   # 1.25 / 1.5
0.8
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal

__all__ = [
    "INITIAL_FIT_S",
    "REPLAY_BANDS",
    "REPLAY_CHANNELS",
    "ReplayScore",
    "band_pass",
    "band_r2",
    "coherence_bound",
    "inflow_rotor_wind",
    "multiple_coherence",
    "record_case",
    "record_initial",
    "replay_initial_state",
    "replay_record",
    "replay_scores",
    "scores_table",
]

REPLAY_BANDS: dict[str, tuple[float, float]] = {"wave": (0.05, 0.25), "0-1 Hz": (0.0, 1.0)}
"""Bands (Hz) in which replays are scored: the wave band and everything up to 1 Hz."""

REPLAY_CHANNELS: tuple[str, ...] = ("PtfmSurge", "PtfmHeave", "PtfmPitch", "TwrBsMyt", "TwHt9ALxt", "RotSpeed",
                                    "BldPitch1")
"""Channels scored by default (issue 16's list)."""

SEGMENT_S = 100.0
"""Welch segment length (s) of the coherence bound: 0.01 Hz resolution, ~10 averages over a 600 s record."""

ROTOR_INITIAL_CHANNELS: tuple[str, ...] = ("RotSpeed", "Azimuth", "BldPitch1", "GenTq")
"""Initial conditions of the rotor and its controller: dropped when the load case is parked."""

_INITIAL_CHANNELS = ("PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw", "TTDspFA", "TTDspSS",
                     "RotSpeed", "Azimuth", "BldPitch1", "GenTq")


# -------------------------------------------------------------------------------------------- statistics
def _series(x: ArrayLike, name: str) -> NDArray[np.float64]:
    a = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} holds NaN or inf")
    return a


def band_pass(x: ArrayLike, fs: float, band: tuple[float, float]) -> NDArray[np.float64]:
    """Zero-phase band-pass by an FFT mask (``lo <= f <= hi``), mean removed (``fs`` in Hz, band in Hz)."""
    a = _series(x, "x")
    spec = np.fft.rfft(a - a.mean())
    f = np.fft.rfftfreq(a.size, 1.0 / fs)
    spec[(f < band[0]) | (f > band[1]) | (f == 0.0)] = 0.0
    return np.fft.irfft(spec, n=a.size)


def band_r2(reference: ArrayLike, model: ArrayLike, fs: float, band: tuple[float, float]) -> float:
    """R² of ``model`` against ``reference`` in a band (both band-passed, own means removed; -)."""
    r = band_pass(reference, fs, band)
    m = band_pass(model, fs, band)
    if r.shape != m.shape:
        raise ValueError(f"reference and model must have the same length, got {r.shape} and {m.shape}")
    sst = float(np.sum(r * r))
    return 1.0 - float(np.sum((r - m) ** 2)) / sst if sst > 0 else math.nan


def multiple_coherence(y: ArrayLike, inputs: ArrayLike, fs: float, segment_s: float = SEGMENT_S
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Multiple coherence of ``y`` with the columns of ``inputs`` (Welch, Hann, 50 % overlap).

    ``gamma^2(f) = S_yx(f) S_xx(f)^-1 S_xy(f) / S_yy(f)``, the fraction of the power of ``y`` at ``f`` that a
    linear time-invariant system driven by the inputs can explain.

    Parameters
    ----------
    y : array_like (n,)
    inputs : array_like (n, m)
    fs : float
        Sample rate (Hz).
    segment_s : float
        Welch segment (s).

    Returns
    -------
    f (Hz), gamma2 (-), S_yy (one-sided PSD of y)
    """
    yy = _series(y, "y")
    xx = _series(inputs, "inputs")
    if xx.ndim == 1:
        xx = xx[:, None]
    if xx.shape[0] != yy.size:
        raise ValueError(f"inputs have {xx.shape[0]} samples, y has {yy.size}")
    nper = min(yy.size, int(round(segment_s * fs)))
    kw = {"fs": fs, "nperseg": nper, "detrend": "constant"}
    m = xx.shape[1]
    f, s_yy = signal.welch(yy, **kw)
    s_xx = np.empty((f.size, m, m), dtype=complex)
    s_xy = np.empty((f.size, m), dtype=complex)
    for i in range(m):
        for j in range(m):
            s_xx[:, i, j] = signal.csd(xx[:, i], xx[:, j], **kw)[1]
        s_xy[:, i] = signal.csd(xx[:, i], yy, **kw)[1]
    g = np.zeros(f.size)
    ok = s_yy > 0
    sol = np.linalg.solve(s_xx[ok] + 1e-30 * np.eye(m), s_xy[ok][..., None])[..., 0]
    g[ok] = np.real(np.einsum("fi,fi->f", np.conj(s_xy[ok]), sol)) / s_yy[ok]
    return f, np.clip(g, 0.0, 1.0), s_yy


def coherence_bound(y: ArrayLike, inputs: ArrayLike, fs: float, band: tuple[float, float],
                    segment_s: float = SEGMENT_S) -> float:
    """Share of the variance of ``y`` in ``band`` (Hz) linearly explained by ``inputs``: the ``S_yy``-weighted
    band average of :func:`multiple_coherence` (-), the R² a linear model driven by the inputs can reach."""
    f, g, s = multiple_coherence(y, inputs, fs, segment_s)
    sel = (f >= band[0]) & (f <= band[1]) & (f > 0)
    tot = float(np.sum(s[sel]))
    return float(np.sum(g[sel] * s[sel]) / tot) if tot > 0 else math.nan


# --------------------------------------------------------------------------------------------- the replay
def record_case(record: Any, case: Mapping[str, Any] | None = None) -> Any:
    """The surrogate's load case for a measured record: its ``case.json`` content when given (wind speed
    replaced by the record's mean ``Wind1VelX``, the linearisation point), else estimated from the record
    (mean hub wind, Hs = 4 std and Tp of ``Wave1Elev``, IEC class B turbulence)."""
    from surrogates.replay import sea_state

    from .validation import surrogate_case

    c: dict[str, Any] = dict(case or {})
    c.pop("initial", None)
    if "Wind1VelX" in record.channels:
        c["wind_speed"] = float(np.mean(record["Wind1VelX"]))
    if not c.get("hs") and "Wave1Elev" in record.channels:
        c["hs"], c["tp"] = sea_state(record.t, record["Wave1Elev"])
    c.setdefault("name", "replay")
    return surrogate_case(c)


_RATE_OF = {"PtfmSurge": "PtfmTVxi", "PtfmSway": "PtfmTVyi", "PtfmHeave": "PtfmTVzi", "PtfmRoll": "PtfmRVxi",
            "PtfmPitch": "PtfmRVyi", "PtfmYaw": "PtfmRVzi"}
"""The platform DOFs' rate channels (ElastoDyn names; m/s and deg/s)."""

RATE_FIT_S = 2.0
"""Window (s) of the quadratic fit that estimates a platform rate at a record's first sample."""


def _initial_rate(t: NDArray[np.float64], x: NDArray[np.float64]) -> float | None:
    """Rate at ``t[0]`` from a least-squares quadratic over the first ``RATE_FIT_S`` seconds (None if too short)."""
    sel = t <= t[0] + RATE_FIT_S
    if np.count_nonzero(sel) < 5:
        return None
    tt = t[sel] - t[0]
    return float(np.polyfit(tt, x[sel], 2)[1])


def record_initial(record: Any) -> dict[str, float]:
    """Initial conditions (OpenFAST names and units) from a record's first sample: platform DOFs, tower-top
    deflections, rotor speed and azimuth, the controller's pitch and generator torque (a controller started from
    its steady state instead drifts by half a revolution of azimuth in the first 50 s of OpenFAST's 18 m/s run,
    which no later sample recovers), those the record has, and the platform DOFs' rates -- the record's
    ``PtfmTVxi`` ... ``PtfmRVzi`` if it has them, else the slope of a quadratic fitted to the first
    :data:`RATE_FIT_S` seconds of the position. Without the rates a replay would start the slow modes from rest:
    the 124 s surge mode then takes minutes to forget it (OpenFAST's 18 m/s run: surge R² over 200-450 s -1.5)."""
    out = {c: float(record[c][0]) for c in _INITIAL_CHANNELS if c in record.channels}
    t = np.asarray(record.t, float)
    for pos, rate in _RATE_OF.items():
        if rate in record.channels:
            out[rate] = float(record[rate][0])
        elif pos in record.channels:
            r = _initial_rate(t, np.asarray(record[pos], float))
            if r is not None and math.isfinite(r):
                out[rate] = r
    return out


def _sidecar(path: Path, suffix: str) -> Path | None:
    name = path.name
    for ext in (".outb", ".out", ".npz", ".csv", ".parquet"):
        if name.lower().endswith(ext):
            cand = path.with_name(name[: -len(ext)] + suffix)
            return cand if cand.is_file() else None
    return None


INITIAL_FIT_S = 100.0
"""Span (s) from a record's first sample over which ``initial="fit"`` fits the platform's initial state."""

_FIT_STEPS = {"PtfmSurge": (0.2, 0.01), "PtfmSway": (0.05, 0.005), "PtfmHeave": (0.02, 0.005),
              "PtfmRoll": (0.02, 0.005), "PtfmPitch": (0.05, 0.01), "PtfmYaw": (0.02, 0.005)}
"""Finite-difference steps of each platform DOF's position (m, deg) and rate (m/s, deg/s) in the fit."""


@dataclass(frozen=True)
class _ReplayInputs:
    record: Any
    case: Any
    model: Any
    waves: Any
    wind: Any
    azimuth: Any


def _replay_inputs(record: Any, case: Mapping[str, Any] | None, wind: Any, model: Any,
                   measured_azimuth: bool) -> _ReplayInputs:
    """The record, load case, model and measured inputs of a replay (see :func:`replay_record`)."""
    import surrogates
    from surrogates.replay import MeasuredWaves, MeasuredWind, record_wind_plane

    from .io import load_record

    src: Path | None = None
    if isinstance(record, str | os.PathLike):
        src = Path(record)
        record = load_record(src, unknown_channels="keep")
    if case is None and src is not None:
        cj = _sidecar(src, ".case.json")
        case = json.loads(cj.read_text(encoding="utf-8")) if cj else None
    if wind is None and src is not None:
        wind = _sidecar(src, ".inflow.npz")
    if isinstance(wind, str | os.PathLike):
        p = Path(wind)
        if p.suffix.lower() == ".bts":
            from .turbsim import measured_wind_from_bts

            wind = measured_wind_from_bts(p)
        else:
            wind = MeasuredWind.from_inflow(p)
    lc = record_case(record, case)
    if model is None:
        model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS)
    waves_in = MeasuredWaves.from_record(record) if "Wave1Elev" in record.channels and lc.hs > 0 else None
    wind_in = wind
    if wind_in is None and "Wind1VelX" in record.channels and lc.wind_speed > 0:
        # a run declared with a power-law shear (a steady-wind run's case.json, InflowWind's PLExp) and no field:
        # the hub wind spread over the disc by that profile, as its rotor met it (the mean tilt and yaw moments)
        alpha = float((case or {}).get("shear_exponent") or 0.0)
        if alpha > 0:
            wind_in = MeasuredWind.from_hub_sheared(
                np.asarray(record.t), np.asarray(record["Wind1VelX"]), shear_exponent=alpha,
                x_ref=record_wind_plane(getattr(record, "meta", None)),
                source=f"record channel Wind1VelX, power-law shear {alpha:g}")
        else:
            wind_in = MeasuredWind.from_record(record)
    if waves_in is None and wind_in is None:
        raise ValueError("the record has neither a wave elevation (Wave1Elev) nor a wind (Wind1VelX) to replay")
    # the rotor's measured azimuth places the blades in the field (a rotor speed 0.1 % off drifts 3P by ~90° in
    # ten minutes); parked, the harmonics are off anyway
    az = record if measured_azimuth and "Azimuth" in record.channels and lc.wind_speed > 0 else None
    return _ReplayInputs(record, lc, model, waves_in, wind_in, az)


def _run(inp: _ReplayInputs, init: dict[str, float] | None, *, dt: float, seed: int, transient: float,
         duration: float | None = None, on_progress: Callable[[float], None] | None = None) -> Any:
    import surrogates

    if init and inp.case.wind_speed <= 0:
        init = {k: v for k, v in init.items() if k not in ROTOR_INITIAL_CHANNELS}
    return surrogates.simulate(inp.model, inp.case, duration, dt=dt, seed=seed, transient=transient, noise=False,
                               initial=init or None, waves=inp.waves, wind=inp.wind, azimuth=inp.azimuth,
                               on_progress=on_progress)


def _fit_initial(inp: _ReplayInputs, base: dict[str, float], span: float, seed: int) -> dict[str, float]:
    """Gauss-Newton on the platform's initial positions and rates from the record's first sample and its slopes:
    the replay's platform series against the record's over ``span`` seconds, each channel scaled by its std there
    and its mean misfit removed (a model's steady offset, e.g. the mean yaw, is no initial-state error and would
    otherwise pull every other DOF); up to three iterations, a step kept only if it lowers the misfit."""
    rec = inp.record
    t = np.asarray(rec.t, float)
    span = float(min(span, t[-1] - t[0]))
    channels = [c for c in _FIT_STEPS if c in rec.channels]
    if not channels or span < 10.0:
        return base
    sel = np.flatnonzero(t <= t[0] + span)[:: max(1, int(round(0.5 / float(rec.dt))))]  # ~2 Hz
    ref = np.column_stack([np.asarray(rec[c], float)[sel] for c in channels])
    scale = np.maximum(ref.std(axis=0), np.array([_FIT_STEPS[c][0] for c in channels]))
    params = [(c, _FIT_STEPS[c][0]) for c in channels] + [(_RATE_OF[c], _FIT_STEPS[c][1]) for c in channels]

    def residual(init: dict[str, float]) -> NDArray[np.float64]:
        sim = _run(inp, init, dt=0.05, seed=seed, transient=0.0, duration=span)
        st = np.asarray(sim.t, float)
        mod = np.column_stack([np.interp(t[sel], st, np.asarray(sim[c], float)) for c in channels])
        err = mod - ref
        return ((err - err.mean(axis=0)) / scale).ravel()

    best = dict(base)
    r_best = residual(best)
    for _ in range(3):
        jac = np.empty((r_best.size, len(params)))
        for j, (name, step) in enumerate(params):
            trial = dict(best)
            trial[name] = trial.get(name, 0.0) + step
            jac[:, j] = (residual(trial) - r_best) / step
        col = np.maximum(np.linalg.norm(jac, axis=0), 1e-12)
        delta = np.linalg.lstsq(jac / col, -r_best, rcond=1e-6)[0] / col
        trial = dict(best)
        for (name, _), d in zip(params, delta, strict=True):
            trial[name] = trial.get(name, 0.0) + float(d)
        r_trial = residual(trial)
        if float(r_trial @ r_trial) >= float(r_best @ r_best):
            break
        best, r_best = trial, r_trial
    return best


def replay_initial_state(record: Any, *, case: Mapping[str, Any] | None = None, wind: Any = None, model: Any = None,
                         span: float = INITIAL_FIT_S, seed: int = 0, measured_azimuth: bool = True
                         ) -> dict[str, float]:
    """The platform's initial state that makes a replay follow a record from its first sample.

    A record that starts inside a run (a field measurement, OpenFAST's output after its start-up) gives the
    platform's positions and, from their slopes, its rates at the first sample (:func:`record_initial`), but not
    the sea's history before it: the replay's wave loads and radiation memory start cold, and the slow modes (the
    OC3 spar's 120 s surge and 30 s heave and pitch, lightly damped) ring for minutes with what that start puts in
    them (OpenFAST's steady-wind run replayed from its first sample: 1.5x OpenFAST's surge below 0.05 Hz 100-300 s
    later). This estimates the initial positions and rates of the platform DOFs the record has by least squares:
    the replay's platform series against the record's over the first `span` seconds (a smoother of the initial
    state, Gauss-Newton with finite differences, up to 3 x 12 short replays, each channel's mean misfit removed).
    Everything after `span` is untouched by the fit, so a replay that discards its first `span` seconds is scored
    out of sample.

    Parameters
    ----------
    record, case, wind, model, seed, measured_azimuth
        As :func:`replay_record`.
    span : float
        Fitted span (s), >= 10 (shorter records: their length).

    Returns
    -------
    dict
        Initial conditions (OpenFAST names and units) for ``replay_record(initial=...)``: :func:`record_initial`
        with the platform's positions and rates refined.
    """
    if not (np.isfinite(span) and span > 0):
        raise ValueError(f"span must be a positive number of seconds, got {span!r}")
    inp = _replay_inputs(record, case, wind, model, measured_azimuth)
    return _fit_initial(inp, record_initial(inp.record), span, seed)


def replay_record(record: Any, *, case: Mapping[str, Any] | None = None, wind: Any = None, model: Any = None,
                  transient: float = 100.0, dt: float = 0.025, initial: bool | str | Mapping[str, float] = True,
                  seed: int = 0,
                  measured_azimuth: bool = True, on_progress: Callable[[float], None] | None = None) -> Any:
    """Simulate the surrogate under a record's measured waves and wind.

    Parameters
    ----------
    record : surrogates.Record or path
        A record with ``Wave1Elev`` (m) and/or ``Wind1VelX`` (m/s); a path is read with
        :func:`fowt_env.io.load_record`, and a ``<run>.case.json`` and ``<run>.inflow.npz`` beside it are used.
    case : mapping, optional
        The run's conditions (``case.json`` keys); default the sidecar, else estimated (:func:`record_case`).
    wind : surrogates.replay.MeasuredWind or path, optional
        A richer wind than the record's ``Wind1VelX``: a ``MeasuredWind``, an ``*.inflow.npz`` (polar field) or a
        TurbSim ``.bts`` (full field). Default: the inflow sidecar if there is one, else ``Wind1VelX``.
    model : surrogates.FOWTModel, optional
        Default: the model with OpenFAST's gauge heights, no sensor noise.
    transient : float
        Start-up discarded (s).
    dt : float
        Output sample time (s).
    initial : bool, "fit" or mapping
        True: start from the record's first sample (:func:`record_initial`); ``"fit"``: from the platform state
        fitted over the record's first ``min(transient, INITIAL_FIT_S)`` seconds (:func:`replay_initial_state`;
        with ``transient`` >= that span the returned record is out of sample); False: from the static
        equilibrium; a mapping: these initial conditions (OpenFAST names and units, as
        ``surrogates.simulate(initial=...)``), e.g. a deck's ElastoDyn initial conditions for a record that starts
        at its run's t = 0, or :func:`replay_initial_state`'s.
    seed : int
        Seeds only the rotor's initial azimuth (when the record has no ``Azimuth``).
    measured_azimuth : bool
        Replay the record's ``Azimuth`` channel, if it has one, as the blades' position in the wind field and
        the phase of the 3P/6P loads (``surrogates.simulate(azimuth=...)``); False: the simulated rotor's own.
    on_progress : callable, optional
        Progress hook of :func:`surrogates.simulate` (simulated seconds just integrated; about the record's
        length in all).

    Returns
    -------
    surrogates.Record
        Noise-free; time stamps on the record's own axis, from ``record.t[0] + transient``.
    """
    inp = _replay_inputs(record, case, wind, model, measured_azimuth)
    if isinstance(initial, Mapping):
        init: dict[str, float] | None = {str(k): float(v) for k, v in initial.items()}
    elif isinstance(initial, str):
        if initial != "fit":
            raise ValueError(f"initial must be True, False, 'fit' or a mapping, got {initial!r}")
        span = min(float(transient), INITIAL_FIT_S) if transient > 0 else INITIAL_FIT_S
        init = _fit_initial(inp, record_initial(inp.record), span, seed)
    else:
        init = record_initial(inp.record) if initial else None
    return _run(inp, init, dt=dt, seed=seed, transient=transient, on_progress=on_progress)


def inflow_rotor_wind(path: str | os.PathLike[str]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The disc-averaged wind ``(t, u)`` (s, m/s) of an OpenFAST reference ``*.inflow.npz``: the rotor-averaged
    input of the coherence bound (``replay_scores(..., rotor_wind=...)``)."""
    with np.load(path, allow_pickle=False) as z:
        return np.asarray(z["t"], float), np.asarray(z["disc_mean_u"], float)


@dataclass
class ReplayScore:
    """Replay against a record for one channel and band: R² and its linear bound (see the module docstring)."""

    channel: str
    band: str
    r2: float
    bound: float
    reference_std: float
    model_std: float
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"channel": self.channel, "band": self.band, "r2": self.r2, "bound": self.bound,
                "reference_std": self.reference_std, "model_std": self.model_std, **self.extra}


def _on_grid(t_src: NDArray[np.float64], x: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.interp(t, t_src, x)


def replay_scores(reference: Any, replay: Any, rotor_wind: tuple[ArrayLike, ArrayLike] | None = None,
                  channels: Sequence[str] = REPLAY_CHANNELS,
                  bands: Mapping[str, tuple[float, float]] | None = None, segment_s: float = SEGMENT_S,
                  ) -> list[ReplayScore]:
    """Score a replay against its reference record over the replay's time span.

    Parameters
    ----------
    reference, replay : surrogates.Record
        The measured record and :func:`replay_record`'s output (same time axis, any rates).
    rotor_wind : (t, u), optional
        Rotor-averaged wind (s, m/s) for the bound; default the reference's ``Wind1VelX``.
    channels, bands, segment_s
        What to score (default :data:`REPLAY_CHANNELS`, :data:`REPLAY_BANDS`) and the Welch segment (s).

    Returns
    -------
    list of ReplayScore
    """
    bands = dict(REPLAY_BANDS if bands is None else bands)
    t = np.asarray(replay.t, float)
    fs = 1.0 / float(np.median(np.diff(t)))
    if t[0] < reference.t[0] - 1e-6 or t[-1] > reference.t[-1] + 1e-6:
        raise ValueError("the replay reaches outside the reference record's time span")
    rt = np.asarray(reference.t, float)
    elev = _on_grid(rt, np.asarray(reference["Wave1Elev"], float), t)
    if rotor_wind is None:
        wind = _on_grid(rt, np.asarray(reference["Wind1VelX"], float), t)
    else:
        wind = np.interp(t, np.asarray(rotor_wind[0], float), np.asarray(rotor_wind[1], float))
    inputs = np.column_stack([elev, wind]) if np.std(wind) > 1e-9 else elev[:, None]
    out: list[ReplayScore] = []
    for ch in channels:
        if ch not in reference.channels or ch not in replay.channels:
            continue
        y = _on_grid(rt, np.asarray(reference[ch], float), t)
        m = np.asarray(replay[ch], float)
        for name, band in bands.items():
            out.append(ReplayScore(ch, name, band_r2(y, m, fs, band), coherence_bound(y, inputs, fs, band, segment_s),
                                   float(np.std(band_pass(y, fs, band))), float(np.std(band_pass(m, fs, band))),
                                   {"reference_mean": float(np.mean(y)), "model_mean": float(np.mean(m))}))
    return out


def scores_table(scores: Sequence[ReplayScore], run: str = "") -> str:
    """Markdown table: per channel, R² and bound per band, and whether R² >= 0.85 x bound."""
    bands = list(dict.fromkeys(s.band for s in scores))
    head = "| run | channel | " + " | ".join(f"R² {b} | bound {b}" for b in bands) + " |"
    lines = [head, "|" + "---|" * (2 + 2 * len(bands))]
    by: dict[str, dict[str, ReplayScore]] = {}
    for s in scores:
        by.setdefault(s.channel, {})[s.band] = s
    for ch, d in by.items():
        cells = []
        for b in bands:
            s = d.get(b)
            if s is None or not np.isfinite(s.bound):
                cells += ["—", "— (constant)" if s is not None else "—"]
                continue
            ok = s.r2 >= 0.85 * s.bound
            cells += [f"{s.r2:.2f}{'' if ok else ' ✗'}", f"{s.bound:.2f}"]
        lines.append(f"| {run} | {ch} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
