"""JONSWAP waves and first-order spar loads against closed forms and independent numerics.

Truth used here: DNV-RP-C205 (section 3.5.5) for the spectrum, linear (Airy) wave theory for the dispersion
relation and the kinematics, hand-derived integrals of the Morison inertia and Froude-Krylov loads on a
cylinder, and scipy's quad/brentq for what has no closed form.
"""

import numpy as np
import pytest
from scipy.fft import next_fast_len
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.signal import welch

from surrogates.waves import SparGeometry, excitation_rao, jonswap_spectrum, synthesize_waves, wave_number

G = 9.80665
RHO = 1025.0
CA = 0.969954


def k_brentq(omega: float, depth: float) -> float:
    """Independent dispersion solve: k in [k0, k0 / tanh(k0 h)], k0 = omega^2 / g (both bounds are exact)."""
    k0 = omega**2 / G
    lo, hi = k0 * (1 - 1e-9), k0 / np.tanh(k0 * depth) * (1 + 1e-9)
    return brentq(lambda k: omega**2 - G * k * np.tanh(k * depth), lo, hi, xtol=1e-300, rtol=1e-15)


def oc3_area(z: float) -> float:
    """OC3 Hywind cross-section (Jonkman 2010): 6.5 m to -4 m, linear taper to 9.4 m at -12 m, 9.4 m below."""
    if z >= -4.0:
        d = 6.5
    elif z >= -12.0:
        d = 6.5 + (9.4 - 6.5) * (-4.0 - z) / 8.0
    else:
        d = 9.4
    return np.pi * d**2 / 4.0


# ------------------------------------------------------------------------------------------------ spectrum
@pytest.mark.parametrize("gamma", [1.0, 3.3, 5.0])
def test_jonswap_zeroth_moment_is_hs_squared_over_16(gamma):
    # DNV-RP-C205 3.5.5.2: A_gamma = 1 - 0.287 ln(gamma) normalises m0 to Hs^2/16 only approximately (~1 %)
    hs, tp = 3.0, 10.0
    m0, _ = quad(lambda f: float(jonswap_spectrum(f, hs, tp, gamma)), 0.0, 3.0, points=[1 / tp], limit=400)
    assert m0 == pytest.approx(hs**2 / 16.0, rel=0.01)


@pytest.mark.parametrize("tp", [4.0, 10.0, 16.0])
def test_jonswap_peaks_at_one_over_tp(tp):
    f = np.linspace(0.2 / tp, 3.0 / tp, 200001)
    assert f[np.argmax(jonswap_spectrum(f, 2.0, tp, 3.3))] == pytest.approx(1.0 / tp, abs=2e-5 / tp)


def test_gamma_one_is_pierson_moskowitz_and_gamma_raises_the_peak():
    # DNV-RP-C205 eq. (3.5.5.1) in angular frequency, S(omega) = 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (w/wp)^-4),
    # and S(f) = 2 pi S(omega) for a one-sided density per Hz
    hs, tp = 2.5, 8.0
    f = np.linspace(0.02, 1.0, 500)
    w, wp = 2 * np.pi * f, 2 * np.pi / tp
    pm = 2 * np.pi * 5 / 16 * hs**2 * wp**4 * w**-5 * np.exp(-1.25 * (w / wp) ** -4)
    np.testing.assert_allclose(jonswap_spectrum(f, hs, tp, 1.0), pm, rtol=1e-12)
    # at f = fp the peak factor is exactly gamma: S = (1 - 0.287 ln gamma) gamma S_PM(fp)
    s_pm_peak = 2 * np.pi * 5 / 16 * hs**2 * wp**-1 * np.exp(-1.25)
    assert float(jonswap_spectrum(1 / tp, hs, tp, 3.3)) == pytest.approx(
        (1 - 0.287 * np.log(3.3)) * 3.3 * s_pm_peak, rel=1e-12)


