"""Kaimal turbulence, IEC turbulence model and rotor averaging against IEC 61400-1 ed. 3 and brute force.

Truth used here: the IEC 61400-1 ed. 3 formulas (Kaimal spectrum and its integral, the normal turbulence
model, the exponential coherence), a brute-force quasi-Monte-Carlo average of the coherence over pairs of
points on the rotor disc, and sample statistics of synthesised records.
"""

import numpy as np
import pytest
from scipy.fft import next_fast_len
from scipy.integrate import quad
from scipy.signal import welch
from scipy.stats import qmc

from surrogates.wind import (
    iec_turbulence_intensity,
    kaimal_spectrum,
    rotor_averaging,
    synthesize_wind,
    turbulence_length_scale,
)

R, V = 63.0, 12.0
LC = 8.1 * 42.0  # IEC 61400-1 ed. 3: Lambda_1 = 42 m above 60 m hub height, L = 8.1 Lambda_1


@pytest.fixture(scope="module")
def disc_pairs():
    """2^18 scrambled-Sobol pairs of points uniform on the rotor disc: their distances, and to the hub."""
    u = qmc.Sobol(d=4, scramble=True, seed=1).random_base2(m=18)
    r1, t1 = R * np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
    r2, t2 = R * np.sqrt(u[:, 2]), 2 * np.pi * u[:, 3]
    between = np.hypot(r1 * np.cos(t1) - r2 * np.cos(t2), r1 * np.sin(t1) - r2 * np.sin(t2))
    return between, r1


def iec_coherence(r, f, v=V):
    return np.exp(-12.0 * np.sqrt((f * r / v) ** 2 + (0.12 * r / LC) ** 2))


# ------------------------------------------------------------------------------------------------- Kaimal
@pytest.mark.parametrize(("v", "ti", "hub"), [(12.0, 0.17, 90.0), (6.0, 0.25, 50.0), (25.0, 0.1, 120.0)])
def test_kaimal_variance_is_sigma_squared(v, ti, hub):
    # int_0^inf 4 (L/V) / (1 + 6 f L/V)^(5/3) df = 1, so the variance is sigma^2 = (TI V)^2
    var, _ = quad(lambda f: float(kaimal_spectrum(f, v, ti, hub)), 0.0, np.inf, limit=500)
    assert var == pytest.approx((ti * v) ** 2, rel=1e-6)


def test_kaimal_length_scale_and_shape():
    # IEC 61400-1 ed. 3, eq. (5) and Table B.1: L_u = 8.1 Lambda_1, Lambda_1 = 0.7 z (z <= 60 m) or 42 m
    assert turbulence_length_scale(90.0) == pytest.approx(340.2)
    assert turbulence_length_scale(50.0) == pytest.approx(8.1 * 35.0)
    assert turbulence_length_scale(60.0) == pytest.approx(8.1 * 42.0)
    v, ti = 10.0, 0.2
    assert float(kaimal_spectrum(0.0, v, ti, 50.0)) == pytest.approx(4 * (ti * v) ** 2 * 283.5 / v)
    # inertial subrange: S ~ f^(-5/3)
    s1, s2 = kaimal_spectrum([10.0, 20.0], v, ti)
    assert np.log(s2 / s1) / np.log(2.0) == pytest.approx(-5 / 3, abs=2e-3)
    assert not np.any(kaimal_spectrum([0.0, 0.1], v, 0.0))


def test_iec_normal_turbulence_model():
    # IEC 61400-1 ed. 3, eq. (11): sigma_1 = I_ref (0.75 V + 5.6), I_ref = 0.16 / 0.14 / 0.12 (A / B / C)
    assert iec_turbulence_intensity(15.0, "B") == pytest.approx(0.1573, abs=5e-5)
    assert iec_turbulence_intensity(10.0, "A") == pytest.approx(0.16 * 13.1 / 10.0)
    assert iec_turbulence_intensity(5.0, "C") == pytest.approx(0.12 * 9.35 / 5.0)
    assert iec_turbulence_intensity(11.4) == pytest.approx(0.14 * (0.75 * 11.4 + 5.6) / 11.4)
    with pytest.raises(ValueError, match="turbulence_class"):
        iec_turbulence_intensity(10.0, "D")
    with pytest.raises(ValueError, match="mean_speed"):
        iec_turbulence_intensity(0.0)


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [({"mean_speed": 0.0}, "mean_speed"), ({"mean_speed": np.nan}, "mean_speed"),
     ({"turbulence_intensity": -0.1}, "turbulence_intensity"),
     ({"turbulence_intensity": 1.0}, "turbulence_intensity"),
     ({"hub_height": 0.0}, "hub_height"), ({"f_hz": [-0.1]}, "f_hz"), ({"f_hz": [np.inf]}, "f_hz")],
)
def test_kaimal_rejects_bad_input(kwargs, word):
    args = {"f_hz": [0.1], "mean_speed": 10.0, "turbulence_intensity": 0.1, **kwargs}
    with pytest.raises(ValueError, match=word):
        kaimal_spectrum(**args)


