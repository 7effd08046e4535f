"""Kaimal turbulence (IEC 61400-1 ed. 3, Annex B) reduced to a hub-point wind and a rotor-effective wind.

Model
-----
* Longitudinal (u) turbulence at hub height: the Kaimal spectrum of IEC 61400-1 ed. 3, Annex B,
  ``S(f) = 4 sigma^2 (L/V) / (1 + 6 f L/V)^(5/3)``, with ``L = 8.1 Lambda_1`` and ``sigma = TI V``.
* Spatial correlation: the IEC exponential coherence
  ``Coh(r, f) = exp(-12 sqrt((f r/V)^2 + (0.12 r/L_c)^2))``, ``L_c = 8.1 Lambda_1``, the same over the whole
  rotor disc (one mean speed, no shear).
* Rotor-effective wind: the average of u over the rotor disc. Its auto-spectrum is ``H2(f) S(f)`` and its
  cross-spectrum with the hub point is ``G(f) S(f)`` (both real: the coherence has no phase), see
  :func:`rotor_averaging`.
* Synthesis: per frequency, the 2x2 spectral matrix ``S [[1, G], [G, H2]]`` is factored as ``L L^T`` with
  ``L = sqrt(S) [[1, 0], [G, sqrt(H2 - G^2)]]`` and applied to two independent random-phase components of unit
  amplitude; one inverse real FFT per series.
* Rotor-plane field (:func:`synthesize_rotor_wind`): the same spectrum and coherence on a polar grid of points
  over the disc (Veers' method, as TurbSim's ``IECKAI`` model), plus the power-law mean profile; the linear
  gradients of u over the disc (:func:`rotor_plane_fit`) drive the rotor's yaw and tilt moments and side force.

Examples
--------
>>> w = synthesize_wind(11.4, 0.17, duration=60.0, dt=0.05, seed=1)
>>> w.hub.shape == w.rotor_effective.shape == (1200,)
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft
from scipy.interpolate import PchipInterpolator

from .validation import check_number

__all__ = [
    "IEC_REFERENCE_INTENSITY",
    "RotorWind",
    "TURBSIM_GRID_SPACING",
    "WindSeries",
    "constrain_to_hub",
    "grid_interpolation_variance",
    "hub_series",
    "iec_turbulence_intensity",
    "kaimal_spectrum",
    "rotor_averaging",
    "rotor_plane_fit",
    "synthesize_rotor_wind",
    "synthesize_wind",
    "turbulence_length_scale",
]

IEC_REFERENCE_INTENSITY = {"A": 0.16, "B": 0.14, "C": 0.12}
"""Expected turbulence intensity at 15 m/s, I_ref, per turbine class (IEC 61400-1 ed. 3, Table 1)."""

_GAUSS_ORDER = 8
_DIRECT_LIMIT = 256  # up to this many frequencies, rotor_averaging evaluates H2 directly (no interpolation)


def _generator(seed: object) -> np.random.Generator:
    """A numpy Generator from an int, a SeedSequence, a Generator (used as is) or None (fresh entropy)."""
    message = f"seed must be None, a non-negative int, a SeedSequence or a Generator, got {seed!r}"
    if isinstance(seed, bool):
        raise ValueError(message)
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise ValueError(message) from exc


def _frequencies(f_hz: object) -> np.ndarray:
    try:
        f = np.asarray(f_hz, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"f_hz must be an array of numbers, got {f_hz!r}") from exc
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError("f_hz must be finite and >= 0")
    return f


def _check_ti(turbulence_intensity: float) -> float:
    ti = check_number("turbulence_intensity", turbulence_intensity, nonneg=True)
    if ti >= 1.0:
        raise ValueError(f"turbulence_intensity must be < 1, got {turbulence_intensity!r}")
    return ti


def turbulence_length_scale(hub_height: float = 90.0) -> float:
    """Kaimal integral scale ``L_u = 8.1 Lambda_1`` (m), also the coherence scale ``L_c`` (IEC 61400-1 ed. 3).

    ``Lambda_1 = 0.7 z_hub`` for ``z_hub <= 60 m``, else 42 m (IEC 61400-1 ed. 3, eq. (5)).

    Parameters
    ----------
    hub_height : float, default 90
        Hub height (m), > 0.

    Examples
    --------
    >>> round(turbulence_length_scale(90.0), 6), round(turbulence_length_scale(50.0), 6)
    (340.2, 283.5)
    """
    z = check_number("hub_height", hub_height, positive=True)
    return 8.1 * (0.7 * z if z <= 60.0 else 42.0)


def kaimal_spectrum(
    f_hz: np.ndarray, mean_speed: float, turbulence_intensity: float, hub_height: float = 90.0
) -> np.ndarray:
    """One-sided longitudinal Kaimal spectrum of IEC 61400-1 ed. 3 (Annex B).

    ``S(f) = 4 sigma^2 (L/V) / (1 + 6 f L/V)^(5/3)`` with ``L = 8.1 Lambda_1`` (see
    :func:`turbulence_length_scale`) and ``sigma = TI V``; its integral over f from 0 to infinity is sigma².

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz), finite and >= 0.
    mean_speed : float
        Mean wind speed at hub height V (m/s), > 0.
    turbulence_intensity : float
        Longitudinal turbulence intensity TI = sigma/V (-), 0 <= TI < 1.
    hub_height : float, default 90
        Hub height (m).

    Returns
    -------
    ndarray
        Spectral density (m²/s²/Hz), shape of ``f_hz``.

    Examples
    --------
    >>> float(kaimal_spectrum(0.0, 10.0, 0.1)) == 4 * 1.0**2 * 340.2 / 10.0
    True
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    ti = _check_ti(turbulence_intensity)
    length = turbulence_length_scale(hub_height)
    f = _frequencies(f_hz)
    sigma = ti * v
    return 4.0 * sigma**2 * (length / v) / (1.0 + 6.0 * f * length / v) ** (5.0 / 3.0)