def test_jonswap_edge_values():
    assert np.all(jonswap_spectrum([0.0, 0.1, 1.0], 0.0, 10.0) == 0.0)
    assert float(jonswap_spectrum(0.0, 2.0, 10.0)) == 0.0
    assert float(jonswap_spectrum(1e-300, 2.0, 10.0)) == 0.0  # no inf * 0
    assert jonswap_spectrum(np.ones((2, 3)) * 0.1, 2.0, 10.0).shape == (2, 3)


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [({"hs": -1.0}, "hs"), ({"tp": 0.0}, "tp"), ({"tp": np.inf}, "tp"), ({"gamma": 0.5}, "gamma"),
     ({"gamma": np.nan}, "gamma"), ({"gamma": 11.0}, "gamma"), ({"f_hz": [0.1, -0.1]}, "f_hz"),
     ({"f_hz": [np.nan]}, "f_hz")],
)
def test_jonswap_rejects_bad_input(kwargs, word):
    args = {"f_hz": [0.1], "hs": 1.0, "tp": 8.0, "gamma": 3.3, **kwargs}
    with pytest.raises(ValueError, match=word):
        jonswap_spectrum(**args)


# ---------------------------------------------------------------------------------------------- dispersion
def test_dispersion_deep_and_shallow_limits():
    w = np.array([0.5, 1.0, 2.0, 4.0])
    np.testing.assert_array_equal(wave_number(w, 1000.0), w**2 / G)  # kh > 25: tanh(kh) == 1 exactly
    w_small = np.array([1e-4, 1e-3])
    np.testing.assert_allclose(wave_number(w_small, 5.0), w_small / np.sqrt(G * 5.0), rtol=1e-6)
    assert float(wave_number(0.0, 320.0)) == 0.0


def test_dispersion_residual_and_independent_root():
    w = np.geomspace(1e-4, 10.0, 400)
    for depth in (0.5, 20.0, 320.0, 5000.0):
        k = wave_number(w, depth)
        np.testing.assert_allclose(G * k * np.tanh(k * depth), w**2, rtol=1e-12)
    for omega, depth in ((0.2, 320.0), (0.6, 50.0), (1.3, 320.0), (0.05, 10.0)):
        assert float(wave_number(omega, depth)) == pytest.approx(k_brentq(omega, depth), rel=1e-12)
    assert wave_number(np.full((3, 2), 0.7), 320.0).shape == (3, 2)


@pytest.mark.parametrize(("kwargs", "word"), [({"omega": [-1.0]}, "omega"), ({"omega": [np.inf]}, "omega"),
                                              ({"depth": 0.0}, "depth"), ({"depth": np.nan}, "depth")])
def test_dispersion_rejects_bad_input(kwargs, word):
    with pytest.raises(ValueError, match=word):
        wave_number(**{"omega": [1.0], "depth": 320.0, **kwargs})


# ------------------------------------------------------------------------------------------------ geometry
def test_oc3_geometry_and_strips():
    geo = SparGeometry()
    z = np.array([11.0, 10.0, 5.0, 0.0, -4.0, -8.0, -12.0, -60.0, -120.0, -121.0])
    np.testing.assert_allclose(geo.diameter(z), [0, 6.5, 6.5, 6.5, 6.5, 7.95, 9.4, 9.4, 9.4, 0])
    zc, dz, d = geo.strips(24)
    assert zc.shape == dz.shape == d.shape == (24,)
    assert dz.sum() == pytest.approx(120.0, rel=1e-12) and np.all(dz > 0)
    assert np.all(np.diff(zc) < 0) and -120 < zc.min() and zc.max() < 0
    assert np.all(np.diff(dz) > 0)  # finer near the surface
    # edges rebuilt from centres and lengths tile [-120, 0]
    np.testing.assert_allclose(zc + dz / 2, np.concatenate([[0.0], (zc - dz / 2)[:-1]]), atol=1e-12)
    np.testing.assert_allclose(d, [np.sqrt(4 * oc3_area(zi) / np.pi) for zi in zc], rtol=1e-12)
    # the strips' submerged volume tends to the OC3 displacement, 8029 m^3 (Jonkman 2010)
    _, dz_f, d_f = geo.strips(2000)
    assert np.sum(np.pi * d_f**2 / 4 * dz_f) == pytest.approx(8029.2, rel=1e-3)


@pytest.mark.parametrize("kwargs", [{"draft": 1.0}, {"taper_top": -20.0}, {"upper_diameter": 0.0},
                                    {"cd": -0.1}, {"ca": np.nan}, {"top": -1.0}])
