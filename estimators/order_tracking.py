"""Computed order tracking: rotor harmonics found by Hankel-DMD on data resampled at equal rotor-azimuth steps.

A rotor harmonic (1P, 3P, 6P) is locked to the rotor azimuth ``psi(t)``, not to time: a load ``cos(3 psi)``
under a rotor speed that wanders with the turbulence is a *smeared* band in the time domain. Over 30 minutes
of near-rated turbulent wind the NREL 5 MW rotor speed varies by a few rpm and its 3P line spreads over
±0.1 Hz (the seed paper's "controller-induced frequency shifts", Section 4); a time-domain DMD then fits it
with several damped modes, none of which is an undamped phase-locked line, and such bands are not
*harmonics* by any test on time-domain lines.

Resampling the record at equal azimuth increments (computed order tracking, Fyfe & Munck 1997; Blough 2003)
turns every rotor-locked component back into a line at a fixed *order* (cycles per revolution), while the
structural modes, which keep their frequency in time, are smeared instead. Hankel-DMD of the resampled data
then finds the harmonics as undamped, phase-locked lines that are stable over delays
(:func:`~estimators.hankel_dmd.harmonic_candidates`).

The resampled data are given an *equivalent* sample interval ``dt_eq = d_psi / mean_speed``, so that an
identified line's frequency is in Hz at the record's mean rotor speed (``order * mean 1P``).

References
----------
Fyfe, K. R. & Munck, E. D. S. (1997). Analysis of computed order tracking. Mechanical Systems and Signal
Processing 11(2), 187-205.
Blough, J. R. (2003). A survey of DSP methods for rotating machinery analysis, what is needed, what is
available. Journal of Sound and Vibration 262(3), 707-720.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from .hankel_dmd import harmonic_candidates
from .validation import MAX_ABS, as_2d_float, check_number

__all__ = ["AngleDomainData", "resample_to_azimuth", "rotor_azimuth", "rotor_harmonics"]


def rotor_azimuth(rotor_speed: object, dt: float) -> np.ndarray:
    """Rotor azimuth integrated from the rotor speed (trapezoidal rule), starting at 0.

    Parameters
    ----------
    rotor_speed : array_like (n_samples,)
        Rotor speed (rad/s), finite and > 0 at every sample (a turning rotor).
    dt : float
        Sample interval (s).

    Returns
    -------
    ndarray (n_samples,)
        Unwrapped azimuth (rad), strictly increasing.

    Raises
    ------
    ValueError
        Not 1-D, fewer than 2 samples, non-finite values, or a speed <= 0 (a parked, idling-through-zero or
        reversing rotor has no order domain).
    """
    dt = check_number("dt", dt, positive=True)
    w = np.asarray(rotor_speed, dtype=float)
    if w.ndim != 1 or w.size < 2:
        raise ValueError(f"rotor_speed must be 1-D with at least 2 samples, got shape {w.shape}")
    bad = np.flatnonzero(~np.isfinite(w))
    if bad.size:
        raise ValueError(f"rotor_speed must be finite: NaN/inf at samples {bad[:5].tolist()}"
                         f"{' ...' if bad.size > 5 else ''}")
    slow = np.flatnonzero(w <= 0.0)
    if slow.size:
        raise ValueError(
            f"rotor_speed must be > 0 rad/s at every sample (a turning rotor) for order tracking; it is <= 0 at "
            f"{slow.size} samples, first {slow[:5].tolist()}"
        )
    return np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * dt)])


@dataclass(frozen=True)
class AngleDomainData:
    """A record resampled at equal rotor-azimuth steps.

    Attributes
    ----------
    y : ndarray (n_samples, n_channels)
        The channels at azimuths ``azimuth`` (same units as the input).
    azimuth : ndarray (n_samples,)
        Rotor azimuth of each sample (rad from the record's first sample), uniform.
    dt : float
        Equivalent sample interval (s): azimuth step / mean rotor speed. A component at order ``k`` (cycles per
        revolution) appears at ``k * mean_speed / (2 pi)`` Hz.
    mean_speed : float
        Mean rotor speed over the record (rad/s): total azimuth / duration.
    speed_percentiles_hz : tuple of float
        5th and 95th percentiles of the rotor frequency (Hz) over the record: an order-``k`` harmonic sweeps
        ``k`` times this range in the time domain.
    """

    y: np.ndarray
    azimuth: np.ndarray
    dt: float
    mean_speed: float
    speed_percentiles_hz: tuple[float, float]

    @property
    def rotor_frequency_hz(self) -> float:
        """Mean 1P frequency (Hz)."""
        return self.mean_speed / (2.0 * np.pi)


def _azimuth_input(n: int, dt: float, rotor_speed: object, azimuth: object) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (rad) and speed (rad/s) from exactly one of the two inputs, checked against ``n`` samples."""
    if (rotor_speed is None) == (azimuth is None):
        raise ValueError("give exactly one of rotor_speed (rad/s) or azimuth (rad, unwrapped)")
    if rotor_speed is not None:
        psi = rotor_azimuth(rotor_speed, dt)
        speed = np.asarray(rotor_speed, dtype=float)
    else:
        psi = np.asarray(azimuth, dtype=float)
        if psi.ndim != 1 or psi.size < 2 or not np.isfinite(psi).all():
            raise ValueError(f"azimuth must be a finite 1-D array, got shape {psi.shape}")
        step = np.diff(psi)
        if not (step > 0).all():
            raise ValueError(
                "azimuth must increase strictly (unwrapped, in rad: e.g. np.unwrap(np.deg2rad(Azimuth))); it "
                f"does not at {int(np.sum(step <= 0))} steps"
            )
        speed = np.gradient(psi, dt)
    if psi.size != n:
        raise ValueError(f"rotor speed / azimuth has {psi.size} samples, the data have {n}")
    return psi, speed


def resample_to_azimuth(
    Y: object, dt: float, *, rotor_speed: object = None, azimuth: object = None
) -> AngleDomainData:
    """Resample a record at equal rotor-azimuth increments (computed order tracking).

    The output has as many samples as the input, spread uniformly over the azimuth the rotor turned through;
    each channel is interpolated with a cubic spline in azimuth. Band-limit the data first (the local sample
    rate in azimuth changes with the speed): :func:`~estimators.preprocess` does.

    Parameters
    ----------
    Y : array_like (n_samples, n_channels)
        Finite data sampled every ``dt``.
    dt : float
        Sample interval (s).
    rotor_speed : array_like (n_samples,), optional
        Rotor speed (rad/s) at the same samples, > 0.
    azimuth : array_like (n_samples,), optional
        Unwrapped rotor azimuth (rad) instead of the speed, strictly increasing.

    Returns
    -------
    AngleDomainData

    Raises
    ------
    ValueError
        Bad shapes, non-finite values, a rotor that stops or reverses, or both/neither of ``rotor_speed`` and
        ``azimuth``.
    """
    dt = check_number("dt", dt, positive=True)
    Y = as_2d_float(Y, "Y", min_samples=4, max_abs=MAX_ABS)
    psi, speed = _azimuth_input(Y.shape[0], dt, rotor_speed, azimuth)
    n = Y.shape[0]
    grid = np.linspace(psi[0], psi[-1], n)
    y = CubicSpline(psi, Y, axis=0)(grid)
    d_psi = (psi[-1] - psi[0]) / (n - 1)
    mean_speed = (psi[-1] - psi[0]) / ((n - 1) * dt)
    lo, hi = np.percentile(speed, [5.0, 95.0]) / (2.0 * np.pi)
    return AngleDomainData(y=np.ascontiguousarray(y), azimuth=grid - psi[0], dt=float(d_psi / mean_speed),
                           mean_speed=float(mean_speed), speed_percentiles_hz=(float(lo), float(hi)))


def rotor_harmonics(
    Y: object,
    dt: float,
    *,
    rotor_speed: object = None,
    azimuth: object = None,
    delays: tuple[int, ...] = (45, 60, 75),
    rank: int | float | str = 24,
    harmonic_damping: float = 0.01,
    min_phase_locking: float = 0.8,
    freq_rtol: float = 0.01,
    components: int | None = 8,
) -> list[dict]:
    """Rotor-locked harmonics of a record: Hankel-DMD lines in the order domain.

    Resamples ``Y`` at equal azimuth steps (:func:`resample_to_azimuth`) and keeps the lines
    :func:`~estimators.hankel_dmd.harmonic_candidates` finds there: labelled ``"harmonic"`` (undamped and
    phase-locked, see :meth:`~estimators.HankelDMD.mode_table`) at every delay depth, at the same order.

    With more than ``components`` channels, the resampled data are first projected on their leading
    ``components`` principal components (unscaled, so each keeps its share of the variance). A rotor harmonic is
    common to the channels and lives in the leading components; the Hankel matrices then have
    ``components x delay`` rows instead of ``n_channels x delay``, and the cost grows with the record's length
    instead of with the cube of ``n_channels x delay`` (36 tower channels at 60 delays: a 2160-square Gram
    matrix per delay depth).

    Parameters
    ----------
    Y : array_like (n_samples, n_channels)
        Band-limited, finite data (z-scored channels give every channel a say).
    dt : float
        Sample interval (s).
    rotor_speed, azimuth : array_like (n_samples,)
        Exactly one: rotor speed (rad/s, > 0) or unwrapped azimuth (rad).
    delays : tuple of int
        Delay depths (samples of the resampled data) compared by :func:`harmonic_candidates`.
    rank : int, float or "auto"
        Hankel-DMD rank.
    harmonic_damping, min_phase_locking, freq_rtol : float
        Passed to :func:`harmonic_candidates`.
    components : int or None
        Principal components kept (default 8); None keeps every channel.

    Returns
    -------
    list of dict
        One row per harmonic, by order: ``order`` (cycles per revolution; 3.0 for blade passing on a
        three-bladed rotor), ``frequency_hz`` (at the mean rotor speed), ``frequency_range_hz`` (the order
        times the 5th-95th percentile rotor frequency: the band the line sweeps in time), ``damping_ratio``
        (largest ``|zeta|`` over the delays, in the order domain), ``phase_locking`` (smallest over the
        delays), ``energy`` (mean share of the order-domain fit) and ``kind`` = ``"harmonic"``.

    Examples
    --------
    A 3P load on a rotor whose speed wanders by ±10 %:

    >>> import numpy as np
    >>> dt, t = 0.05, np.arange(0, 600, 0.05)
    >>> w = 1.27 * (1 + 0.1 * np.sin(2 * np.pi * t / 97))
    >>> psi = rotor_azimuth(w, dt)
    >>> rng = np.random.default_rng(0)
    >>> Y = np.c_[np.cos(3 * psi), 0.5 * np.sin(3 * psi + 0.4)] + 0.1 * rng.standard_normal((t.size, 2))
    >>> [round(r["order"], 2) for r in rotor_harmonics(Y, dt, rotor_speed=w, rank=4)]
    [3.0]
    """
    ang = resample_to_azimuth(Y, dt, rotor_speed=rotor_speed, azimuth=azimuth)
    f1 = ang.rotor_frequency_hz
    lo, hi = ang.speed_percentiles_hz
    y = ang.y
    if components is not None:
        k = int(components)
        if k < 1:
            raise ValueError(f"components must be a positive integer or None, got {components!r}")
        if k < y.shape[1]:
            yc = y - y.mean(axis=0)
            _, vecs = np.linalg.eigh(yc.T @ yc)  # ascending: the last k are the leading components
            y = yc @ vecs[:, ::-1][:, :k]
    rows = []
    for line in harmonic_candidates(y, ang.dt, delays, rank, harmonic_damping=harmonic_damping,
                                    min_phase_locking=min_phase_locking, freq_rtol=freq_rtol):
        order = line["frequency_hz"] / f1
        rows.append({
            "order": float(order),
            "frequency_hz": float(line["frequency_hz"]),
            "frequency_range_hz": (float(order * lo), float(order * hi)),
            "damping_ratio": float(max(abs(z) for z in line["damping_ratios"])),
            "phase_locking": float(line["phase_locking"]),
            "energy": float(line["energy"]),
            "kind": "harmonic",
        })
    return rows
