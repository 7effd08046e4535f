"""JONSWAP irregular waves and first-order wave loads on the OC3 Hywind spar.

Model: linear (Airy) long-crested waves on finite depth, random-phase synthesis (deterministic amplitudes
``sqrt(2 S df)``, uniform random phases) on the FFT grid, so that every time series costs one inverse FFT.
Loads are first order: Morison inertia with Froude-Krylov, ``rho (1 + Ca) (pi D^2 / 4) a(z)`` per strip of the
spar at its undisturbed position, plus the vertical Froude-Krylov force of the dynamic pressure on the
horizontal areas (keel disc and the taper between -4 and -12 m). Diffraction is neglected (kD is small in the
wave band) and so is radiation memory (the platform's extra linear damping stands in for it). The strip
velocities are returned for the quadratic-drag effect, which the simulator evaluates on the relative velocity.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.fft import irfft, next_fast_len

from .oc3 import GRAVITY, RHO_WATER, WATER_DEPTH
from .validation import check_number

__all__ = ["jonswap_spectrum", "wave_number", "SparGeometry", "WaveLoads", "synthesize_waves", "excitation_rao"]


def jonswap_spectrum(f_hz: np.ndarray, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """One-sided JONSWAP spectral density (DNV-RP-C205, section 3.5.5).

    ``S(f) = A_gamma S_PM(f) gamma^exp(-(f - fp)^2 / (2 sigma^2 fp^2))`` with the Pierson-Moskowitz spectrum
    ``S_PM = (5/16) Hs^2 fp^4 f^-5 exp(-(5/4) (fp/f)^4)``, ``sigma = 0.07`` (f <= fp) or 0.09, and the
    normalising factor ``A_gamma = 1 - 0.287 ln(gamma)``.

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz), >= 0.
    hs : float
        Significant wave height (m), >= 0.
    tp : float
        Peak period (s), > 0.
    gamma : float
        Peak-enhancement factor (-), 1 <= gamma <= 10 (1 = Pierson-Moskowitz).

    Returns
    -------
    ndarray
        Spectral density (m²/Hz).
    """
    hs = check_number("hs", hs, nonneg=True)
    tp = check_number("tp", tp, positive=True)
    gamma = check_number("gamma", gamma)
    if not 1.0 <= gamma <= 10.0:
        raise ValueError(f"gamma must be between 1 and 10, got {gamma!r}")
    f = np.asarray(f_hz, dtype=float)
    out = np.zeros_like(f)
    if hs == 0.0:
        return out
    fp = 1.0 / tp
    pos = f > 0
    fv = f[pos]
    s_pm = 5.0 / 16.0 * hs**2 * fp**4 * fv**-5.0 * np.exp(-1.25 * (fp / fv) ** 4)
    sigma = np.where(fv <= fp, 0.07, 0.09)
    peak = gamma ** np.exp(-((fv - fp) ** 2) / (2.0 * sigma**2 * fp**2))
    out[pos] = (1.0 - 0.287 * np.log(gamma)) * s_pm * peak
    return out


def wave_number(omega: np.ndarray, depth: float = WATER_DEPTH) -> np.ndarray:
    """Wave number from the linear dispersion relation ``omega^2 = g k tanh(k h)`` (Newton, vectorised).

    Parameters
    ----------
    omega : array_like
        Angular frequency (rad/s), >= 0.
    depth : float
        Water depth (m), > 0.

    Returns
    -------
    ndarray
        Wave number (rad/m).
    """
    depth = check_number("depth", depth, positive=True)
    w = np.asarray(omega, dtype=float)
    k0 = w**2 / GRAVITY
    # start from the deep-water value or the shallow-water one, whichever is larger (Newton converges from above)
    k = np.maximum(k0, w / np.sqrt(GRAVITY * depth))
    for _ in range(50):
        th = np.tanh(k * depth)
        fk = GRAVITY * k * th - w**2
        dfk = GRAVITY * th + GRAVITY * k * depth * (1.0 - th**2)
        step = np.where(dfk > 0, fk / np.where(dfk > 0, dfk, 1.0), 0.0)
        k = k - step
        if np.all(np.abs(step) <= 1e-14 * np.maximum(k, 1e-30)):
            break
    return np.where(w > 0, k, 0.0)


@dataclass(frozen=True)
class SparGeometry:
    """Submerged geometry and Morison coefficients of the OC3 Hywind spar (Jonkman 2010, section 3).

    Attributes
    ----------
    upper_diameter, lower_diameter : float
        Diameter above the taper and below it (m).
    taper_top, taper_bottom, draft : float
        Heights of the taper's top and bottom and of the keel (m, negative below SWL).
    ca, cd : float
        Added-mass and drag coefficients (-).
    """

    upper_diameter: float = 6.5
    lower_diameter: float = 9.4
    taper_top: float = -4.0
    taper_bottom: float = -12.0
    draft: float = -120.0
    ca: float = 0.969954
    cd: float = 0.6

    def diameter(self, z: np.ndarray) -> np.ndarray:
        """Diameter at heights ``z`` (m); zero above SWL and below the keel."""
        z = np.asarray(z, dtype=float)
        frac = np.clip((self.taper_top - z) / (self.taper_top - self.taper_bottom), 0.0, 1.0)
        d = self.upper_diameter + frac * (self.lower_diameter - self.upper_diameter)
        return np.where((z <= 0.0) & (z >= self.draft), d, 0.0)

    def strips(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Strip discretisation of the submerged length: centres (m), lengths (m), diameters (m).

        The strips are finer near the surface, where the wave kinematics are largest.
        """
        if int(n) < 2:
            raise ValueError(f"n must be at least 2 strips, got {n!r}")
        s = np.linspace(0.0, 1.0, int(n) + 1) ** 1.8
        edges = self.draft * s
        centres = 0.5 * (edges[1:] + edges[:-1])
        dz = -np.diff(edges)
        return centres, dz, self.diameter(centres)