def test_geometry_rejects_bad_values(kwargs):
    with pytest.raises(ValueError, match="|".join(kwargs) + "|heights"):
        SparGeometry(**kwargs)
    with pytest.raises(ValueError, match="strips"):
        SparGeometry().strips(0)


# --------------------------------------------------------------------------------------- transfer functions
def test_surge_and_pitch_excitation_of_a_uniform_cylinder_in_deep_water():
    """Deep water, draft T: a(z) = i w^2 e^{kz} per unit amplitude, so
    Fx = i rho (1+Ca) A w^2 (1 - e^{-kT}) / k and
    My = int z dFx = i rho (1+Ca) A w^2 (e^{-kT}(1 + kT) - 1) / k^2.
    """
    geo = SparGeometry(upper_diameter=9.4, lower_diameter=9.4)
    f = np.array([0.05, 0.1, 0.2, 0.4])
    depth = 10000.0  # kh > 100 for f >= 0.05 Hz
    rao = excitation_rao(f, 0.0, depth=depth, geometry=geo, diffraction=False)
    w = 2 * np.pi * f
    k, area, t = w**2 / G, np.pi * 9.4**2 / 4, 120.0
    fx = 1j * RHO * (1 + CA) * area * w**2 * (1 - np.exp(-k * t)) / k
    my = 1j * RHO * (1 + CA) * area * w**2 * (np.exp(-k * t) * (1 + k * t) - 1) / k**2
    np.testing.assert_allclose(rao[:, 0], fx, rtol=1e-9)
    np.testing.assert_allclose(rao[:, 4], my, rtol=1e-9)
    np.testing.assert_allclose(rao[:, [1, 3, 5]], 0.0, atol=0)
    # the midpoint rule on the drag strips converges to the same force
    strips = excitation_rao(f, 0.0, depth, geo, n_strips=3000, diffraction=False)
    np.testing.assert_allclose(strips[:, 0], fx, rtol=1e-4)


def test_maccamy_fuchs_diffraction_of_a_uniform_cylinder_in_deep_water():
    """MacCamy & Fuchs (1954), derived here from the partial-wave expansion of the incident wave: on a vertical
    cylinder of radius a in deep water the force per unit length is ``4 rho g e^{kz} / (k conj(H1'(ka)))``
    per unit amplitude for eta = Re(A e^{i w t}) (H1 = J1 + i Y1, the Hankel function), so over a draft T
    ``Fx = 4 rho g (1 - e^{-kT}) / (k^2 conj(H1'(ka)))``; for ka -> 0 it is Morison with Cm = 2."""
    from scipy.special import h1vp

    geo = SparGeometry(upper_diameter=9.4, lower_diameter=9.4, ca=1.0)
    f = np.array([0.02, 0.1, 0.2, 0.4, 0.6])
    depth = 20000.0
    w = 2 * np.pi * f
    k, t, a = w**2 / G, 120.0, 4.7
    closed = 4 * RHO * G * (1 - np.exp(-k * t)) / (k**2 * np.conj(h1vp(1, k * a)))
    np.testing.assert_allclose(excitation_rao(f, 0.0, depth=depth, geometry=geo)[:, 0], closed, rtol=1e-7)
    morison = excitation_rao(f, 0.0, depth=depth, geometry=geo, diffraction=False)[:, 0]
    assert abs(closed[0] / morison[0] - 1) < 1e-3  # long waves: Morison
    assert abs(closed[-1]) < 0.3 * abs(morison[-1])  # ka = 0.87 * 4.7 = 4.1: diffraction cuts the load


def test_surge_excitation_of_a_uniform_cylinder_in_finite_depth():
    """int_{-T}^0 cosh(k(z+h)) dz / sinh(kh) = (sinh(kh) - sinh(k(h-T))) / (k sinh(kh))."""
    geo = SparGeometry(upper_diameter=9.4, lower_diameter=9.4)
    depth, t, area = 320.0, 120.0, np.pi * 9.4**2 / 4
    for f in (0.01, 0.02, 0.05):
        w = 2 * np.pi * f
        k = k_brentq(w, depth)
        closed = RHO * (1 + CA) * area * w**2 * (np.sinh(k * depth) - np.sinh(k * (depth - t))) / (
            k * np.sinh(k * depth))
        assert excitation_rao([f], 0.0, depth, geo, diffraction=False)[0, 0] == pytest.approx(1j * closed, rel=1e-9)


