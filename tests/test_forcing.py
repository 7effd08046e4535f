"""Wave and wind forcing against closed forms (DNV-RP-C205, IEC 61400-1, linear wave theory)."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import csd, welch

from surrogates.oc3 import GRAVITY, RHO_WATER
from surrogates.waves import SparGeometry, excitation_rao, jonswap_spectrum, synthesize_waves, wave_number
from surrogates.wind import (
    iec_turbulence_intensity,
    kaimal_spectrum,
    rotor_averaging,
    synthesize_wind,
)


# ------------------------------------------------------------------------------------------------ waves
@pytest.mark.parametrize("gamma", [1.0, 3.3, 5.0])
def test_jonswap_zeroth_moment_is_hs_squared_over_16(gamma):
    # DNV-RP-C205 3.5.5.2: the normalising factor 1 - 0.287 ln(gamma) makes m0 = Hs^2/16 to about 1-2 %
    m0, _ = quad(lambda f: jonswap_spectrum(np.array([f]), 3.0, 10.0, gamma)[0], 0.0, 2.0, limit=400)
    assert m0 == pytest.approx(3.0**2 / 16.0, rel=0.02)


def test_jonswap_peak_and_pierson_moskowitz_limit():
    f = np.linspace(0.01, 0.5, 20001)
    s = jonswap_spectrum(f, 2.0, 8.0, 3.3)
    assert f[np.argmax(s)] == pytest.approx(1 / 8.0, abs=1e-4)
    hs, tp = 2.0, 8.0
    pm = 5 / 16 * hs**2 * tp**-4 * f**-5 * np.exp(-1.25 * (f * tp) ** -4)
    np.testing.assert_allclose(jonswap_spectrum(f, hs, tp, 1.0), pm, rtol=1e-12)


def test_dispersion_limits_and_residual():
    w = np.linspace(0.05, 3.0, 50)
    k = wave_number(w, 320.0)
    np.testing.assert_allclose(w**2, GRAVITY * k * np.tanh(k * 320.0), rtol=1e-12)
    deep = wave_number(np.array([2.0]), 5000.0)
    assert deep[0] == pytest.approx(4.0 / GRAVITY, rel=1e-10)
    shallow = wave_number(np.array([0.01]), 5.0)
    assert shallow[0] == pytest.approx(0.01 / np.sqrt(GRAVITY * 5.0), rel=1e-4)


def test_surge_excitation_of_uniform_deep_cylinder_matches_closed_form():
    """Uniform cylinder of draft T in deep water: F = rho (1+Ca) A w^2 int_{-T}^0 e^{kz} dz = ... (1-e^{-kT})/k
    (Morison; diffraction off -- MacCamy-Fuchs is checked against its closed form in test_waves.py)."""
    geo = SparGeometry(upper_diameter=9.4, lower_diameter=9.4, taper_top=-4.0, taper_bottom=-12.0)
    f = np.array([0.05, 0.1, 0.2])
    rao = excitation_rao(f, 0.0, depth=5000.0, geometry=geo, n_strips=4000, diffraction=False)
    w = 2 * np.pi * f
    k = w**2 / GRAVITY
    area = np.pi * 9.4**2 / 4
    closed = RHO_WATER * (1 + geo.ca) * area * w**2 * (1 - np.exp(-k * 120.0)) / k
    np.testing.assert_allclose(np.abs(rao[:, 0]), closed, rtol=2e-3)
    # moment about SWL: int z e^{kz} dz = (e^{-kT}(1 + kT) - 1)/k^2 (negative: the force acts below SWL)
    m_closed = RHO_WATER * (1 + geo.ca) * area * w**2 * (np.exp(-k * 120) * (1 + k * 120) - 1) / k**2
    np.testing.assert_allclose(np.abs(rao[:, 4]), np.abs(m_closed), rtol=2e-3)


def test_synthesised_waves_have_the_requested_statistics():
    w = synthesize_waves(3.0, 10.0, 3.3, 0.0, 3 * 3600.0, 0.25, seed=4)
    assert 4 * np.std(w.elevation) == pytest.approx(3.0, rel=0.05)
    f, p = welch(w.elevation, fs=4.0, nperseg=4096)
    near = (f > 0.08) & (f < 0.12)
    np.testing.assert_allclose(p[near], jonswap_spectrum(f[near], 3.0, 10.0, 3.3), rtol=0.35)


def test_wave_direction_projects_loads():
    along = synthesize_waves(2.0, 9.0, 3.3, 0.0, 600.0, 0.1, seed=1)
    across = synthesize_waves(2.0, 9.0, 3.3, 90.0, 600.0, 0.1, seed=1)
    assert np.std(across.excitation[:, 0]) < 1e-9 * np.std(along.excitation[:, 0])
    assert np.std(across.excitation[:, 4]) < 1e-9 * np.std(along.excitation[:, 4])
    np.testing.assert_allclose(across.excitation[:, 1], along.excitation[:, 0], rtol=1e-9, atol=1e-6)
    # roll moment of waves along +y is minus the pitch moment of waves along +x (Mx = -int z Fy)
    np.testing.assert_allclose(across.excitation[:, 3], -along.excitation[:, 4], rtol=1e-9, atol=1e-3)
    # heave comes from the pressure on the up-facing taper (the keel is deep): present, smaller than surge
    assert 0 < np.std(along.excitation[:, 2]) < np.std(along.excitation[:, 0])


def test_heave_froude_krylov_matches_pressure_integral():
    """Deep water: Fz = rho g [e^{k z_keel} A_keel - int_taper e^{k z} (-dA/dz) dz] per metre of amplitude."""
    geo = SparGeometry()
    f = np.array([0.07, 0.1, 0.15])
    rao = excitation_rao(f, 0.0, depth=5000.0)
    k = (2 * np.pi * f) ** 2 / GRAVITY
    for kk, fz in zip(k, rao[:, 2], strict=True):
        taper, _ = quad(lambda z, kk=kk: np.exp(kk * z) * (-np.gradient(
            np.pi * geo.diameter(np.array([z - 1e-4, z + 1e-4])) ** 2 / 4, 2e-4)[0]), -12.0, -4.0)
        keel = np.exp(kk * -120.0) * np.pi * 9.4**2 / 4
        assert abs(fz) == pytest.approx(RHO_WATER * GRAVITY * abs(keel - taper), rel=1e-3)


def test_waves_are_deterministic_per_seed_and_validate_input():
    a = synthesize_waves(1.0, 6.0, 3.3, 0.0, 60.0, 0.1, seed=3)
    b = synthesize_waves(1.0, 6.0, 3.3, 0.0, 60.0, 0.1, seed=3)
    c = synthesize_waves(1.0, 6.0, 3.3, 0.0, 60.0, 0.1, seed=4)
    assert a.elevation.tobytes() == b.elevation.tobytes()
    assert not np.allclose(a.elevation, c.elevation)
    for kwargs, word in (({"hs": -1.0}, "hs"), ({"tp": 0.0}, "tp"), ({"dt": float("nan")}, "dt"),
                         ({"gamma": 0.5}, "gamma")):
        args = {"hs": 1.0, "tp": 6.0, "gamma": 3.3, "direction_deg": 0.0, "duration": 60.0, "dt": 0.1, **kwargs}
        with pytest.raises(ValueError, match=word):
            synthesize_waves(**args)


# ------------------------------------------------------------------------------------------------- wind
def test_kaimal_variance_is_sigma_squared():
    v, ti = 12.0, 0.17
    var, _ = quad(lambda f: kaimal_spectrum(np.array([f]), v, ti)[0], 0.0, np.inf, limit=500)
    assert var == pytest.approx((ti * v) ** 2, rel=1e-6)


def test_iec_normal_turbulence_model():
    # IEC 61400-1 ed. 3, eq. (11): sigma_1 = I_ref (0.75 V + 5.6); class B I_ref = 0.14
    assert iec_turbulence_intensity(15.0, "B") == pytest.approx(0.14 * (0.75 * 15 + 5.6) / 15)
    with pytest.raises(ValueError, match="turbulence_class"):
        iec_turbulence_intensity(10.0, "D")


def test_rotor_averaging_is_a_decreasing_reduction_and_converges():
    f = np.array([0.0, 0.01, 0.05, 0.1, 0.3, 1.0])
    h2, g = rotor_averaging(f, 12.0)
    assert np.all((h2 > 0) & (h2 <= 1)) and np.all((g > 0) & (g <= 1))
    assert np.all(np.diff(h2) < 0) and np.all(np.diff(g) < 0)
    assert np.all(h2 >= g**2 - 1e-12)  # the 2x2 spectral matrix [[1, g], [g, h2]] is positive semi-definite
    assert h2[-1] < 0.002  # small eddies average out over the disc
    fine_h2, fine_g = rotor_averaging(f[2:4], 12.0, n_points=2048)
    np.testing.assert_allclose(h2[2:4], fine_h2, rtol=0.03)
    np.testing.assert_allclose(g[2:4], fine_g, rtol=0.03)


def test_synthesised_wind_statistics_and_coherence():
    w = synthesize_wind(12.0, 0.15, 3600.0, 0.1, seed=9)
    assert np.mean(w.hub) == pytest.approx(12.0, abs=1e-9)
    assert np.std(w.hub) == pytest.approx(0.15 * 12.0, rel=0.12)
    assert np.std(w.rotor_effective) < np.std(w.hub)
    f, pxy = csd(w.hub, w.rotor_effective, fs=10.0, nperseg=4096)
    _, pxx = welch(w.hub, fs=10.0, nperseg=4096)
    sel = (f > 0.05) & (f < 0.2)
    _, g = rotor_averaging(f[sel], 12.0)
    np.testing.assert_allclose(np.real(pxy[sel]) / pxx[sel], g, atol=0.15)
    calm = synthesize_wind(12.0, 0.0, 60.0, 0.1, seed=1)
    assert np.all(calm.hub == 12.0) and np.all(calm.rotor_effective == 12.0)
    with pytest.raises(ValueError, match="turbulence_intensity"):
        synthesize_wind(12.0, 1.5, 60.0, 0.1)
