"""Kaimal turbulence (IEC 61400-1) reduced to a hub-point wind and a rotor-effective wind.

The longitudinal wind at the hub follows the IEC Kaimal spectrum; the rotor-effective wind is its average over
the rotor disc, whose spectrum is ``H2(f) S(f)`` with ``H2`` the disc-averaged IEC exponential coherence, and
whose cross-spectrum with the hub point is ``G(f) S(f)``. Both series are synthesised together (a 2x2
Cholesky factor of the spectral matrix per frequency, random phases) by inverse FFT.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.fft import irfft, next_fast_len

from .validation import check_number

__all__ = ["kaimal_spectrum", "iec_turbulence_intensity", "rotor_averaging", "WindSeries", "synthesize_wind"]


def _lambda1(hub_height: float) -> float:
    """IEC 61400-1 ed. 3 longitudinal turbulence scale parameter (m)."""
    return 0.7 * hub_height if hub_height <= 60.0 else 42.0


def kaimal_spectrum(f_hz: np.ndarray, mean_speed: float, turbulence_intensity: float,
                    hub_height: float = 90.0) -> np.ndarray:
    """Longitudinal Kaimal spectrum of IEC 61400-1 ed. 3 (Annex B).

    ``S(f) = 4 sigma^2 (L/V) / (1 + 6 f L / V)^(5/3)`` with ``L = 8.1 Lambda_1`` and ``sigma = TI V``.

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz).
    mean_speed : float
        Mean wind speed at hub height (m/s), > 0.
    turbulence_intensity : float
        Longitudinal turbulence intensity (-), 0 <= TI < 1.
    hub_height : float
        Hub height (m).

    Returns
    -------
    ndarray
        Spectral density (m²/s²/Hz).
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    ti = check_number("turbulence_intensity", turbulence_intensity, nonneg=True)
    if ti >= 1:
        raise ValueError(f"turbulence_intensity must be < 1, got {turbulence_intensity!r}")
    length = 8.1 * _lambda1(check_number("hub_height", hub_height, positive=True))
    f = np.asarray(f_hz, dtype=float)
    sigma = ti * v
    return 4.0 * sigma**2 * (length / v) / (1.0 + 6.0 * np.abs(f) * length / v) ** (5.0 / 3.0)


def iec_turbulence_intensity(mean_speed: float, turbulence_class: str = "B") -> float:
    """Normal turbulence model of IEC 61400-1 ed. 3: ``sigma_1 = I_ref (0.75 V + 5.6)``, returned as sigma_1/V.

    Parameters
    ----------
    mean_speed : float
        Hub-height mean wind (m/s).
    turbulence_class : {"A", "B", "C"}
        I_ref = 0.16, 0.14, 0.12.
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    refs = {"A": 0.16, "B": 0.14, "C": 0.12}
    if turbulence_class not in refs:
        raise ValueError(f"turbulence_class must be one of {sorted(refs)}, got {turbulence_class!r}")
    return refs[turbulence_class] * (0.75 * v + 5.6) / v


def _disc_points(rotor_radius: float, n_rings: int = 8, n_az: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Equal-area quadrature points (y, z) on the rotor disc and their weights (sum 1)."""
    r_edges = rotor_radius * np.sqrt(np.linspace(0.0, 1.0, n_rings + 1))
    r = 0.5 * (r_edges[1:] + r_edges[:-1])
    pts = []
    for i, ri in enumerate(r):
        az = 2 * np.pi * (np.arange(n_az) + 0.5 * (i % 2)) / n_az
        pts.append(np.column_stack([ri * np.cos(az), ri * np.sin(az)]))
    p = np.vstack(pts)
    return p, np.full(len(p), 1.0 / len(p))