def test_oc3_surge_pitch_and_heave_excitation_against_quadrature():
    geo, depth = SparGeometry(), 320.0
    f = np.array([0.03, 0.08, 0.15])
    rao = excitation_rao(f, 0.0, depth, geo, diffraction=False)
    for fi, row in zip(f, rao, strict=True):
        w = 2 * np.pi * fi
        k = k_brentq(w, depth)
        decay = lambda z, k=k: np.cosh(k * (z + depth)) / np.sinh(k * depth)  # noqa: E731
        opts = {"points": [-12.0, -4.0], "limit": 400, "epsabs": 0.0, "epsrel": 1e-12}
        fx = RHO * (1 + CA) * w**2 * quad(lambda z, d=decay: oc3_area(z) * d(z), -120, 0, **opts)[0]
        my = RHO * (1 + CA) * w**2 * quad(lambda z, d=decay: z * oc3_area(z) * d(z), -120, 0, **opts)[0]
        # heave: dynamic pressure rho g cosh(k(z+h))/cosh(kh) pushes the keel up and the taper annulus down
        p = lambda z, k=k: RHO * G * np.cosh(k * (z + depth)) / np.cosh(k * depth)  # noqa: E731
        annulus = quad(lambda z, p=p: p(z) * -(oc3_area(z + 1e-6) - oc3_area(z - 1e-6)) / 2e-6, -12, -4,
                       epsabs=0.0, epsrel=1e-10)[0]
        fz = p(-120.0) * np.pi * 9.4**2 / 4 - annulus
        assert row[0] == pytest.approx(1j * fx, rel=1e-8)
        assert row[4] == pytest.approx(1j * my, rel=1e-8)
        assert row[2] == pytest.approx(fz, rel=1e-7)
        assert abs(row[2].imag) == 0.0  # pressure is in phase with the elevation


def test_heave_excitation_tends_to_the_waterplane_restoring_at_low_frequency():
    # as f -> 0 the dynamic pressure is rho g eta at every depth: Fz -> rho g A_waterplane (C33 of the spar)
    fz = excitation_rao([1e-5], 0.0, 320.0)[0, 2]
    assert fz.real == pytest.approx(RHO * G * np.pi * 6.5**2 / 4, rel=1e-6)
    # and the inertia force vanishes (as omega sqrt(g/h) / h in shallow water)
    fx = excitation_rao([1e-5, 0.1], 0.0, 320.0)[:, 0]
    assert abs(fx[0]) < 1e-3 * abs(fx[1])


def test_direction_projects_the_excitation():
    f = np.array([0.07, 0.12])
    along = excitation_rao(f, 0.0)
    for deg in (30.0, 90.0, 225.0):
        c, s = np.cos(np.deg2rad(deg)), np.sin(np.deg2rad(deg))
        rot = excitation_rao(f, deg)
        np.testing.assert_allclose(rot[:, 0], c * along[:, 0], rtol=1e-12, atol=1e-9 * abs(along[0, 0]))
        np.testing.assert_allclose(rot[:, 1], s * along[:, 0], rtol=1e-12, atol=1e-9 * abs(along[0, 0]))
        np.testing.assert_allclose(rot[:, 3], -s * along[:, 4], rtol=1e-12, atol=1e-9 * abs(along[0, 4]))
        np.testing.assert_allclose(rot[:, 4], c * along[:, 4], rtol=1e-12, atol=1e-9 * abs(along[0, 4]))
        np.testing.assert_allclose(rot[:, 2], along[:, 2], rtol=1e-12)


