"""Rotor-plane wind (:func:`surrogates.wind.synthesize_rotor_wind`): spectra, coherence, shear, OpenFAST inflow."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import dblquad
from scipy.signal import butter, coherence, csd, sosfiltfilt, welch

from surrogates.wind import (
    kaimal_spectrum,
    rotor_averaging,
    rotor_plane_fit,
    synthesize_rotor_wind,
    synthesize_wind,
    turbulence_length_scale,
)

REFERENCE = Path("/work/shared/reference/openfast")


def _point_yz(w):
    """(y, z) of the polar grid points relative to the hub, shape (n_radii, n_azimuth)."""
    r, psi = w.polar_radii[:, None], w.polar_azimuth_rad[None, :]
    return r * np.sin(psi), r * np.cos(psi)


def test_shapes_determinism_and_field_consistency():
    w = synthesize_rotor_wind(12.0, 0.15, duration=120.0, dt=0.025, seed=7)
    n = 4800
    assert w.t.shape == w.hub.shape == w.rotor_effective.shape == w.shear_y.shape == w.shear_z.shape == (n,)
    assert w.polar_u.shape == (n, 5, 12) and w.polar_u.dtype == np.float32
    assert w.polar_radii[0] == 0.0 and w.polar_radii[-1] == 63.0
    np.testing.assert_allclose(w.polar_azimuth_rad, np.arange(12) * np.pi / 6)
    again = synthesize_rotor_wind(12.0, 0.15, duration=120.0, dt=0.025, seed=7, return_field=False)
    assert again.polar_u is None
    for name in ("hub", "rotor_effective", "shear_y", "shear_z"):
        assert getattr(w, name).tobytes() == getattr(again, name).tobytes()
    # the reduced series are the plane fit of the field (float32 rounding only)
    mean, gy, gz = rotor_plane_fit(w.polar_u, w.polar_radii, w.polar_azimuth_rad, radius=63.0)
    np.testing.assert_allclose(mean, w.rotor_effective, atol=1e-5)
    np.testing.assert_allclose(gy, w.shear_y, atol=1e-7)
    np.testing.assert_allclose(gz, w.shear_z, atol=1e-7)
    np.testing.assert_allclose(w.polar_u[:, 0, :], np.broadcast_to(w.hub[:, None], (n, 12)), atol=1e-5)
    # the existing two-series synthesis is untouched
    assert synthesize_wind(12.0, 0.15, duration=10.0, dt=0.1, seed=1).hub.shape == (100,)


def test_rotor_plane_fit_recovers_a_plane():
    r, psi = np.array([0.0, 15.0, 30.0, 45.0, 60.0]), np.arange(16) * np.pi / 8
    y, z = r[:, None] * np.sin(psi), r[:, None] * np.cos(psi)
    field = np.stack([9.0 + 0.01 * y - 0.03 * z, 11.0 - 0.02 * y + 0.04 * z])
    mean, gy, gz = rotor_plane_fit(field, r, psi, radius=63.0)
    np.testing.assert_allclose(mean, [9.0, 11.0])
    np.testing.assert_allclose(gy, [0.01, -0.02])
    np.testing.assert_allclose(gz, [-0.03, 0.04])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius": 95.0}, "radius"),
        ({"n_radii": 1}, "n_radii"),
        ({"n_azimuth": 2}, "n_azimuth"),
        ({"shear_exponent": -0.1}, "shear_exponent"),
        ({"n_radii": True}, "n_radii"),
    ],
)
def test_bad_arguments_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        synthesize_rotor_wind(12.0, 0.1, 10.0, 0.1, 0, **kwargs)


def test_hub_variance_is_the_kaimal_variance():
    # random phases, deterministic amplitudes: the hub variance is the Kaimal integral over the FFT grid (no
    # sampling scatter); that grid misses the content below df and above the Nyquist frequency (about 1.5 %)
    v, ti, dt = 12.0, 0.15, 0.05
    w = synthesize_rotor_wind(v, ti, duration=3600.0, dt=dt, seed=3, return_field=False)
    n_fft = w.meta["n_fft"]
    f = np.fft.rfftfreq(n_fft, dt)[1:-1]
    riemann = np.sum(kaimal_spectrum(f, v, ti)) / (n_fft * dt)
    assert w.hub.var() == pytest.approx(riemann, rel=0.01)
    assert w.hub.var() == pytest.approx((ti * v) ** 2, rel=0.03)


def test_disc_mean_variance_matches_rotor_averaging():
    # closed form: sum over the FFT grid of H2(f) S(f) df. Sampling tolerance from the seeds' own scatter (the
    # disc mean mixes independent phase components, so its variance is random: about 4 % per 2 h record);
    # the 5 x 12 grid's quadrature adds < 1 % at 12 m/s.
    v, ti, dt, duration = 12.0, 0.15, 1.0, 7200.0  # dt: content above 0.5 Hz is irrelevant here
    variances = []
    for seed in range(8):
        w = synthesize_rotor_wind(v, ti, duration, dt, seed=seed, return_field=False)
        variances.append(w.rotor_effective.var())
    n_fft = w.meta["n_fft"]
    f = np.fft.rfftfreq(n_fft, dt)[1:-1]
    h2, _ = rotor_averaging(f, v)
    expected = np.sum(h2 * kaimal_spectrum(f, v, ti)) / (n_fft * dt)
    standard_error = np.std(variances, ddof=1) / np.sqrt(len(variances))
    assert abs(np.mean(variances) - expected) < 4.0 * standard_error + 0.01 * expected
    assert standard_error < 0.05 * expected  # the tolerance is meaningful


def test_point_coherence_is_the_iec_coherence():
    # coherency (co-spectrum over the geometric mean of the auto-spectra; the IEC coherence is real) estimated by
    # Welch (1024-sample Hann segments) pooled over 4 two-hour records (~80 effective averages), averaged over ~5
    # bins (+-0.005 Hz): scatter ~0.08 per bin, ~0.035 per band, so +-0.1 is about 3 standard errors (24 records
    # agree to 0.02: 0.634/0.276/0.065 against 0.632/0.288/0.041 at 63 m). scipy's magnitude-squared coherence
    # |Sxy|^2/(Sxx Syy) gives the same picture (Coh^2) with an upward bias of ~0.02 at low coherence.
    v, dt = 12.0, 0.5
    lc = turbulence_length_scale(90.0)
    pairs = [((0, 0), (1, 0)), ((1, 0), (1, 3)), ((0, 0), (4, 6))]  # r = 15.75 m, 22.3 m, 63 m
    pooled = {}
    for seed in range(4):
        w = synthesize_rotor_wind(v, 0.15, duration=7200.0, dt=dt, seed=seed)
        for a, b in pairs:
            x, y_ = w.polar_u[:, a[0], a[1]], w.polar_u[:, b[0], b[1]]
            f, sxy = csd(x, y_, fs=1.0 / dt, nperseg=1024)
            sums = np.stack([sxy.real, welch(x, fs=1.0 / dt, nperseg=1024)[1], welch(y_, fs=1.0 / dt, nperseg=1024)[1]])
            pooled[a, b] = pooled.get((a, b), 0.0) + sums
    f_msc, msc = coherence(x, y_, fs=1.0 / dt, nperseg=1024)  # last pair (63 m) of the last record
    y, z = _point_yz(w)
    for (a, b), (co, sxx, syy) in pooled.items():
        r = np.hypot(y[a] - y[b], z[a] - z[b])
        coherency = co / np.sqrt(sxx * syy)
        for f0 in (0.005, 0.02, 0.05):
            band = np.abs(f - f0) < 0.005
            iec = np.exp(-12.0 * np.sqrt((f[band] * r / v) ** 2 + (0.12 * r / lc) ** 2))
            assert np.mean(coherency[band]) == pytest.approx(np.mean(iec), abs=0.1), (r, f0)
    band = np.abs(f_msc - 0.005) < 0.005
    iec = np.exp(-12.0 * np.sqrt((f_msc[band] * 63.0 / v) ** 2 + (0.12 * 63.0 / lc) ** 2))
    assert np.mean(msc[band]) == pytest.approx(np.mean(iec**2), abs=0.12)


def _power_law_plane_shear(v, hub_height, radius, alpha):
    """Gz of the area-weighted least-squares plane through V ((H + z)/H)^alpha over the disc (1/s)."""
    num, _ = dblquad(
        lambda r, p: v * ((hub_height + r * np.cos(p)) / hub_height) ** alpha * r * np.cos(p) * r,
        0.0,
        2.0 * np.pi,
        0.0,
        radius,
    )
    return num / (np.pi * radius**4 / 4.0)


@pytest.mark.parametrize("v", [8.0, 18.0])
def test_mean_vertical_shear_is_the_power_law_plane(v):
    expected = _power_law_plane_shear(v, 90.0, 63.0, 0.2)
    assert expected == pytest.approx(0.2 * v / 90.0, rel=0.08)  # the plane is close to the derivative at hub
    steady = synthesize_rotor_wind(v, 0.0, duration=10.0, dt=1.0, seed=0)
    assert steady.shear_z == pytest.approx(np.full(10, expected), rel=0.01)  # 5 x 12 grid: +0.7 %
    assert np.abs(steady.shear_y).max() < 1e-12
    turbulent = synthesize_rotor_wind(v, 0.15, duration=3600.0, dt=0.2, seed=5, return_field=False)
    # turbulent fluctuations average out: std(Gz) ~ 0.02 1/s, correlation time ~ 10 s -> ~ 0.0015 over 1 h
    assert turbulent.shear_z.mean() == pytest.approx(expected, abs=0.004)
    assert abs(turbulent.shear_y.mean()) < 0.004


# --- OpenFAST / TurbSim reference inflow ------------------------------------------------------------------------

CASES = [
    ("c_op08", 8.0, "NTM_B_08mps_s801_700s"),
    ("c_op12", 12.0, "NTM_B_12mps_s1201_700s"),
    ("c_op18", 18.0, "NTM_B_18mps_s1801_700s"),
]


def _grid_sigma(summary: Path) -> float | None:
    """TurbSim's realised 'Mean standard deviation across all grid points' of u (m/s) from its .sum file."""
    if not summary.exists():
        return None
    text = summary.read_text(errors="replace")
    match = re.search(r"Mean standard deviation across all grid points:\s*u component:\s*([0-9.]+)", text)
    return float(match.group(1)) if match else None