def iec_turbulence_intensity(mean_speed: float, turbulence_class: str = "B") -> float:
    """IEC 61400-1 ed. 3 normal turbulence model, eq. (11): ``sigma_1 = I_ref (0.75 V + 5.6)``, as sigma_1/V.

    Parameters
    ----------
    mean_speed : float
        Hub-height mean wind V (m/s), > 0.
    turbulence_class : {"A", "B", "C"}, default "B"
        Turbulence category; I_ref = 0.16, 0.14, 0.12 (:data:`IEC_REFERENCE_INTENSITY`).

    Returns
    -------
    float
        Turbulence intensity (-).

    Examples
    --------
    >>> round(iec_turbulence_intensity(15.0, "B"), 4)
    0.1573
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    key = turbulence_class.upper() if isinstance(turbulence_class, str) else turbulence_class
    if key not in IEC_REFERENCE_INTENSITY:
        raise ValueError(
            f"turbulence_class must be one of {sorted(IEC_REFERENCE_INTENSITY)}, got {turbulence_class!r}"
        )
    return IEC_REFERENCE_INTENSITY[key] * (0.75 * v + 5.6) / v


def _coherence_decay(f_hz: np.ndarray, mean_speed: float, coherence_scale: float) -> np.ndarray:
    """Decay rate ``a(f) = 12 sqrt((f/V)^2 + (0.12/L_c)^2)`` (1/m) of the IEC coherence ``exp(-a(f) r)``
    (IEC 61400-1 ed. 3, eq. (B.4))."""
    return 12.0 * np.sqrt((f_hz / mean_speed) ** 2 + (0.12 / coherence_scale) ** 2)


TURBSIM_GRID_SPACING = 145.0 / 30.0
"""Spacing (m) of the TurbSim grid of the OC3 Hywind reference runs: 31 x 31 points over 145 m x 145 m."""


def grid_interpolation_variance(f_hz: np.ndarray, mean_speed: float, spacing: float,
                                hub_height: float = 90.0) -> np.ndarray:
    """Spectrum of a field read by bilinear interpolation from a square grid, relative to the point spectrum.

    OpenFAST's InflowWind reads the turbulence at each blade node by bilinear interpolation of the TurbSim grid
    around it. A value interpolated at ``(t_y, t_z)`` inside a cell from its four corners, which have the
    point spectrum and the IEC coherence ``c1 = Coh(spacing, f)`` between edge neighbours and
    ``c2 = Coh(sqrt(2) spacing, f)`` across the diagonal, has the spectrum of the point times
    ``sum_kl w_k w_l Coh_kl``; averaged over the position in the cell (``E[(1-t)^2 + t^2] = 2/3``,
    ``E[t (1-t)] = 1/6`` per direction) that is

    ``H(f) = 4/9 + 4/9 c1 + 1/9 c2``,

    1 where the corners are coherent (large eddies pass unchanged) and 4/9 where they are independent: the
    grid removes up to 5/9 of the small-scale variance. (Between the values at two points farther apart than
    a few grid cells the cross-spectrum is that of the points.)

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz), finite and >= 0.
    mean_speed : float
        Mean wind speed at hub height V (m/s), > 0.
    spacing : float
        Grid spacing (m), > 0; :data:`TURBSIM_GRID_SPACING` for the reference deck.
    hub_height : float, default 90
        Hub height (m), sets the coherence scale ``L_c``.

    Returns
    -------
    ndarray
        ``H(f)`` (-), in [4/9, 1], shape of ``f_hz``.

    Examples
    --------
    >>> h = grid_interpolation_variance([0.0, 0.5, 50.0], 12.0, TURBSIM_GRID_SPACING)
    >>> bool(0.98 < h[0] <= 1.0 and abs(h[2] - 4 / 9) < 1e-12 and h[0] > h[1] > h[2])
    True
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    d = check_number("spacing", spacing, positive=True)
    f = _frequencies(f_hz)
    a = _coherence_decay(f, v, turbulence_length_scale(hub_height))
    return 4.0 / 9.0 + 4.0 / 9.0 * np.exp(-a * d) + 1.0 / 9.0 * np.exp(-a * np.sqrt(2.0) * d)