# --------------------------------------------------------------------------------------------- synthesis
def test_synthesised_sea_has_the_requested_height_and_spectrum():
    hs, tp, gamma = 3.0, 10.0, 3.3
    w = synthesize_waves(hs, tp, gamma, 0.0, 3 * 3600.0, 0.25, seed=4)
    assert w.elevation.shape == w.t.shape == (43200,)
    assert w.t[1] - w.t[0] == 0.25
    assert 4 * np.std(w.elevation) == pytest.approx(hs, rel=0.03)
    assert abs(np.mean(w.elevation)) < 0.01 * hs
    f, p = welch(w.elevation, fs=4.0, nperseg=4096)
    for lo, hi in ((0.085, 0.095), (0.095, 0.105), (0.105, 0.115), (0.13, 0.16)):
        band = (f >= lo) & (f < hi)
        target = quad(lambda x: float(jonswap_spectrum(x, hs, tp, gamma)), lo, hi)[0] / (hi - lo)
        assert p[band].mean() == pytest.approx(target, rel=0.15)


def test_synthesis_uses_the_linear_transfer_functions():
    """With a fast FFT length the record is periodic: its DFT recovers each component exactly, so the ratio
    of load (or velocity) to elevation is the linear-theory transfer function at each synthesised frequency.
    """
    n, dt, depth, direction = 4096, 0.1, 320.0, 20.0
    assert next_fast_len(n, real=True) == n
    w = synthesize_waves(2.0, 8.0, 3.3, direction, n * dt, dt, seed=11, depth=depth)
    eta = np.fft.rfft(w.elevation)
    f = np.fft.rfftfreq(n, dt)
    active = np.abs(eta) > 1e-6 * np.abs(eta).max()
    assert 0.05 < f[active].min() < 0.1 < f[active].max()
    rao = excitation_rao(f[active], direction, depth)
    for j in range(5):
        ratio = np.fft.rfft(w.excitation[:, j])[active] / eta[active]
        np.testing.assert_allclose(ratio, rao[:, j], rtol=1e-7, atol=1e-9 * np.abs(rao[:, 0]).max())
    assert np.all(w.excitation[:, 5] == 0.0)
    # velocity at the strips: u = omega cosh(k(z+h))/sinh(kh) eta along the propagation direction
    for idx in (0, 5, 12):
        z = w.strip_z[idx]
        fa = f[active]
        k = np.array([k_brentq(2 * np.pi * fi, depth) for fi in fa])
        with np.errstate(over="ignore", invalid="ignore"):  # deep water (kh > 50): the ratio is e^{kz}
            decay = np.where(k * depth > 50, np.exp(k * z), np.cosh(k * (z + depth)) / np.sinh(k * depth))
        h = 2 * np.pi * fa * decay
        for comp, proj in ((0, np.cos(np.deg2rad(direction))), (1, np.sin(np.deg2rad(direction)))):
            ratio = np.fft.rfft(w.velocity[:, idx, comp])[active] / eta[active]
            np.testing.assert_allclose(ratio, proj * h, rtol=1e-7, atol=1e-10)


def test_strip_outputs_match_the_geometry_and_decay_with_depth():
    w = synthesize_waves(4.0, 11.0, 3.3, 0.0, 1200.0, 0.2, seed=2, n_strips=16)
    zc, dz, d = SparGeometry().strips(16)
    np.testing.assert_array_equal(w.strip_z, zc)
    np.testing.assert_array_equal(w.strip_dz, dz)
    np.testing.assert_array_equal(w.strip_diameter, d)
    assert w.velocity.shape == (6000, 16, 2)
    sd = w.velocity[:, :, 0].std(axis=0)
    assert np.all(np.diff(sd) < 0)
    # near the surface, std(u) ~ std of omega * eta: between 2 pi / Tp * Hs / 4 * 0.6 and * 1.6
    assert 0.6 < sd[0] / (2 * np.pi / 11.0 * 1.0) < 1.6
    assert np.abs(w.velocity[:, :, 1]).max() == 0.0


def test_wave_direction_projects_the_synthesised_loads():
    along = synthesize_waves(2.0, 9.0, 3.3, 0.0, 600.0, 0.1, seed=1)
    across = synthesize_waves(2.0, 9.0, 3.3, 90.0, 600.0, 0.1, seed=1)
    sx, sm = np.std(along.excitation[:, 0]), np.std(along.excitation[:, 4])
    assert np.std(across.excitation[:, 0]) < 1e-12 * sx and np.std(across.excitation[:, 4]) < 1e-12 * sm
    np.testing.assert_allclose(across.excitation[:, 1], along.excitation[:, 0], rtol=0, atol=1e-9 * sx)
    np.testing.assert_allclose(across.excitation[:, 3], -along.excitation[:, 4], rtol=0, atol=1e-9 * sm)
    np.testing.assert_allclose(across.velocity[:, :, 1], along.velocity[:, :, 0], atol=1e-12)
    # heave comes from the pressure on the up-facing taper (the keel is deep): present, well below surge
    sz = np.std(along.excitation[:, 2])
    assert 0.05 * sx < sz < 0.5 * sx
    np.testing.assert_array_equal(across.excitation[:, 2], along.excitation[:, 2])
    np.testing.assert_array_equal(along.elevation, across.elevation)