def excitation_rao(
    f_hz: np.ndarray,
    direction_deg: float = 0.0,
    depth: float = WATER_DEPTH,
    geometry: SparGeometry | None = None,
    n_strips: int = 200,
) -> np.ndarray:
    """Complex first-order wave excitation per unit wave amplitude, about the SWL reference point.

    The incident wave is ``eta = Re(a exp(i omega t))`` at the origin, travelling along ``direction_deg``.

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz).
    direction_deg : float
        Wave propagation direction (deg, 0 = +x downwind, 90 = +y).
    depth : float
        Water depth (m).
    geometry : SparGeometry, optional
    n_strips : int
        Integration strips.

    Returns
    -------
    ndarray, shape (len(f_hz), 6)
        [Fx, Fy, Fz, Mx, My, Mz] per metre of wave amplitude (N/m, N·m/m), complex.
    """
    geo = geometry or SparGeometry()
    beta = np.deg2rad(check_number("direction_deg", direction_deg))
    f = np.atleast_1d(np.asarray(f_hz, dtype=float))
    w = 2 * np.pi * f
    k = wave_number(w, depth)
    z, dz, diam = geo.strips(n_strips)
    kz = k[:, None] * (z[None, :] + depth)
    kh = k[:, None] * depth
    with np.errstate(over="ignore", invalid="ignore"):
        # cosh(k(z+h))/sinh(kh) written to stay finite in deep water
        decay_h = np.where(kh > 30, np.exp(k[:, None] * z[None, :]), np.cosh(kz) / np.sinh(np.maximum(kh, 1e-12)))
        decay_p = np.where(kh > 30, np.exp(k[:, None] * z[None, :]), np.cosh(kz) / np.cosh(kh))
    decay_h = np.nan_to_num(decay_h)
    decay_p = np.nan_to_num(decay_p)
    # horizontal particle acceleration per unit amplitude: i omega * (omega * decay_h) (velocity = omega decay eta)
    acc = 1j * w[:, None] ** 2 * decay_h
    area = np.pi * diam**2 / 4.0
    fh = RHO_WATER * (1.0 + geo.ca) * area[None, :] * acc * dz[None, :]  # (nf, ns) along the wave direction
    f_along = fh.sum(axis=1)
    m_along = (fh * z[None, :]).sum(axis=1)
    out = np.zeros((f.size, 6), dtype=complex)
    out[:, 0] = f_along * np.cos(beta)
    out[:, 1] = f_along * np.sin(beta)
    out[:, 3] = -m_along * np.sin(beta)
    out[:, 4] = m_along * np.cos(beta)
    # vertical Froude-Krylov: dynamic pressure rho g decay_p eta on the keel (up) and on the taper annulus (down)
    keel_area = np.pi * geo.lower_diameter**2 / 4.0

    def p_at(zz: float) -> np.ndarray:
        if depth * np.max(k, initial=0.0) > 30:
            return RHO_WATER * GRAVITY * np.exp(k * zz)
        return RHO_WATER * GRAVITY * np.cosh(k * (zz + depth)) / np.cosh(k * depth)

    # taper: the annulus faces up, so the pressure pushes down; integrate p(z) dA(z) with Gauss-Legendre
    xg, wg = np.polynomial.legendre.leggauss(16)
    zg = 0.5 * (geo.taper_top + geo.taper_bottom) + 0.5 * (geo.taper_top - geo.taper_bottom) * xg
    taper_slope = (geo.lower_diameter - geo.upper_diameter) / (geo.taper_top - geo.taper_bottom)  # -dD/dz
    da_dz = -np.pi / 2.0 * geo.diameter(zg) * taper_slope
    taper = sum(w_i * p_at(z_i) * (-d_i) for w_i, z_i, d_i in zip(wg, zg, da_dz, strict=True))
    taper = taper * 0.5 * (geo.taper_top - geo.taper_bottom)
    out[:, 2] = p_at(geo.draft) * keel_area - taper
    out[f == 0] = 0.0
    return out