# ----------------------------------------------------------------------------------------- rotor averaging
def test_rotor_averaging_matches_brute_force_disc_quadrature(disc_pairs):
    between, to_hub = disc_pairs
    f = np.array([0.0, 0.02, 0.1, 0.3])
    h2, g = rotor_averaging(f, V, R, 90.0)
    for fi, h2_i, g_i, tol in zip(f, h2, g, (1e-4, 1e-4, 1e-3, 1e-2), strict=True):
        assert h2_i == pytest.approx(iec_coherence(between, fi).mean(), rel=tol)
        assert g_i == pytest.approx(iec_coherence(to_hub, fi).mean(), rel=1e-4)


def test_rotor_averaging_on_a_long_fft_grid_matches_brute_force(disc_pairs):
    between, to_hub = disc_pairs
    f = np.fft.rfftfreq(96000, 0.0125)  # the grid of 1200 s at 80 Hz: interpolated internally
    h2, g = rotor_averaging(f, V)
    for target in (0.0, 0.013, 0.05, 0.2):
        i = int(np.argmin(np.abs(f - target)))
        assert h2[i] == pytest.approx(iec_coherence(between, f[i]).mean(), rel=3e-3)
        assert g[i] == pytest.approx(iec_coherence(to_hub, f[i]).mean(), rel=1e-4)
    assert np.all(np.diff(h2) < 0) and np.all(np.diff(g) < 0)
    assert np.all(h2 >= g**2)


def test_rotor_averaging_limits_and_properties():
    f = np.concatenate([[0.0], np.geomspace(1e-4, 40.0, 60)])
    h2, g = rotor_averaging(f, V)
    assert np.all((h2 > 0) & (h2 <= 1)) and np.all((g > 0) & (g <= 1))
    assert np.all(np.diff(h2) < 0) and np.all(np.diff(g) < 0)
    assert np.all(h2 >= g**2)  # the spectral matrix [[1, g], [g, h2]] is positive semi-definite
    # f -> 0: only the 0.12 r / L_c term is left; for a point-sized rotor both ratios tend to 1
    h2_small, g_small = rotor_averaging([0.0, 0.001], V, rotor_radius=0.01)
    np.testing.assert_allclose(h2_small, 1.0, atol=1e-4)
    np.testing.assert_allclose(g_small, 1.0, atol=1e-4)
    # high frequency: near p the coherence is exp(-a |p - q|) and both ratios behave as 2 / (a R)^2
    a = 12 * np.sqrt((f[-1] / V) ** 2 + (0.12 / LC) ** 2)
    assert h2[-1] == pytest.approx(2 / (a * R) ** 2, rel=2e-3)
    assert g[-1] == pytest.approx(2 / (a * R) ** 2, rel=2e-3)


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [({"mean_speed": 0.0}, "mean_speed"), ({"rotor_radius": -1.0}, "rotor_radius"),
     ({"hub_height": np.nan}, "hub_height"), ({"n_points": 4}, "n_points"), ({"f_hz": [-1.0]}, "f_hz")],
)
def test_rotor_averaging_rejects_bad_input(kwargs, word):
    with pytest.raises(ValueError, match=word):
        rotor_averaging(**{"f_hz": [0.1], "mean_speed": 10.0, **kwargs})


# ---------------------------------------------------------------------------------------------- synthesis
@pytest.fixture(scope="module")
def hour_of_wind():
    n, dt = 36000, 0.1
    assert next_fast_len(n, real=True) == n  # the record is a whole period: sample statistics are exact sums
    return synthesize_wind(V, 0.15, n * dt, dt, seed=9)


def test_synthesised_wind_has_the_requested_mean_and_intensity(hour_of_wind):
    w = hour_of_wind
    assert w.t.shape == w.hub.shape == w.rotor_effective.shape == (36000,)
    assert np.mean(w.hub) == pytest.approx(V, abs=1e-9)
    assert np.mean(w.rotor_effective) == pytest.approx(V, abs=1e-9)
    # within a few %: the variance below 1/3600 Hz and above the 5 Hz Nyquist frequency is absent (~2.7 %)
    assert np.std(w.hub) == pytest.approx(0.15 * V, rel=0.03)
    assert np.std(w.hub) < 0.15 * V
    assert 0.3 * np.std(w.hub) < np.std(w.rotor_effective) < 0.9 * np.std(w.hub)