def test_phases_do_not_depend_on_the_height_and_still_water_is_still():
    a = synthesize_waves(1.0, 7.0, 2.0, 10.0, 300.0, 0.1, seed=6)
    b = synthesize_waves(2.5, 7.0, 2.0, 10.0, 300.0, 0.1, seed=6)
    np.testing.assert_allclose(b.elevation, 2.5 * a.elevation, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(b.excitation, 2.5 * a.excitation, rtol=1e-12, atol=1e-6)
    calm = synthesize_waves(0.0, 7.0, 2.0, 10.0, 300.0, 0.1, seed=6)
    assert not calm.elevation.any() and not calm.excitation.any() and not calm.velocity.any()
    assert not calm.spectrum.any()


def test_cut_and_nyquist():
    w = synthesize_waves(2.0, 8.0, 3.3, 0.0, 600.0, 0.05, seed=1, f_max_hz=0.3)
    assert w.frequencies_hz[w.spectrum > 0].max() <= 0.3
    assert w.meta["f_max_hz"] <= 0.3
    coarse = synthesize_waves(2.0, 3.0, 3.3, 0.0, 600.0, 1.0, seed=1)  # fp = 0.33 Hz, Nyquist 0.5 Hz
    assert coarse.frequencies_hz[coarse.spectrum > 0].max() < 0.5
    assert np.all(np.isfinite(coarse.excitation))


def test_waves_are_deterministic_per_seed():
    a = synthesize_waves(1.0, 6.0, 3.3, 30.0, 60.0, 0.1, seed=3)
    b = synthesize_waves(1.0, 6.0, 3.3, 30.0, 60.0, 0.1, seed=3)
    c = synthesize_waves(1.0, 6.0, 3.3, 30.0, 60.0, 0.1, seed=4)
    for name in ("elevation", "excitation", "velocity"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
    assert not np.allclose(a.elevation, c.elevation)
    g1 = synthesize_waves(1.0, 6.0, 3.3, 0.0, 60.0, 0.1, seed=np.random.default_rng(8))
    g2 = synthesize_waves(1.0, 6.0, 3.3, 0.0, 60.0, 0.1, seed=np.random.default_rng(8))
    assert g1.elevation.tobytes() == g2.elevation.tobytes()
    ss = synthesize_waves(1.0, 6.0, 3.3, 0.0, 60.0, 0.1, seed=np.random.SeedSequence(8))
    assert ss.elevation.shape == (600,)
    assert a.meta["seed"] == 3 and g1.meta["seed"] is None and a.meta["hs"] == 1.0


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [({"hs": -1.0}, "hs"), ({"hs": np.nan}, "hs"), ({"tp": 0.0}, "tp"), ({"gamma": 0.5}, "gamma"),
     ({"direction_deg": np.inf}, "direction_deg"), ({"duration": 0.05}, "duration"),
     ({"duration": -1.0}, "duration"), ({"dt": 0.0}, "dt"), ({"dt": np.nan}, "dt"),
     ({"depth": -5.0}, "depth"), ({"n_strips": 0}, "n_strips"), ({"n_strips": 2.5}, "n_strips"),
     ({"f_max_hz": -0.1}, "f_max_hz"), ({"seed": -3}, "seed"), ({"seed": "x"}, "seed"),
     ({"geometry": "oc3"}, "geometry")],
)
def test_synthesis_rejects_bad_input(kwargs, word):
    args = {"hs": 1.0, "tp": 6.0, "gamma": 3.3, "direction_deg": 0.0, "duration": 60.0, "dt": 0.1, **kwargs}
    with pytest.raises(ValueError, match=word):
        synthesize_waves(**args)