def _gradient_stats(mean, gy, gz, dt):
    """std of (disc mean, Gy, Gz) full band, then of (Gy, Gz) low-passed below 0.15 Hz."""
    sos = butter(4, 0.15, fs=1.0 / dt, output="sos")
    low = [sosfiltfilt(sos, x - x.mean()).std() for x in (gy, gz)]
    return np.array([mean.std(), gy.std(), gz.std(), *low])


@pytest.mark.skipif(not REFERENCE.exists(), reason="OpenFAST reference runs not available")
@pytest.mark.parametrize(("case", "v", "wind"), CASES)
def test_gradient_fluctuations_match_turbsim_inflow(case, v, wind):
    """std of the disc mean and of the fitted gradients, ours (8 seeds) against the TurbSim field OpenFAST saw.

    Both are fitted with :func:`rotor_plane_fit` (the reference on its 0-60 m x 16 polar grid, disc edge 63 m).
    Ours is run at the field's realised turbulence level: TurbSim's grid-mean realised sigma (.sum file; the
    runs used ScaleIEC = 0, so the hub point's realised TI - 19.9/19.5/15.1 % - is one sample of it and at
    12 m/s lies 11 % above the grid mean 17.5 %). Tolerance: 3 seed-to-seed standard deviations of one record
    (about 10 % of the std of each quantity), i.e. a single realisation against the ensemble.
    """
    files = sorted(REFERENCE.glob(f"runs/{case}*/*.inflow.npz"))
    if not files:
        pytest.skip(f"no inflow file for {case}")
    with np.load(files[0], allow_pickle=False) as d:
        t, polar, radii, psi = d["t"], d["polar_u"], d["polar_radii"], d["polar_azimuth_rad"]
        disc, hub = d["disc_mean_u"], d["hub_uvw"][:, 0]
    dt = float(np.median(np.diff(t)))
    mean, gy, gz = rotor_plane_fit(polar, radii, psi, radius=63.0)
    assert np.corrcoef(mean, disc)[0, 1] > 0.99  # our fit's mean is the file's disc mean
    ref = _gradient_stats(mean, gy, gz, dt)
    sigma = _grid_sigma(REFERENCE / "decks/5MW_Baseline/Wind" / f"{wind}.sum") or float(hub.std())
    ti = sigma / v
    ours = []
    for seed in range(8):
        w = synthesize_rotor_wind(v, ti, t.size * dt, 0.1, seed=seed, return_field=False)
        ours.append(_gradient_stats(w.rotor_effective, w.shear_y, w.shear_z, 0.1))
    ours = np.array(ours)
    centre, scatter = ours.mean(axis=0), ours.std(axis=0, ddof=1)
    assert np.all(np.abs(ref - centre) < 3.0 * scatter), (ref, centre, scatter)