@lru_cache(maxsize=8)
def _distance_rule(n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes ``u = s / (2R)`` and weights of ``int_0^1 q(u) h(u) du`` with ``q`` the pdf of the distance.

    ``q(u) = (16 u / pi) (acos(u) - u sqrt(1 - u^2))`` is the density of the distance between two points drawn
    uniformly on a disc, scaled by its diameter. With ``u = sin(phi)`` the integrand becomes the smooth
    ``(16/pi) sin(phi) cos(phi) (pi/2 - phi - sin(phi) cos(phi)) h(sin(phi))``; ``phi`` in [0, pi/2] is cut
    into geometric panels (refined towards 0, where ``exp(-b u)`` concentrates at high frequency) with 8
    Gauss-Legendre nodes each. Returns the nodes u and the weights (sum 1).
    """
    n_panels = max(4, n_points // _GAUSS_ORDER)
    edges = np.concatenate([[0.0], np.geomspace(1e-7, 0.5 * np.pi, n_panels)])
    xg, wg = np.polynomial.legendre.leggauss(_GAUSS_ORDER)
    lo, hi = edges[:-1, None], edges[1:, None]
    phi = (0.5 * (lo + hi) + 0.5 * (hi - lo) * xg).ravel()
    dphi = (0.5 * (hi - lo) * wg).ravel()
    sc = np.sin(phi) * np.cos(phi)
    weights = 16.0 / np.pi * sc * (0.5 * np.pi - phi - sc) * dphi
    return np.sin(phi), weights


def rotor_averaging(
    f_hz: np.ndarray,
    mean_speed: float,
    rotor_radius: float = 63.0,
    hub_height: float = 90.0,
    n_points: int = 256,
) -> tuple[np.ndarray, np.ndarray]:
    """Spectral reduction of the disc-averaged longitudinal wind under the IEC exponential coherence.

    With ``Coh(r, f) = exp(-a(f) r)``, ``a(f) = 12 sqrt((f/V)^2 + (0.12/L_c)^2)`` (IEC 61400-1 ed. 3,
    eq. (B.4); ``L_c = 8.1 Lambda_1``), this returns

    * ``H2(f) = (1/A^2) int_A int_A Coh(|p - q|, f) dA_p dA_q``, the ratio of the auto-spectrum of the
      rotor-averaged wind to the point spectrum. The double integral over the disc is reduced exactly to one
      over the distance s between two points, whose density on a disc of radius R is
      ``(4 s / (pi R^2)) (acos(s/2R) - (s/2R) sqrt(1 - (s/2R)^2))``; that integral is evaluated with
      ``n_points`` Gauss-Legendre nodes. On long frequency arrays H2 is computed on a log grid of ``a`` (about
      40 points per decade) and interpolated (monotone cubic in log-log), so 50 000 frequencies cost
      a few milliseconds.
    * ``G(f) = (1/A) int_A Coh(|p - hub|, f) dA``, the ratio of the cross-spectrum of hub point and rotor
      average to the point spectrum, in closed form: ``2 (1 - e^{-x} (1 + x)) / x^2`` with ``x = a R``.

    Both decrease with f from their values at f = 0 (below 1 because of the ``0.12 r / L_c`` term) and behave
    as ``2 / (a R)^2`` at high frequency; ``H2 >= G^2`` (Cauchy-Schwarz).

    Parameters
    ----------
    f_hz : array_like
        Frequencies (Hz), >= 0.
    mean_speed : float
        Mean wind speed at hub height V (m/s), > 0.
    rotor_radius : float, default 63
        Rotor radius R (m), > 0.
    hub_height : float, default 90
        Hub height (m), sets ``L_c``.
    n_points : int, default 256
        Quadrature nodes of the distance integral (>= 32; used in panels of 8).

    Returns
    -------
    H2, G : ndarray
        Auto-spectrum ratio and cross-spectrum ratio (-), shape of ``f_hz``.

    Examples
    --------
    >>> h2, g = rotor_averaging([0.0, 0.1, 1.0], 11.4)
    >>> bool(np.all(np.diff(h2) < 0) and np.all(g**2 <= h2))
    True
    """
    v = check_number("mean_speed", mean_speed, positive=True)
    radius = check_number("rotor_radius", rotor_radius, positive=True)
    lc = turbulence_length_scale(hub_height)
    if isinstance(n_points, bool) or not isinstance(n_points, int | np.integer) or n_points < 32:
        raise ValueError(f"n_points must be an integer >= 32, got {n_points!r}")
    f = _frequencies(f_hz)
    a = _coherence_decay(f, v, lc)  # decay rate of the coherence with distance (1/m)

    u, wq = _distance_rule(int(n_points))

    def h2_of(rate: np.ndarray) -> np.ndarray:
        return np.exp(-2.0 * radius * rate[:, None] * u[None, :]) @ wq

    flat = a.ravel()
    if flat.size <= _DIRECT_LIMIT:
        h2 = h2_of(flat)
    else:
        a_lo, a_hi = float(flat.min()), float(flat.max())
        n_grid = int(np.clip(np.ceil(40.0 * np.log10(a_hi / a_lo)), 1, 600)) + 1
        grid = np.geomspace(a_lo, a_hi * (1.0 + 1e-12), n_grid)
        spline = PchipInterpolator(np.log(grid), np.log(h2_of(grid)))
        h2 = np.exp(spline(np.log(flat)))
    x = a * radius
    with np.errstate(divide="ignore", invalid="ignore"):
        g_closed = 2.0 * (-np.expm1(-x) - x * np.exp(-x)) / x**2
    g_series = 1.0 - 2.0 * x / 3.0 + x**2 / 4.0 - x**3 / 15.0 + x**4 / 72.0
    g = np.where(x < 1e-2, g_series, g_closed)
    return h2.reshape(a.shape), g


@dataclass(frozen=True)
class WindSeries:
    """Longitudinal wind at the hub point and averaged over the rotor disc (SI units, time-major).

    Attributes
    ----------
    t : ndarray (n,)
        Time (s), ``t[i] = i dt``.
    hub : ndarray (n,)
        Longitudinal wind speed at the hub point (m/s, mean included).
    rotor_effective : ndarray (n,)
        Longitudinal wind averaged over the rotor disc (m/s, mean included).
    frequencies_hz : ndarray (n_fft // 2 + 1,)
        The synthesis grid (Hz).
    meta : dict
        ``mean_speed, turbulence_intensity, hub_height, rotor_radius, seed`` (None unless an int was given),
        ``dt, n_fft``.

    Examples
    --------
    >>> w = synthesize_wind(8.0, 0.0, duration=10.0, dt=0.5, seed=0)
    >>> w.hub.tolist() == [8.0] * 20
    True
    """

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
    seed: int | np.random.SeedSequence | np.random.Generator | None = 0,
    hub_height: float = 90.0,
    rotor_radius: float = 63.0,
) -> WindSeries:
    """Synthesise jointly Gaussian hub-point and rotor-effective longitudinal wind by inverse FFT.

    Per frequency of the FFT grid, two independent components of unit amplitude and uniform random phase are
    combined with the Cholesky factor ``sqrt(2 S df) [[1, 0], [G, sqrt(max(H2 - G^2, 0))]]`` of the spectral
    matrix (``S`` from :func:`kaimal_spectrum`, ``H2, G`` from :func:`rotor_averaging`; the ``max`` keeps it
    positive semi-definite), so the hub series has the auto-spectrum S, the rotor-effective series ``H2 S``
    and their cross-spectrum is ``G S``. The hub series has deterministic amplitudes (random phases only).

    The series has ``n = round(duration / dt)`` samples, taken from the start of a record periodic over
    ``n_fft = scipy.fft.next_fast_len(n)`` samples (``df = 1 / (n_fft dt)``). The mean is added to both
    series; variance below ``df`` and above the Nyquist frequency ``1 / (2 dt)`` is absent (with V = 12 m/s
    and a one-hour record, about 1.5 % of the variance lies below df).

    Parameters
    ----------
    mean_speed : float
        Mean wind at hub height (m/s), >= 0 (0 gives calm air).
    turbulence_intensity : float
        TI (-), 0 <= TI < 1; 0 gives a constant wind.
    duration : float
        Record length (s), >= dt.
    dt : float
        Sample time (s), > 0.
    seed : int, SeedSequence, Generator or None, default 0
        Source of the random phases; the same seed gives the same bytes.
    hub_height : float, default 90
        Hub height (m).
    rotor_radius : float, default 63
        Rotor radius (m).

    Returns
    -------
    WindSeries

    Raises
    ------
    ValueError
        An argument is not finite or out of range (the message names it).

    Examples
    --------
    >>> w = synthesize_wind(12.0, 0.15, duration=600.0, dt=0.1, seed=3)
    >>> bool(w.rotor_effective.std() < w.hub.std())
    True
    """
    v = check_number("mean_speed", mean_speed, nonneg=True)
    ti = _check_ti(turbulence_intensity)
    duration = check_number("duration", duration, positive=True)
    dt = check_number("dt", dt, positive=True)
    hub_height = check_number("hub_height", hub_height, positive=True)
    rotor_radius = check_number("rotor_radius", rotor_radius, positive=True)
    if duration < dt:
        raise ValueError(f"duration ({duration} s) must be at least one sample time dt ({dt} s)")
    rng = _generator(seed)
    n_out = int(round(duration / dt))
    n_fft = next_fast_len(n_out, real=True)
    t = np.arange(n_out) * dt
    freqs = np.fft.rfftfreq(n_fft, dt)
    meta = {
        "mean_speed": v, "turbulence_intensity": ti, "hub_height": hub_height, "rotor_radius": rotor_radius,
        "seed": int(seed) if isinstance(seed, int | np.integer) else None, "dt": dt, "n_fft": int(n_fft),
    }
    if v == 0.0 or ti == 0.0:
        return WindSeries(t, np.full(n_out, v), np.full(n_out, v), freqs, meta)

    phases = rng.uniform(0.0, 2.0 * np.pi, (2, freqs.size))
    keep = np.flatnonzero((freqs > 0.0) & (freqs < 0.5 / dt))
    fk = freqs[keep]
    amp = np.sqrt(2.0 * kaimal_spectrum(fk, v, ti, hub_height) / (n_fft * dt)) * (0.5 * n_fft)
    h2, g = rotor_averaging(fk, v, rotor_radius, hub_height)
    g = np.minimum(g, np.sqrt(h2))
    resid = np.sqrt(np.maximum(h2 - g**2, 0.0))
    z1 = np.exp(1j * phases[0, keep])
    z2 = np.exp(1j * phases[1, keep])
    spectra = np.zeros((2, freqs.size), dtype=complex)
    spectra[0, keep] = amp * z1
    spectra[1, keep] = amp * (g * z1 + resid * z2)
    # irfft gives (1/N) sum_j X_j e^{2 pi i j m / N} + c.c.; the N/2 in amp makes it sum_j Re(X_j e^{i w_j t})
    series = irfft(spectra, n=n_fft, axis=-1)[:, :n_out] + v
    return WindSeries(t, series[0].copy(), series[1].copy(), freqs, meta)


_COHERENCE_FLOOR = 1e-4  # above the frequency where all pairs' coherence is below this, points are independent
_CHOLESKY_CHUNK = 512  # frequencies factored per batch (memory: chunk * n_points^2 * 8 bytes)
_FFT_BLOCK_VALUES = 1 << 21  # points per batched inverse FFT: at most this many samples (16 MB of float64)


def _coherent_groups(dist: np.ndarray, f_hz: np.ndarray, mean_speed: float) -> list[tuple[slice, list[np.ndarray]]]:
    """Split increasing frequencies into runs over which the points fall into the same coherent groups.

    At frequency f the points form the connected components of the graph joining every pair whose coherence
    bound ``exp(-12 f d / V)`` is at least :data:`_COHERENCE_FLOOR` (``d <= V ln(1/floor) / (12 f)``): pairs in
    different components are all below the floor, as every pair is above ``coherent_max_hz``. These components
    are the single-linkage clusters of the points cut at that distance. Returns ``(frequency slice, groups)``
    with each group's point indices in increasing order; the components only split as f grows, so the runs are
    contiguous.
    """
    from scipy.cluster.hierarchy import fcluster, linkage
    from scipy.spatial.distance import squareform

    reach = mean_speed * np.log(1.0 / _COHERENCE_FLOOR) / (12.0 * np.maximum(f_hz, 1e-300))
    tree = linkage(squareform(dist, checks=False), method="single")
    merges = np.searchsorted(np.sort(tree[:, 2]), reach, side="right")  # merges within reach, per frequency
    runs: list[tuple[slice, list[np.ndarray]]] = []
    last: np.ndarray | None = None
    for start in np.flatnonzero(np.diff(merges, prepend=-1)):
        labels = fcluster(tree, reach[start], criterion="distance")
        if last is not None and np.array_equal(labels, last):
            continue
        if runs:
            runs[-1] = (slice(runs[-1][0].start, int(start)), runs[-1][1])
        runs.append((slice(int(start), f_hz.size), [np.flatnonzero(labels == c) for c in np.unique(labels)]))
        last = labels
    return runs


def _factor(coh: np.ndarray) -> np.ndarray:
    """``L`` with ``L L^T = coh`` for a stack of symmetric matrices: Cholesky (the exponential kernel is positive
    definite for distinct points), or, for a matrix made indefinite by a nugget, ``V sqrt(max(lambda, 0))``
    from its eigen-decomposition."""
    try:
        return np.linalg.cholesky(coh)
    except np.linalg.LinAlgError:
        out = np.empty_like(coh)
        for i, c in enumerate(coh):
            try:
                out[i] = np.linalg.cholesky(c)
            except np.linalg.LinAlgError:
                lam, vec = np.linalg.eigh(c)
                out[i] = vec * np.sqrt(np.clip(lam, 0.0, None))
        return out


def _coherent_coefficients(rng: np.random.Generator, f_hz: np.ndarray, amp: np.ndarray, dist: np.ndarray,
                           mean_speed: float, coherence_scale: float,
                           nugget: np.ndarray | None = None) -> np.ndarray:
    """Fourier coefficients of the grid points in the coherent band (Veers): ``amp L(f) z(f)`` per frequency.

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws the unit-amplitude random phases ``z``, shape ``(n_points, n_freq)``, first of all.
    f_hz : ndarray (n_freq,)
        Frequencies (Hz), increasing.
    amp : ndarray (n_freq,)
        Point amplitudes (the spectrum's, scaled for the inverse FFT).
    dist : ndarray (n_points, n_points)
        Distances between the points (m).
    mean_speed, coherence_scale : float
        V (m/s) and ``L_c`` (m) of the IEC coherence.
    nugget : ndarray (n_points, n_freq), optional
        Small-scale variance each point lacks, as a fraction of the spectrum (``1 - H`` of
        :func:`grid_interpolation_variance` for a point read from a grid, 0 for a grid node): subtracted from the
        diagonal of the coherence matrix. Where that makes the matrix indefinite (points closer than the grid
        spacing, whose interpolated values share corners and are more coherent than the points), its negative
        eigenvalues are set to zero for those frequencies.

    Returns
    -------
    ndarray (n_points, n_freq), complex
        ``L`` is the Cholesky factor of the coherence matrix ``exp(-a(f) dist)``, so the coefficients have the
        cross-spectral matrix ``amp^2 Coh``. Where the points split into groups whose mutual coherences are all
        below :data:`_COHERENCE_FLOOR` (:func:`_coherent_groups`; on the polar grid the rings part above about
        ``0.05 V`` Hz, the outer rings' own points soon after), each group's coherence is factored on its own: the
        same floor as above ``coherent_max_hz``, and a fraction of the cost (the factorisation of the whole
        grid is the bulk of the synthesis).
    """
    n_points, n_freq = dist.shape[0], f_hz.size
    phase = rng.uniform(0.0, 2.0 * np.pi, (n_points, n_freq))
    z = np.empty((n_freq, n_points, 2))  # frequency-major, [cos, sin] of the phases
    z[:, :, 0] = np.cos(phase).T
    z[:, :, 1] = np.sin(phase).T
    del phase
    coef = np.empty((n_points, n_freq), dtype=complex)
    for pts, sl, chol in _coherence_factors(f_hz, dist, mean_speed, coherence_scale, nugget):
        if chol.ndim == 1:  # a point alone: coherence 1 with itself (less its nugget), L = its square root
            coef[pts[0], sl] = (z[sl, pts[0], 0] + 1j * z[sl, pts[0], 1]) * (amp[sl] * chol)
            continue
        lz = chol @ z[sl][:, pts]  # (f, j, 2): L applied to the cos and sin parts of z
        coef[pts, sl] = (lz[:, :, 0] + 1j * lz[:, :, 1]).T * amp[sl]
    return coef


_FACTOR_CACHE_SIZE = 2  # factor sets kept (~14 MB each for the simulator's 65-point field)


def _coherence_factors(f_hz: np.ndarray, dist: np.ndarray, mean_speed: float, coherence_scale: float,
                       nugget: np.ndarray | None) -> list[tuple[np.ndarray, slice, np.ndarray]]:
    """The factors of the coherence matrices of :func:`_coherent_coefficients`: ``(points, frequency slice, L)``
    per coherent group and chunk of frequencies, ``L`` of shape ``(f, j, j)``, or ``(f,)`` (the square root of
    one point's own coherence, 1 less its nugget). They depend on the grid, the mean wind and the frequencies,
    not on the seed, so the last :data:`_FACTOR_CACHE_SIZE` sets are kept (read-only) for the next draws of the
    same field -- a batch of seeds, a campaign at one wind speed; factoring them is most of a draw's cost."""
    f_hz = np.ascontiguousarray(f_hz, dtype=float)
    dist = np.ascontiguousarray(dist, dtype=float)
    return _coherence_factors_of(f_hz.tobytes(), dist.tobytes(), float(mean_speed), float(coherence_scale),
                                 None if nugget is None else np.ascontiguousarray(nugget, dtype=float).tobytes())


@lru_cache(maxsize=_FACTOR_CACHE_SIZE)
def _coherence_factors_of(f_key: bytes, dist_key: bytes, mean_speed: float, coherence_scale: float,
                          nugget_key: bytes | None) -> list[tuple[np.ndarray, slice, np.ndarray]]:
    f_hz = np.frombuffer(f_key, dtype=float)
    dist = np.frombuffer(dist_key, dtype=float)
    n_side = int(round(dist.size ** 0.5))
    dist = dist.reshape(n_side, n_side)
    nugget = None if nugget_key is None else np.frombuffer(nugget_key, dtype=float).reshape(n_side, f_hz.size)
    n_points = dist.shape[0]
    out: list[tuple[np.ndarray, slice, np.ndarray]] = []
    for run, groups in _coherent_groups(dist, f_hz, mean_speed):
        for pts in groups:
            if pts.size == 1:
                own = np.ones(run.stop - run.start) if nugget is None else np.sqrt(1.0 - nugget[pts[0], run])
                out.append((pts, run, own))
                continue
            d = dist[np.ix_(pts, pts)]
            chunk = max(1, _CHOLESKY_CHUNK * n_points**2 // pts.size**2)
            for start in range(run.start, run.stop, chunk):
                sl = slice(start, min(start + chunk, run.stop))
                decay = _coherence_decay(f_hz[sl], mean_speed, coherence_scale)
                coh = np.exp(-decay[:, None, None] * d[None, :, :])
                if nugget is not None:
                    diag = np.arange(pts.size)
                    coh[:, diag, diag] -= nugget[pts, sl].T
                out.append((pts, sl, _factor(coh)))
    for pts, _, chol in out:
        pts.setflags(write=False)
        chol.setflags(write=False)
    return out


def _polar_weights(radii: np.ndarray, n_azimuth: int, radius: float) -> np.ndarray:
    """Area of the disc (m²) represented by one point of each ring: annuli with edges midway between rings."""
    edges = np.concatenate([[0.0], 0.5 * (radii[1:] + radii[:-1]), [radius]])
    ring_area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    return ring_area / n_azimuth


def _check_polar_grid(radii: object, azimuth_rad: object, radius: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    r = np.asarray(radii, dtype=float)
    psi = np.asarray(azimuth_rad, dtype=float)
    if r.ndim != 1 or r.size < 2 or not np.all(np.isfinite(r)) or r[0] < 0 or np.any(np.diff(r) <= 0):
        raise ValueError(f"radii must be >= 2 finite, increasing, non-negative radii (m), got {radii!r}")
    if psi.ndim != 1 or psi.size < 3 or not np.all(np.isfinite(psi)):
        raise ValueError(f"azimuth_rad must be >= 3 finite azimuths (rad), got {azimuth_rad!r}")
    step = 2.0 * np.pi / psi.size
    if not np.allclose(np.diff(psi), step, atol=1e-9):
        raise ValueError("azimuth_rad must be uniformly spaced over the full circle (2 pi / n_azimuth apart)")
    outer = float(r[-1]) if radius is None else check_number("radius", radius, positive=True)
    if outer < r[-1]:
        raise ValueError(f"radius ({outer} m) must be >= the largest ring radius ({r[-1]} m)")
    return r, psi, outer


def rotor_plane_fit(
    polar_u: np.ndarray, radii: np.ndarray, azimuth_rad: np.ndarray, radius: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Area-weighted least-squares plane ``u ≈ U0 + Gy y + Gz z`` fitted to a wind field on a polar grid.

    The grid is rings of radius ``radii`` (a ring of radius 0 is the hub, its azimuthal copies counted once in
    area) times uniformly spaced azimuths ``psi`` measured from the top towards +y (port), so a point sits at
    ``y = r sin(psi)``, ``z = r cos(psi)`` relative to the hub. Each point carries the area of its share of an
    annulus whose edges lie midway between rings (the outer edge at ``radius``). With uniform azimuths ``1, y, z``
    are orthogonal under these weights, so the fit decouples: ``U0 = sum(w u) / sum(w)`` (the area-weighted
    disc mean), ``Gy = sum(w u y) / sum(w y^2)``, ``Gz = sum(w u z) / sum(w z^2)``.

    A rotor responds to these gradients: yaw moment proportional to ``-Gy``, tilt moment to ``+Gz`` and side
    force to ``-Gz`` (through the blades' rotational sampling).

    Parameters
    ----------
    polar_u : array_like, shape (n_t, n_radii, n_azimuth)
        Streamwise wind (m/s) on the grid, time-major.
    radii : array_like, shape (n_radii,)
        Ring radii (m), increasing, >= 0.
    azimuth_rad : array_like, shape (n_azimuth,)
        Azimuths (rad) from the top towards +y, uniformly spaced over the circle (>= 3).
    radius : float, optional
        Outer radius of the disc (m), >= ``radii[-1]``; default ``radii[-1]``.

    Returns
    -------
    mean, shear_y, shear_z : ndarray, shape (n_t,)
        Disc mean (m/s) and the horizontal (towards +y) and vertical (upwards) gradients (1/s).

    Examples
    --------
    >>> r, psi = np.array([0.0, 30.0, 60.0]), np.arange(8) * np.pi / 4
    >>> z = r[:, None] * np.cos(psi)[None, :]
    >>> mean, gy, gz = rotor_plane_fit((10.0 + 0.02 * z)[None], r, psi, radius=63.0)
    >>> float(mean[0]), abs(float(gy[0])) < 1e-15, round(float(gz[0]), 12)
    (10.0, True, 0.02)
    """
    r, psi, outer = _check_polar_grid(radii, azimuth_rad, radius)
    u = np.asarray(polar_u)
    if u.ndim != 3 or u.shape[1:] != (r.size, psi.size):
        raise ValueError(f"polar_u must have shape (n_t, {r.size}, {psi.size}), got {u.shape}")
    w = _polar_weights(r, psi.size, outer)  # per point of each ring
    ring_sum = u.sum(axis=2, dtype=float)
    ring_sin = u @ np.sin(psi)
    ring_cos = u @ np.cos(psi)
    mean = ring_sum @ w / (w.sum() * psi.size)
    wr = w * r
    shear_y = ring_sin @ wr / (np.sum(wr * r) * np.sum(np.sin(psi) ** 2))
    shear_z = ring_cos @ wr / (np.sum(wr * r) * np.sum(np.cos(psi) ** 2))
    return mean, shear_y, shear_z


@dataclass(frozen=True)
class RotorWind:
    """Streamwise wind over the rotor disc reduced to its mean and linear gradients (SI units, time-major).

    Attributes
    ----------
    t : ndarray (n,)
        Time (s), ``t[i] = i dt``.
    hub : ndarray (n,)
        Streamwise wind at the hub point (m/s, mean included).
    rotor_effective : ndarray (n,)
        Area-weighted mean of u over the disc (m/s, mean profile included).
    shear_y : ndarray (n,)
        Horizontal gradient dU/dy of the plane fitted to u over the disc (1/s; y to port).
    shear_z : ndarray (n,)
        Vertical gradient dU/dz of that plane (1/s; z up), mean shear of the power-law profile included.
    polar_u : ndarray (n, n_radii, n_azimuth) of float32, or None
        The synthesised field on the polar grid (m/s); ``None`` when ``return_field=False``. The ring of
        radius 0 is the hub, repeated over azimuth.
    polar_radii : ndarray (n_radii,)
        Ring radii (m), from 0 (hub) to the rotor radius.
    polar_azimuth_rad : ndarray (n_azimuth,)
        Azimuths (rad) from the top towards +y (port): a point is at ``y = r sin(psi)``, ``z = H + r cos(psi)``.
    meta : dict
        ``mean_speed, turbulence_intensity, shear_exponent, hub_height, radius, seed`` (None unless an int was
        given), ``dt, n_fft, n_points, coherent_max_hz`` (above it the grid points are synthesised independently).

    Examples
    --------
    >>> w = synthesize_rotor_wind(10.0, 0.0, duration=2.0, dt=0.5, seed=0, shear_exponent=0.0)
    >>> w.hub.tolist() == [10.0] * 4 and float(np.abs(w.shear_z).max()) < 1e-12
    True
    """

    t: np.ndarray
    hub: np.ndarray
    rotor_effective: np.ndarray
    shear_y: np.ndarray
    shear_z: np.ndarray
    polar_u: np.ndarray | None
    polar_radii: np.ndarray
    polar_azimuth_rad: np.ndarray
    meta: dict = field(default_factory=dict)


def _check_count(name: str, value: object, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def synthesize_rotor_wind(
    mean_speed: float,
    turbulence_intensity: float,
    duration: float,
    dt: float,
    seed: int | np.random.SeedSequence | np.random.Generator | None = 0,
    *,
    shear_exponent: float = 0.2,
    hub_height: float = 90.0,
    radius: float = 63.0,
    n_radii: int = 5,
    n_azimuth: int = 12,
    return_field: bool = True,
    grid_spacing: float | None = None,
) -> RotorWind:
    """Synthesise the streamwise wind over the rotor disc (Veers' method) and its mean and linear gradients.

    Model (that of TurbSim's ``IECKAI`` model for the u component):

    * every point has the IEC 61400-1 ed. 3 Kaimal spectrum :func:`kaimal_spectrum` with the hub-height
      ``sigma = TI V`` (uniform over the disc) and the hub-height length scale;
    * two points a distance r apart have the IEC coherence ``exp(-12 sqrt((f r / V)^2 + (0.12 r / L_c)^2))``,
      ``L_c = 8.1 Lambda_1`` (:func:`turbulence_length_scale`; TurbSim prints it as the u-coherence parameters
      ``(12, 0.12 / L_c)``), real (no phase);
    * the mean power-law profile ``V ((H + z) / H)^alpha`` is added;
    * with ``grid_spacing``, the points (all but the hub) carry the field as OpenFAST reads it from a TurbSim
      grid of that spacing, by bilinear interpolation: the point spectrum times ``H(f)`` of
      :func:`grid_interpolation_variance` (down to 4/9 where neighbouring grid points are incoherent, ~0.3 Hz
      upwards at 12 m/s and 4.8 m), the cross-spectra between points those of the points (exact for points
      a few grid cells apart, as on the default polar grid). The hub is a grid node (TurbSim centres one
      there), unsmoothed. Measured on the OC3 reference run at 12 m/s, with the same rotor sampling: the TurbSim
      field's collective rotationally sampled wind carries 0.6x, 0.5x and 0.4x the variance of a point-value
      field in 0.4-0.5, 0.7-1 and 2-3 Hz, as the interpolated synthetic grid does (0.7x, 0.55x, 0.47x).

    The points form a polar grid: the hub and ``n_radii - 1`` rings at radii ``k R / (n_radii - 1)``, each with
    ``n_azimuth`` points from the top towards +y. Per frequency of the FFT grid the coherence matrix is factored
    ``C = L L^T`` (Cholesky) and the points' Fourier coefficients are ``sqrt(2 S df) L z`` with ``z`` independent
    unit-amplitude components of uniform random phase; one inverse real FFT per point gives its series. Above
    ``coherent_max_hz = V ln(1e4) / (12 d_min)`` (``d_min`` the closest pair of points) every coherence is below
    1e-4, ``L`` is the identity to that accuracy and the points are synthesised independently, so the spectrum
    reaches the Nyquist frequency ``1 / (2 dt)`` at the cost of an FFT per point (the Cholesky factors are only
    needed up to about 1-2 Hz). Below it the same floor applies group by group: from the frequency where all
    coherences between two groups of points (on the polar grid: the hub and the rings, then the outer rings'
    own points) are below 1e-4, each group's coherence matrix is factored on its own (``L`` block diagonal;
    the whole grid's factorisation, the bulk of the cost, is needed only up to about ``0.05 V`` Hz). As in
    :func:`synthesize_wind` the series are the first ``n = round(duration/dt)`` samples of a record periodic
    over ``n_fft = next_fast_len(n)``; variance below ``df`` and at the Nyquist frequency is absent.

    The disc mean and gradients come from :func:`rotor_plane_fit` on the grid (area weights). With the default
    5 x 12 grid their variances are within about 1 % of those of the continuous disc (checked against a
    24 x 64 grid). The power-law profile's plane fit gives a mean ``shear_z`` slightly above ``alpha V / H``: at
    12 m/s 0.0286 1/s over the continuous disc (0.0288 on the default grid) against 0.0267 1/s.

    Parameters
    ----------
    mean_speed : float
        Mean wind at hub height V (m/s), >= 0 (0 gives calm air).
    turbulence_intensity : float
        TI = sigma / V at hub height (-), 0 <= TI < 1; 0 gives the steady sheared wind.
    duration : float
        Record length (s), >= dt.
    dt : float
        Sample time (s), > 0.
    seed : int, SeedSequence, Generator or None, default 0
        Source of the random phases; the same seed gives the same bytes.
    shear_exponent : float, default 0.2
        Power-law exponent alpha of the mean profile (-), >= 0 (IEC 61400-1 NTM: 0.2).
    hub_height : float, default 90
        Hub height H (m), > ``radius``.
    radius : float, default 63
        Rotor radius R (m), > 0.
    n_radii : int, default 5
        Rings including the hub (>= 2).
    n_azimuth : int, default 12
        Points per ring (>= 3).
    return_field : bool, default True
        Keep the field on the polar grid (``n * n_radii * n_azimuth`` float32 values; 13 MB for 700 s at
        0.0125 s); with False only the reduced series are kept (memory O(n)).
    grid_spacing : float, optional
        Spacing (m) of the Cartesian grid the field is read from by bilinear interpolation, > 0
        (:data:`TURBSIM_GRID_SPACING` for the OC3 reference deck); None: point values.

    Returns
    -------
    RotorWind

    Raises
    ------
    ValueError
        An argument is not finite or out of range (the message names it).

    Examples
    --------
    >>> w = synthesize_rotor_wind(12.0, 0.17, duration=600.0, dt=0.05, seed=2)
    >>> w.polar_u.shape, bool(w.rotor_effective.std() < w.hub.std())
    ((12000, 5, 12), True)
    >>> bool(0.02 < w.shear_z.mean() < 0.035)
    True
    """
    v = check_number("mean_speed", mean_speed, nonneg=True)
    ti = _check_ti(turbulence_intensity)
    duration = check_number("duration", duration, positive=True)
    dt = check_number("dt", dt, positive=True)
    alpha = check_number("shear_exponent", shear_exponent, nonneg=True)
    hub_height = check_number("hub_height", hub_height, positive=True)
    radius = check_number("radius", radius, positive=True)
    if radius >= hub_height:
        raise ValueError(f"radius ({radius} m) must be smaller than hub_height ({hub_height} m)")
    n_radii = _check_count("n_radii", n_radii, 2)
    n_azimuth = _check_count("n_azimuth", n_azimuth, 3)
    if duration < dt:
        raise ValueError(f"duration ({duration} s) must be at least one sample time dt ({dt} s)")
    spacing = None if grid_spacing is None else check_number("grid_spacing", grid_spacing, positive=True)
    rng = _generator(seed)
    n_out = int(round(duration / dt))
    n_fft = next_fast_len(n_out, real=True)
    t = np.arange(n_out) * dt

    radii = np.arange(n_radii) * radius / (n_radii - 1)
    psi = np.arange(n_azimuth) * 2.0 * np.pi / n_azimuth
    # points: the hub, then ring by ring, azimuth fastest
    y = np.concatenate([[0.0], (radii[1:, None] * np.sin(psi)[None, :]).ravel()])
    z = np.concatenate([[0.0], (radii[1:, None] * np.cos(psi)[None, :]).ravel()])
    n_points = y.size
    u_mean = v * ((hub_height + z) / hub_height) ** alpha
    # plane-fit rows for the points (the hub point carries the whole central disc)
    w_ring = _polar_weights(radii, n_azimuth, radius)
    w_pt = np.concatenate([[w_ring[0] * n_azimuth], np.repeat(w_ring[1:], n_azimuth)])
    proj = np.stack([w_pt / w_pt.sum(), w_pt * y / np.sum(w_pt * y * y), w_pt * z / np.sum(w_pt * z * z)])

    dist = np.hypot(y[:, None] - y[None, :], z[:, None] - z[None, :])
    d_min = float(dist[np.triu_indices(n_points, 1)].min())
    f_coherent = (v * np.log(1.0 / _COHERENCE_FLOOR) / (12.0 * d_min)) if v > 0.0 else 0.0
    meta = {
        "mean_speed": v, "turbulence_intensity": ti, "shear_exponent": alpha, "hub_height": hub_height,
        "radius": radius, "seed": int(seed) if isinstance(seed, int | np.integer) else None, "dt": dt,
        "n_fft": int(n_fft), "n_points": int(n_points), "coherent_max_hz": float(f_coherent),
        "grid_spacing": spacing,
    }
    polar = np.empty((n_out, n_radii, n_azimuth), dtype=np.float32) if return_field else None
    if not (v > 0.0 and ti > 0.0):  # the steady sheared wind
        series = np.broadcast_to(u_mean[:, None], (n_points, n_out))
        if polar is not None:
            polar[:] = np.concatenate([np.full(n_azimuth, u_mean[0]), u_mean[1:]]).reshape(n_radii, n_azimuth)
        reduced = proj @ series
        return RotorWind(t, np.full(n_out, u_mean[0]), reduced[0], reduced[1], reduced[2], polar, radii, psi, meta)

    freqs = np.fft.rfftfreq(n_fft, dt)
    keep = np.flatnonzero((freqs > 0.0) & (freqs < 0.5 / dt))
    amp = np.sqrt(2.0 * kaimal_spectrum(freqs[keep], v, ti, hub_height) / (n_fft * dt)) * (0.5 * n_fft)
    n_low = int(np.searchsorted(freqs[keep], f_coherent, side="right"))
    # keep is the contiguous bins 1 .. (Nyquist excluded): the coherent band, then the rest
    low = slice(int(keep[0]), int(keep[0]) + n_low) if keep.size else slice(0, 0)
    high = slice(low.stop, int(keep[-1]) + 1 if keep.size else 0)
    # the grid's share of each point's spectrum: H(f) off the hub, 1 at the hub (a grid node)
    h_grid = np.ones(keep.size) if spacing is None else grid_interpolation_variance(freqs[keep], v, spacing,
                                                                                     hub_height)
    on_grid = np.arange(n_points) > 0
    nugget = None if spacing is None else on_grid[:, None] * (1.0 - h_grid[None, :n_low])
    coef_low = _coherent_coefficients(rng, freqs[low], amp[:n_low], dist, v, turbulence_length_scale(hub_height),
                                      nugget)
    amp_high = amp[n_low:]
    amp_high_grid = amp_high * np.sqrt(h_grid[n_low:])
    n_high = amp_high.size
    reduced = np.zeros((3, n_out))
    hub = np.empty(0)
    flat = None if polar is None else polar.reshape(n_out, n_radii * n_azimuth)  # point j >= 1: column j + n_az - 1
    # points in blocks (one batched inverse FFT each, memory bounded); the random phases above the coherent
    # band are drawn point after point, as one draw per point would
    block = max(1, min(n_points, _FFT_BLOCK_VALUES // n_fft))
    for j0 in range(0, n_points, block):
        j1 = min(j0 + block, n_points)
        spectrum = np.zeros((j1 - j0, max(high.stop, 1)), dtype=complex)  # irfft zero-pads up to Nyquist
        spectrum[:, low] = coef_low[j0:j1]
        phase = rng.uniform(0.0, 2.0 * np.pi, (j1 - j0, n_high))
        a_high = np.where(on_grid[j0:j1, None], amp_high_grid[None, :], amp_high[None, :])
        spectrum.real[:, high] = a_high * np.cos(phase)  # a_high e^{i phase}, without a complex exp
        spectrum.imag[:, high] = a_high * np.sin(phase)
        # irfft gives (1/N) sum_k X_k e^{2 pi i k m / N} + c.c.; the N/2 in amp makes it sum_k Re(X_k e^{i w_k t})
        series = irfft(spectrum, n=n_fft, axis=-1)[:, :n_out]
        series += u_mean[j0:j1, None]
        reduced += proj[:, j0:j1] @ series
        if j0 == 0:
            hub = series[0].copy()
            if flat is not None:
                polar[:, 0, :] = series[0][:, None]
        if flat is not None:
            r0 = max(j0, 1)
            flat[:, r0 + n_azimuth - 1: j1 + n_azimuth - 1] = series[r0 - j0:].T
    return RotorWind(t, hub, reduced[0], reduced[1], reduced[2], polar, radii, psi, meta)


def hub_series(t: object, hub: object, name: str = "t and hub") -> tuple[np.ndarray, np.ndarray]:
    """A measured hub-height wind series, checked: ``(t, u)`` as float arrays (s, m/s).

    Raises
    ------
    ValueError
        Unless both are 1-D of the same length >= 2, finite, with ``t`` strictly increasing (``name`` leads the
        message).
    """
    tm = np.asarray(t, dtype=float)
    hm = np.asarray(hub, dtype=float)
    if tm.ndim != 1 or hm.shape != tm.shape or tm.size < 2:
        raise ValueError(f"{name} must be 1-D arrays of the same length >= 2, got shapes {tm.shape} and {hm.shape}")
    if not (np.all(np.isfinite(tm)) and np.all(np.isfinite(hm))):
        raise ValueError(f"{name} must be finite (fill or cut the gaps of a measured series first)")
    if np.any(np.diff(tm) <= 0):
        raise ValueError(f"{name}: the time axis must be strictly increasing")
    return tm, hm


def constrain_to_hub(wind: RotorWind, t: np.ndarray, hub: np.ndarray, *, ramp: float = 20.0) -> RotorWind:
    """A synthesised rotor field conditioned on a measured hub-height wind (a constrained realisation).

    Given a hub series ``h(t)`` (a nacelle anemometer, a met mast at hub height, OpenFAST's ``Wind1VelX``), the
    rest of the field is drawn from the IEC model *given* ``h``: the Hoffman-Ribak construction
    ``u_j <- u_j + K_j * (h - u_hub)`` with ``u`` an unconstrained draw (``wind``) and ``K_j`` the regression
    of point ``j`` on the hub, which for the model of :func:`synthesize_rotor_wind` is the zero-phase filter
    ``K_j(f) = Coh(r_j, f) = exp(-a(f) r_j)`` (the IEC coherence at the point's distance ``r_j`` from the hub;
    cross-spectrum over the hub's spectrum). For jointly Gaussian fields ``u_j - K_j * u_hub`` is independent of
    ``u_hub``, so the result is an exact draw of the field conditioned on the measured hub series: the hub point
    is ``h``, a point at distance r keeps ``S (1 - Coh^2)`` of its spectrum as fresh randomness (the seed), and
    where ``h`` is itself a draw of the model the field's statistics are those of an unconstrained field. This is
    the idea of TurbSim's user time-series constraint, here only at the hub. Use it to repeat a measured wind's
    slow gusts (which a single 10-minute draw of the spectrum meets only by chance) while the rotor-plane
    structure stays random.

    The constraint is radial, so the disc's linear gradients (``shear_y``, ``shear_z``) are unchanged and the disc
    mean gains the area-weighted ring average of the corrections. Only the fluctuation of ``h`` is used: its mean
    is replaced by the field's hub mean (the load case's wind speed; give the series' mean as the case's wind).
    Outside the measured span the correction fades in (before) and out (after) over ``ramp`` seconds with a
    raised cosine, so a simulation's start-up can run unconstrained into the measured window.

    Parameters
    ----------
    wind : RotorWind
        An unconstrained draw with its polar field (``synthesize_rotor_wind(..., return_field=True)``) and a
        mean speed > 0.
    t : array_like, shape (m,)
        Times (s) of the hub series on the field's time axis (``wind.t``), strictly increasing, m >= 2.
    hub : array_like, shape (m,)
        Hub-height streamwise wind (m/s), finite.
    ramp : float, default 20
        Length (s) of the fade-in before ``t[0]`` and fade-out after ``t[-1]``, >= 0.

    Returns
    -------
    RotorWind
        The constrained field; ``meta["constrained_to_hub"]`` records the span, the ramp and the series' mean.

    Raises
    ------
    ValueError
        A field without its polar grid or mean wind, or a bad series (the message names it).

    Examples
    --------
    >>> w = synthesize_rotor_wind(12.0, 0.17, duration=120.0, dt=0.05, seed=1)
    >>> t = np.arange(0.0, 100.0, 0.05)
    >>> h = 12.0 + np.sin(2 * np.pi * 0.02 * t)
    >>> c = constrain_to_hub(w, t, h, ramp=10.0)
    >>> bool(np.allclose(c.hub[:2000], h, atol=1e-9)), bool(np.array_equal(c.shear_y, w.shear_y))
    (True, True)
    """
    if wind.polar_u is None:
        raise ValueError("wind must carry its polar field: synthesize_rotor_wind(..., return_field=True)")
    v = float(wind.meta.get("mean_speed", 0.0))
    if not v > 0.0:
        raise ValueError("wind must have a mean speed > 0 m/s to be constrained to a hub series")
    tm, hm = hub_series(t, hub)
    ramp = check_number("ramp", ramp, nonneg=True)
    tf = wind.t
    n = tf.size
    dt = float(tf[1] - tf[0]) if n > 1 else 1.0
    target = v + np.interp(tf, tm, hm - hm.mean())  # the profile's hub value plus the measured fluctuation
    weight = np.ones(n)
    if ramp > 0.0:
        before, after = (tm[0] - tf) / ramp, (tf - tm[-1]) / ramp
        weight = np.where(before > 0.0, 0.5 + 0.5 * np.cos(np.pi * np.clip(before, 0.0, 1.0)), weight)
        weight = np.where(after > 0.0, 0.5 + 0.5 * np.cos(np.pi * np.clip(after, 0.0, 1.0)), weight)
    else:
        weight[(tf < tm[0]) | (tf > tm[-1])] = 0.0
    residual = weight * (target - wind.hub)
    n_fft = next_fast_len(2 * n, real=True)  # zero padding: the zero-phase filter does not wrap around
    spectrum = rfft(residual, n_fft)
    f = np.fft.rfftfreq(n_fft, dt)
    hub_height = float(wind.meta.get("hub_height", 90.0))
    decay = _coherence_decay(f, v, turbulence_length_scale(hub_height))
    radii = np.asarray(wind.polar_radii, dtype=float)
    corr = irfft(np.exp(-decay[None, :] * radii[:, None]) * spectrum[None, :], n_fft, axis=-1)[:, :n]
    corr[radii == 0.0] = residual  # the hub itself: exactly the measured series
    polar = wind.polar_u + corr.T[:, :, None].astype(np.float32)
    w_ring = _polar_weights(radii, wind.polar_azimuth_rad.size, float(wind.meta.get("radius", radii[-1])))
    rotor_effective = wind.rotor_effective + (w_ring @ corr) / w_ring.sum()
    meta = {**wind.meta, "constrained_to_hub": {"t_start": float(tm[0]), "t_end": float(tm[-1]), "ramp": ramp,
                                                "series_mean": float(hm.mean())}}
    return RotorWind(tf.copy(), wind.hub + residual, rotor_effective, wind.shear_y.copy(), wind.shear_z.copy(),
                     polar, wind.polar_radii, wind.polar_azimuth_rad, meta)