@dataclass(frozen=True)
class WaveLoads:
    """Synthesised wave elevation, excitation and strip kinematics on a regular time grid (SI units).

    Attributes
    ----------
    t : ndarray (n,)
        Time (s).
    elevation : ndarray (n,)
        Wave elevation at the origin (m).
    excitation : ndarray (n, 6)
        [Fx, Fy, Fz, Mx, My, Mz] about the SWL reference point (N, N·m).
    strip_z, strip_dz, strip_diameter : ndarray (n_strips,)
        Strip centres, lengths and diameters (m).
    velocity : ndarray (n, n_strips, 2)
        Undisturbed horizontal particle velocity at the strip centres, x and y (m/s).
    frequencies_hz, spectrum : ndarray
        The discrete one-sided spectrum used (Hz, m²/Hz).
    meta : dict
    """

    t: np.ndarray
    elevation: np.ndarray
    excitation: np.ndarray
    strip_z: np.ndarray
    strip_dz: np.ndarray
    strip_diameter: np.ndarray
    velocity: np.ndarray
    frequencies_hz: np.ndarray
    spectrum: np.ndarray
    meta: dict = field(default_factory=dict)


def synthesize_waves(
    hs: float,
    tp: float,
    gamma: float,
    direction_deg: float,
    duration: float,
    dt: float,
    seed: int | np.random.Generator | None = 0,
    depth: float = WATER_DEPTH,
    geometry: SparGeometry | None = None,
    n_strips: int = 24,
    f_max_hz: float | None = None,
) -> WaveLoads:
    """Synthesise long-crested JONSWAP waves and their first-order loads on the spar by inverse FFT.

    Parameters
    ----------
    hs, tp, gamma : float
        Significant height (m), peak period (s), peak enhancement (-).
    direction_deg : float
        Propagation direction (deg; 0 = along the wind, +x).
    duration, dt : float
        Length (s) and sample time (s); ``n = round(duration / dt)`` samples. The components sit on the grid of
        a fast FFT length ``N >= n`` (frequency spacing ``1 / (N dt)``); the first n samples are returned.
    seed : int or Generator
        Random phases.
    depth : float
        Water depth (m).
    geometry : SparGeometry, optional
    n_strips : int
        Strips for the drag kinematics.
    f_max_hz : float, optional
        Components above this frequency are dropped (default: where S < 1e-6 of the peak, at most 1 Hz).

    Returns
    -------
    WaveLoads
    """
    hs = check_number("hs", hs, nonneg=True)
    tp = check_number("tp", tp, positive=True)
    duration = check_number("duration", duration, positive=True)
    dt = check_number("dt", dt, positive=True)
    direction = check_number("direction_deg", direction_deg)
    if duration < dt:
        raise ValueError(f"duration ({duration} s) must be at least one sample time dt ({dt} s)")
    geo = geometry or SparGeometry()
    n_out = int(round(duration / dt))
    n = next_fast_len(n_out, real=True)  # synthesise on a fast FFT length, return the first n_out samples
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    freqs = np.fft.rfftfreq(n, dt)
    df = 1.0 / (n * dt)
    spec = jonswap_spectrum(freqs, hs, tp, gamma)
    if f_max_hz is None:
        f_max_hz = min(1.0, float(freqs[spec >= 1e-6 * spec.max()].max())) if spec.max() > 0 else 0.0
    spec = np.where(freqs <= f_max_hz, spec, 0.0)
    phases = rng.uniform(0.0, 2.0 * np.pi, freqs.size)
    amp = np.sqrt(2.0 * spec * df) * np.exp(1j * phases)  # complex amplitude of each component
    amp[0] = 0.0
    active = np.nonzero(amp)[0]
    beta = np.deg2rad(direction)
    z, dz, diam = geo.strips(n_strips)

    def series(coeff: np.ndarray) -> np.ndarray:
        """Time series sum_j Re(coeff_j amp_j exp(i w_j t)) via irfft; coeff over `active` frequencies."""
        full = np.zeros(coeff.shape[:-1] + (freqs.size,), dtype=complex)
        full[..., active] = coeff * amp[active]
        return irfft(full, n=n, axis=-1)[..., :n_out] * n / 2.0

    elevation = series(np.ones(active.size))
    rao = excitation_rao(freqs[active], direction, depth, geo)  # (na, 6)
    excitation = series(rao.T).T
    w = 2 * np.pi * freqs[active]
    k = wave_number(w, depth)
    kh = k * depth
    kz = k[None, :] * (z[:, None] + depth)
    with np.errstate(over="ignore", invalid="ignore"):
        decay = np.where(kh[None, :] > 30, np.exp(k[None, :] * z[:, None]),
                         np.cosh(kz) / np.sinh(np.maximum(kh[None, :], 1e-12)))
    decay = np.nan_to_num(decay)
    u_along = series(w[None, :] * decay)  # (ns, n): horizontal velocity along the wave direction
    velocity = np.empty((n_out, z.size, 2))
    velocity[:, :, 0] = (u_along * np.cos(beta)).T
    velocity[:, :, 1] = (u_along * np.sin(beta)).T
    return WaveLoads(
        t=np.arange(n_out) * dt,
        elevation=elevation,
        excitation=np.ascontiguousarray(excitation),
        strip_z=z,
        strip_dz=dz,
        strip_diameter=diam,
        velocity=velocity,
        frequencies_hz=freqs,
        spectrum=spec,
        meta={"hs": hs, "tp": tp, "gamma": float(gamma), "direction_deg": direction,
              "seed": seed if isinstance(seed, int) else None, "depth": depth},
    )