def rotor_averaging(f_hz: np.ndarray, mean_speed: float, rotor_radius: float = 63.0, hub_height: float = 90.0,
                    n_rings: int = 8, n_az: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Spectral reduction of disc-averaged wind under the IEC exponential coherence.

    ``Coh(r, f) = exp(-12 sqrt((f r / V)^2 + (0.12 r / L_c)^2))``, ``L_c = 8.1 Lambda_1``.

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz).
    mean_speed : float
        Mean wind (m/s).
    rotor_radius, hub_height : float
        (m).
    n_rings, n_az : int
        Quadrature resolution.

    Returns
    -------
    H2 : ndarray
        Auto-spectrum ratio of the rotor-averaged wind to the point wind (-).
    G : ndarray
        Cross-spectrum ratio of hub point and rotor average (-), in closed form.
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    lc = 8.1 * _lambda1(check_number("hub_height", hub_height, positive=True))
    f = np.asarray(f_hz, dtype=float)
    p, w = _disc_points(check_number("rotor_radius", rotor_radius, positive=True), n_rings, n_az)
    dist = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
    # a point's own cell: use the mean distance between two random points of a cell of equal area (~0.52 x its
    # side) instead of 0, so the quadrature does not leave a floor of 1/n_points at high frequency
    np.fill_diagonal(dist, 0.52 * np.sqrt(np.pi * rotor_radius**2 / len(p)))
    # evaluate on a log grid, interpolate (the functions are smooth)
    grid = np.concatenate([[0.0], np.logspace(-4, np.log10(max(f.max(initial=1.0), 1e-3)) + 0.01, 120)])
    h2 = np.empty(grid.size)
    ww = np.outer(w, w)
    for i, fi in enumerate(grid):
        coh = np.exp(-12.0 * np.sqrt((fi * dist / v) ** 2 + (0.12 * dist / lc) ** 2))
        h2[i] = float(np.sum(ww * coh))
    # hub point vs disc average: the coherence is exp(-a r) with r the distance from the centre, so the disc
    # average has the closed form (2 / (a R)^2) (1 - exp(-a R) (1 + a R))
    a_r = 12.0 * np.sqrt((np.abs(f) / v) ** 2 + (0.12 / lc) ** 2) * rotor_radius
    g_exact = 2.0 / a_r**2 * (1.0 - np.exp(-a_r) * (1.0 + a_r))
    return np.interp(np.abs(f), grid, h2), g_exact


@dataclass(frozen=True)
class WindSeries:
    """Longitudinal wind at the hub point and averaged over the rotor disc (m/s, mean included)."""

    t: np.ndarray
    hub: np.ndarray
    rotor_effective: np.ndarray
    frequencies_hz: np.ndarray
    meta: dict = field(default_factory=dict)


def synthesize_wind(
    mean_speed: float,
    turbulence_intensity: float,
    duration: float,
    dt: float,
    seed: int | np.random.Generator | None = 0,
    hub_height: float = 90.0,
    rotor_radius: float = 63.0,
) -> WindSeries:
    """Synthesise jointly Gaussian hub-point and rotor-effective longitudinal wind (Kaimal, IEC coherence).

    Parameters
    ----------
    mean_speed : float
        Mean wind at hub height (m/s), >= 0 (0 gives calm air).
    turbulence_intensity : float
        TI (-), 0 gives a constant wind.
    duration, dt : float
        Length and sample time (s).
    seed : int or Generator
    hub_height, rotor_radius : float
        (m).

    Returns
    -------
    WindSeries
    """
    v = check_number("mean_speed", mean_speed, nonneg=True)
    ti = check_number("turbulence_intensity", turbulence_intensity, nonneg=True)
    if ti >= 1:
        raise ValueError(f"turbulence_intensity must be < 1, got {turbulence_intensity!r}")
    duration = check_number("duration", duration, positive=True)
    dt = check_number("dt", dt, positive=True)
    if duration < dt:
        raise ValueError(f"duration ({duration} s) must be at least one sample time dt ({dt} s)")
    n_out = int(round(duration / dt))
    n = next_fast_len(n_out, real=True)  # synthesise on a fast FFT length, return the first n_out samples
    t = np.arange(n_out) * dt
    freqs = np.fft.rfftfreq(n, dt)
    meta = {"mean_speed": v, "turbulence_intensity": ti, "hub_height": hub_height, "rotor_radius": rotor_radius}
    if v == 0.0 or ti == 0.0:
        const = np.full(n_out, v)
        return WindSeries(t, const, const.copy(), freqs, meta)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    df = 1.0 / (n * dt)
    s = kaimal_spectrum(freqs, v, ti, hub_height)
    s[0] = 0.0
    h2, g = rotor_averaging(freqs, v, rotor_radius, hub_height)
    # spectral matrix [[S, G S], [G S, H2 S]] = L L^T with L = sqrt(S) [[1, 0], [G, sqrt(H2 - G^2)]]
    resid = np.sqrt(np.clip(h2 - g**2, 0.0, None))
    z1 = np.exp(1j * rng.uniform(0.0, 2 * np.pi, freqs.size))
    z2 = np.exp(1j * rng.uniform(0.0, 2 * np.pi, freqs.size))
    amp = np.sqrt(2.0 * s * df)
    hub_c = amp * z1
    eff_c = amp * (g * z1 + resid * z2)
    hub = irfft(hub_c, n=n)[:n_out] * n / 2.0 + v
    eff = irfft(eff_c, n=n)[:n_out] * n / 2.0 + v
    return WindSeries(t, hub, eff, freqs, meta)