def test_synthesised_hub_and_rotor_spectra(hour_of_wind):
    w = hour_of_wind
    f, pxx = welch(w.hub, fs=10.0, nperseg=2048)
    _, pyy = welch(w.rotor_effective, fs=10.0, nperseg=2048)
    for lo, hi in ((0.02, 0.05), (0.05, 0.1), (0.1, 0.2), (0.5, 1.0)):
        band = (f >= lo) & (f < hi)
        kaimal = quad(lambda x: float(kaimal_spectrum(x, V, 0.15)), lo, hi)[0] / (hi - lo)
        assert pxx[band].mean() == pytest.approx(kaimal, rel=0.15)
        h2, _ = rotor_averaging(f[band], V)  # checked against brute force above
        assert np.mean(pyy[band] / pxx[band]) == pytest.approx(h2.mean(), rel=0.15)


def test_hub_and_rotor_average_are_correlated_as_the_coherence_says(hour_of_wind):
    """The record is one period, so its DFT holds the components exactly: per frequency, rotor / hub =
    G + sqrt(H2 - G^2) e^{i theta} with theta uniform. Band means of the real part, of the squared modulus and
    of the imaginary part are compared with G, H2 and 0 within 4 standard errors of that random term."""
    w = hour_of_wind
    ratio = np.fft.rfft(w.rotor_effective)[1:-1] / np.fft.rfft(w.hub)[1:-1]  # without 0 and Nyquist
    f = np.fft.rfftfreq(w.hub.size, 0.1)[1:-1]
    for lo, hi in ((0.0005, 0.01), (0.01, 0.03), (0.03, 0.1), (0.1, 1.0)):
        band = (f >= lo) & (f < hi)
        h2, g = rotor_averaging(f[band], V)
        m, n = band.sum(), np.sqrt(h2 - g**2)
        se = np.sqrt(np.mean(n**2) / (2 * m))
        assert abs(np.mean(ratio[band].real) - g.mean()) < 4 * se
        assert abs(np.mean(ratio[band].imag)) < 4 * se
        assert abs(np.mean(np.abs(ratio[band]) ** 2) - h2.mean()) < 4 * np.sqrt(2 * np.mean((g * n) ** 2) / m)
    # at low frequency the hub point and the rotor average are strongly coherent, at high frequency hardly
    low, high = (f > 0) & (f < 0.01), (f > 0.5) & (f < 2.0)
    assert np.mean(ratio[low].real) > 0.5 and abs(np.mean(ratio[high].real)) < 0.05


def test_calm_and_laminar_wind_are_constant():
    laminar = synthesize_wind(11.4, 0.0, 60.0, 0.1, seed=1)
    assert np.all(laminar.hub == 11.4) and np.all(laminar.rotor_effective == 11.4)
    calm = synthesize_wind(0.0, 0.2, 60.0, 0.1, seed=1)
    assert not calm.hub.any() and not calm.rotor_effective.any()
    assert laminar.t[-1] == pytest.approx(59.9)


def test_wind_is_deterministic_per_seed():
    a = synthesize_wind(10.0, 0.15, 120.0, 0.05, seed=3)
    b = synthesize_wind(10.0, 0.15, 120.0, 0.05, seed=3)
    c = synthesize_wind(10.0, 0.15, 120.0, 0.05, seed=4)
    assert a.hub.tobytes() == b.hub.tobytes()
    assert a.rotor_effective.tobytes() == b.rotor_effective.tobytes()
    assert not np.allclose(a.hub, c.hub)
    g1 = synthesize_wind(10.0, 0.15, 120.0, 0.05, seed=np.random.default_rng(5))
    g2 = synthesize_wind(10.0, 0.15, 120.0, 0.05, seed=np.random.default_rng(5))
    assert g1.rotor_effective.tobytes() == g2.rotor_effective.tobytes()
    assert a.meta["seed"] == 3 and g1.meta["seed"] is None and a.meta["turbulence_intensity"] == 0.15


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [({"mean_speed": -1.0}, "mean_speed"), ({"mean_speed": np.inf}, "mean_speed"),
     ({"turbulence_intensity": 1.5}, "turbulence_intensity"),
     ({"turbulence_intensity": np.nan}, "turbulence_intensity"),
     ({"duration": 0.01}, "duration"), ({"dt": 0.0}, "dt"), ({"dt": -0.1}, "dt"),
     ({"hub_height": -90.0}, "hub_height"), ({"rotor_radius": 0.0}, "rotor_radius"),
     ({"seed": -1}, "seed"), ({"seed": 1.5}, "seed")],
)
def test_synthesis_rejects_bad_input(kwargs, word):
    args = {"mean_speed": 12.0, "turbulence_intensity": 0.1, "duration": 60.0, "dt": 0.1, **kwargs}
    with pytest.raises(ValueError, match=word):
        synthesize_wind(**args)
