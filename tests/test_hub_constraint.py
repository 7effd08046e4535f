"""A rotor field conditioned on a measured hub wind (:func:`surrogates.wind.constrain_to_hub`,
``simulate(hub_wind=...)``, ``validate(constrain_wind=...)``), checked against the IEC model's closed forms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import csd, welch

import surrogates
from fowt_env import validation as V
from surrogates.wind import constrain_to_hub, kaimal_spectrum, synthesize_rotor_wind, turbulence_length_scale

V12, TI = 12.0, 0.15
LC = turbulence_length_scale(90.0)


def _iec(f, r, v=V12):
    return np.exp(-12.0 * np.sqrt((f * r / v) ** 2 + (0.12 * r / LC) ** 2))


def test_hub_follows_the_series_gradients_untouched_and_outside_the_ramp_unchanged():
    w = synthesize_rotor_wind(V12, TI, duration=400.0, dt=0.05, seed=4)
    t = np.arange(100.0, 300.0, 0.05)
    h = 11.0 + 2.0 * np.sin(2 * np.pi * 0.01 * t)  # its mean (11) is replaced by the field's hub mean (12)
    c = constrain_to_hub(w, t, h, ramp=20.0)
    inside = (w.t >= 100.0) & (w.t < 300.0 - 1e-9)
    assert np.allclose(c.hub[inside], h[: inside.sum()] - 11.0 + V12, atol=1e-9)
    assert np.allclose(c.polar_u[inside, 0, :], c.hub[inside, None], atol=1e-4)  # the hub ring is the hub
    assert np.array_equal(c.shear_y, w.shear_y) and np.array_equal(c.shear_z, w.shear_z)  # a radial constraint
    outside = (w.t < 80.0 - 1e-9) | (w.t > 320.0 + 1e-9)
    assert np.array_equal(c.hub[outside], w.hub[outside])
    # off the hub the correction is the residual filtered by the coherence, whose kernel has tails of tens of
    # seconds at 63 m (the IEC coherence's low-frequency floor, 0.12 r / L_c): small but not nil away from the span
    change = np.abs(c.polar_u - w.polar_u).max(axis=(1, 2))
    assert change[(w.t < 40.0) | (w.t > 360.0)].max() < 0.1 * change[inside].max()
    assert c.meta["constrained_to_hub"]["series_mean"] == pytest.approx(11.0)


def test_constrained_field_keeps_the_iec_statistics():
    # the hub series is itself a draw of the model (another seed): the constrained field is then a draw of the
    # unconstrained model, so a ring point keeps the Kaimal spectrum and its coherency with the hub is the IEC
    # coherence (closed form). Welch over 4 two-hour records, as test_point_coherence_is_the_iec_coherence.
    dt = 0.5
    pooled = 0.0
    for seed in range(4):
        h = synthesize_rotor_wind(V12, TI, 7200.0, dt, seed=100 + seed, return_field=False).hub
        w = synthesize_rotor_wind(V12, TI, 7200.0, dt, seed=seed)
        c = constrain_to_hub(w, w.t, h)
        hub, ring = c.hub, c.polar_u[:, 2, 5].astype(float)  # r = 31.5 m
        f, sxy = csd(hub, ring, fs=1 / dt, nperseg=1024)
        pooled = pooled + np.stack([sxy.real, welch(hub, fs=1 / dt, nperseg=1024)[1],
                                    welch(ring, fs=1 / dt, nperseg=1024)[1]])
    co, shh, srr = pooled / 4
    for f0 in (0.005, 0.02, 0.05):
        band = np.abs(f - f0) < 0.005
        assert np.mean(co[band] / np.sqrt(shh[band] * srr[band])) == pytest.approx(
            np.mean(_iec(f[band], 31.5)), abs=0.1), f0
    band = (f > 0.003) & (f < 0.3)
    ratio = np.sum(srr[band]) / np.sum(kaimal_spectrum(f[band], V12, TI))
    assert ratio == pytest.approx(1.0, abs=0.1)


def test_conditional_mean_and_variance_are_the_closed_forms():
    # one fixed hub series, 24 draws of the rest. Across draws, at a fixed time, a point at r from the hub has
    # the variance sum_f S(f) (1 - Coh(r, f)^2) df (the randomness the hub does not explain) about the mean
    # (Coh(r) * h)(t) (the hub's regression); both closed forms of the IEC model.
    dt, duration, n_draws = 0.5, 2000.0, 24
    h = synthesize_rotor_wind(V12, TI, duration, dt, seed=99, return_field=False).hub
    draws = []
    for seed in range(n_draws):
        w = synthesize_rotor_wind(V12, TI, duration, dt, seed=seed)
        draws.append(constrain_to_hub(w, w.t, h).polar_u[:, 4, 3].astype(float))  # r = 63 m
    draws = np.array(draws)
    n_fft = w.meta["n_fft"]
    f = np.fft.rfftfreq(n_fft, dt)[1:-1]
    s = kaimal_spectrum(f, V12, TI)
    expected_var = np.sum(s * (1.0 - _iec(f, 63.0) ** 2)) / (n_fft * dt)
    mid = slice(200, -200)  # away from the ends of the periodic draw and the zero-padded filter
    var = draws[:, mid].var(axis=0, ddof=1).mean()
    assert var == pytest.approx(expected_var, rel=0.1)
    n = h.size
    spec = np.fft.rfft(h - h.mean(), 2 * n)
    predicted = np.fft.irfft(spec * _iec(np.fft.rfftfreq(2 * n, dt), 63.0), 2 * n)[:n] + V12
    rms = np.sqrt(np.mean((draws.mean(axis=0)[mid] - predicted[mid]) ** 2))
    assert rms == pytest.approx(np.sqrt(expected_var / n_draws), rel=0.25)  # only the draws' own scatter
    assert expected_var < 0.75 * (TI * V12) ** 2  # the hub explains 30 % at 63 m: the variance test has teeth


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"t": np.arange(3.0), "hub": np.ones(4)}, "same length"),
    ({"t": np.array([0.0, 1.0, 1.0]), "hub": np.ones(3)}, "strictly increasing"),
    ({"t": np.arange(3.0), "hub": np.array([1.0, np.nan, 1.0])}, "finite"),
    ({"t": np.arange(3.0), "hub": np.ones(3), "ramp": -1.0}, "ramp"),
])
def test_bad_series_are_named(kwargs, match):
    w = synthesize_rotor_wind(V12, TI, 10.0, 0.5, seed=0)
    with pytest.raises(ValueError, match=match):
        constrain_to_hub(w, **kwargs)


def test_a_field_without_its_grid_or_wind_is_refused():
    with pytest.raises(ValueError, match="polar field"):
        constrain_to_hub(synthesize_rotor_wind(V12, TI, 10.0, 0.5, return_field=False), np.arange(3.0), np.ones(3))
    with pytest.raises(ValueError, match="mean speed"):
        constrain_to_hub(synthesize_rotor_wind(0.0, 0.0, 10.0, 0.5), np.arange(3.0), np.ones(3))


# --------------------------------------------------------------------------------------------- simulate
def test_simulate_hub_wind_sets_wind1velx_and_leaves_the_rest_to_the_seed():
    lc = surrogates.operating_case(12.0, 2.5, 10.0)
    t = np.arange(0.0, 150.0, 0.1) + 500.0  # its own clock: the first sample is the record's first
    u = 12.0 + 1.5 * np.sin(2 * np.pi * 0.01 * t) + 0.3 * np.sin(2 * np.pi * 0.3 * t)
    recs = surrogates.simulate(surrogates.FOWTModel(), lc, 100.0, 0.05, [0, 1], transient=30.0, noise=False,
                               hub_wind=(t, u))
    for rec in recs:
        expected = np.interp(rec.t, t - t[0], u - u.mean() + lc.wind_speed)
        assert np.abs(np.asarray(rec["Wind1VelX"]) - expected).max() < 1e-9
        assert rec.meta["hub_wind"]["series_mean"] == pytest.approx(u.mean())
    assert not np.allclose(recs[0]["TwrBsMxt"], recs[1]["TwrBsMxt"])  # the rotor plane stays random
    # a slow gust at the hub moves the rotor: the constrained rotor speed follows the hub wind's slow swing
    slow = np.interp(recs[0].t, t - t[0], np.sin(2 * np.pi * 0.01 * t))
    assert np.corrcoef(slow, recs[0]["Wind1VelX"])[0, 1] > 0.9
    with pytest.raises(ValueError, match="wind="):
        surrogates.simulate(surrogates.FOWTModel(), lc, 10.0, hub_wind=(t, u), wind=(t, u))
    with pytest.raises(ValueError, match="turbulence_intensity > 0"):
        surrogates.simulate(surrogates.FOWTModel(), lc.replace(turbulence_intensity=0.0), 10.0, hub_wind=(t, u))
    with pytest.raises(ValueError, match="finite"):
        surrogates.simulate(surrogates.FOWTModel(), lc, 10.0, hub_wind=(t, np.where(t > 550, np.nan, u)))
    with pytest.raises(ValueError, match="Wind1VelX"):
        surrogates.simulate(surrogates.FOWTModel(), lc, 10.0, hub_wind=recs[0].select(["PtfmPitch"]))
    with pytest.raises(ValueError, match="Record with Wind1VelX or a"):
        surrogates.simulate(surrogates.FOWTModel(), lc, 10.0, hub_wind=u)


# --------------------------------------------------------------------------------------------- validate
def test_validate_conditions_turbulent_runs_on_their_hub_wind():
    rep = V.validate(None, seeds=1, duration=60.0, runs=["c_op12"], wind="hub")
    assert rep.settings["constrain_wind"] is True and rep.settings["wind"] == "hub"
    assert any("conditioned on the record's Wind1VelX" in n for n in rep.notes)
    assert rep.runs[0]["load_case"]["turbulence_intensity"] == pytest.approx(0.1703, abs=1e-3)  # nominal
    free = V.validate(None, seeds=1, duration=60.0, runs=["c_op12"], constrain_wind=False)
    assert free.settings["constrain_wind"] is False and not any("conditioned" in n for n in free.notes)


def test_cli_free_wind_switches_the_constraint_off(tmp_path):
    import json

    from fowt_env.cli import main

    out = tmp_path / "v.json"
    assert main(["validate", "--seeds", "1", "--duration", "30", "--runs", "c_op12", "--free-wind",
                 "--json", str(out)]) == 0
    settings = json.loads(out.read_text())["settings"]
    assert settings["constrain_wind"] is False and settings["wind"] == "synthetic"


# ------------------------------------------------------------------------------------ validate, the run's own field
def test_validate_drives_turbulent_runs_with_their_inflow_field_by_default():
    rep = V.validate(None, seeds=1, duration=30.0, runs=["c_op12"])
    assert rep.settings["wind"] == "inflow"
    assert any("the run's own wind field" in n for n in rep.notes)
    assert not any("conditioned on the record's Wind1VelX" in n for n in rep.notes)
    with pytest.raises(ValueError, match="wind must be one of"):
        V.validate(None, seeds=1, duration=30.0, runs=["c_op12"], wind="turbsim")


def test_inflow_driven_surrogate_follows_openfast_rotor_speed():
    """Fed the wind OpenFAST saw (its packaged inflow field), from OpenFAST's own start, the surrogate's rotor speed
    follows OpenFAST's series below rated (8 m/s, where the rotor speed is the wind's integral through the torque
    law), which a random field cannot: the check that the field is placed at the run's time axis."""
    from surrogates.replay import MeasuredWind

    run = V.load_reference(None, ["c_op08"])[0][0]
    case = V.surrogate_case(V._with_measured_inputs(run))
    field = MeasuredWind.from_inflow(Path(run.source).with_name(f"{run.name}.inflow.npz")).window(0.0)
    assert field.t[0] >= 0.0 and field.t[0] < 0.25
    sim = surrogates.simulate(surrogates.FOWTModel(), case, 120.0, 0.1, 0, transient=100.0, noise=False,
                              wind=field, initial=dict(run.case["start"]))
    ref = np.interp(sim.t, run.record.t, run.record["RotSpeed"])
    assert np.corrcoef(ref, sim["RotSpeed"])[0, 1] > 0.9
    assert np.std(sim["RotSpeed"]) == pytest.approx(np.std(ref), rel=0.15)


def test_measured_wind_window():
    from surrogates.replay import MeasuredWind

    t = np.arange(-5.0, 40.0, 0.5)
    w = MeasuredWind.from_hub(t, 10.0 + np.sin(t))
    cut = w.window(0.0, 30.0)
    assert cut.t[0] == 0.0 and cut.t[-1] == 30.0
    np.testing.assert_allclose(cut.hub, 10.0 + np.sin(cut.t))
    assert len(cut.rotor_effective) == len(cut.t)
    with pytest.raises(ValueError, match="fewer than two samples"):
        w.window(50.0)
    with pytest.raises(ValueError, match="shorter than"):  # the series' own checks hold for the window
        w.window(30.0)


def test_cli_wind_hub_is_the_hub_conditioned_field(tmp_path):
    import json

    from fowt_env.cli import main

    out = tmp_path / "v.json"
    assert main(["validate", "--seeds", "1", "--duration", "30", "--runs", "c_op12", "--wind", "hub",
                 "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["settings"]["wind"] == "hub" and report["settings"]["constrain_wind"] is True
    assert any("conditioned on the record's Wind1VelX" in n for n in report["notes"])
