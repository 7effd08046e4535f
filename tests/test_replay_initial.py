"""A replay starts from the record's platform rates as well as its positions (closed forms)."""

from __future__ import annotations

import numpy as np
import pytest

import surrogates
from fowt_env.replay import record_initial


def test_record_initial_estimates_the_platform_rates_from_the_positions():
    t = np.arange(0.0, 30.0, 0.1)
    surge = 20.0 + 0.3 * t - 0.002 * t**2          # m: rate 0.3 m/s at t = 0
    pitch = 4.0 + 0.5 * np.sin(2 * np.pi * t / 30.0)  # deg: rate 0.5 * 2 pi / 30 deg/s at t = 0
    rec = surrogates.Record(t, np.column_stack([surge, pitch]), ["PtfmSurge", "PtfmPitch"], ["m", "deg"], {})
    init = record_initial(rec)
    assert init["PtfmSurge"] == pytest.approx(20.0) and init["PtfmPitch"] == pytest.approx(4.0)
    assert init["PtfmTVxi"] == pytest.approx(0.3, rel=1e-6)
    # a quadratic over the first 2 s of a 30 s sine: the cubic term costs ~ (2 pi 2 / 30)^2 / 6 ~ 3 %
    assert init["PtfmRVyi"] == pytest.approx(0.5 * 2 * np.pi / 30.0, rel=0.03)
    assert "PtfmTVzi" not in init  # no heave channel, no heave rate


def test_record_rate_channels_are_taken_as_they_are():
    t = np.arange(0.0, 10.0, 0.1)
    rec = surrogates.Record(t, np.column_stack([np.full_like(t, 5.0), np.full_like(t, -0.2)]),
                            ["PtfmSurge", "PtfmTVxi"], ["m", "m/s"], {})
    assert record_initial(rec)["PtfmTVxi"] == pytest.approx(-0.2)


def test_simulation_starts_with_the_given_platform_velocity():
    model = surrogates.FOWTModel(effects="none")
    v0 = 0.4  # m/s surge, in still water and no wind: a free surge decay from the equilibrium with that velocity
    rec = surrogates.simulate(model, None, duration=4.0, dt=0.0125, transient=0.0, noise=False, seed=0,
                              initial={"PtfmTVxi": v0})
    surge = np.asarray(rec["PtfmSurge"])
    slope = np.polyfit(rec.t[:40] - rec.t[0], surge[:40], 2)[1]
    assert slope == pytest.approx(v0, rel=0.02)
    with pytest.raises(ValueError, match="unknown channel"):
        surrogates.simulate(model, None, duration=1.0, initial={"PtfmTVxx": 1.0})


def test_controller_starts_from_a_measured_pitch_and_torque():
    """initial_controller_state: the PI integrator is set so that the DLL's next command equals the given pitch at
    the given speed error (continuity, closed form of the PI law); at the minimum pitch it rests on its lower
    limit (below rated); the torque is taken as given."""
    from surrogates.controller import DISCON, PARAMS, discon_step, initial_controller_state

    ref = DISCON["PC_RefSpd"]
    for speed, pitch in ((ref + 3.0, np.deg2rad(8.0)), (ref - 2.0, np.deg2rad(2.0)), (ref, np.deg2rad(14.0))):
        state = initial_controller_state(speed, pitch, torque=40e3)
        assert state[3] == 40e3
        s = state.copy()
        discon_step(PARAMS, s, speed, 1e-4)  # 0.1 ms later, the same speed: the command has not moved
        assert s[2] == pytest.approx(pitch, abs=1e-5)
    below = initial_controller_state(ref - 20.0, 0.0)
    assert below[1] == 0.0 and below[2] == 0.0


def test_replay_initial_pitch_and_torque_reach_the_controller():
    lc = surrogates.operating_case(18.0, 0.0, 10.0, turbulence_intensity=0.0)
    sim = surrogates.Simulator(surrogates.FOWTModel(), lc)
    x, ctrl = sim.initial_state({"RotSpeed": 11.0, "BldPitch1": 10.0, "GenTq": 43.0})
    assert ctrl[2] == pytest.approx(np.deg2rad(10.0)) and ctrl[3] == pytest.approx(43e3)
    assert ctrl[0] == pytest.approx(sim.system.structure.data.gearbox_ratio * 11.0 * np.pi / 30.0)
    with pytest.raises(ValueError, match="parked"):
        surrogates.Simulator(surrogates.FOWTModel(), None).initial_state({"BldPitch1": 3.0})


def test_measured_wind_is_advected_from_its_plane_to_the_rotor():
    """Taylor's frozen turbulence: a wind measured x_ref metres downwind of the platform axis reaches the rotor
    (x_rotor - x_ref) / U later; moving the plane 2 U metres upwind delays it by 2 s more; a wind measured at the
    rotor (x_ref None) is not delayed. The replayed rotor-level input is the measured series shifted by it."""
    from surrogates.model import INPUT_BLOCKS
    from surrogates.replay import MeasuredWind, advection_delay, replay_forcing

    lc = surrogates.operating_case(12.0, 0.0, 10.0, turbulence_intensity=0.0)
    sim = surrogates.Simulator(surrogates.FOWTModel(), lc)
    t = np.arange(0.0, 400.0, 0.05)
    u = 12.0 + np.sin(2 * np.pi * 0.05 * t)
    at_rotor = MeasuredWind.from_rotor_effective(t, u)
    fixed = MeasuredWind.from_rotor_effective(t, u, x_ref=0.0)
    upwind = MeasuredWind.from_rotor_effective(t, u, x_ref=-2.0 * lc.wind_speed)  # advected at the case speed
    d0 = advection_delay(sim, fixed)
    assert advection_delay(sim, at_rotor) == 0.0
    st = sim.system.structure
    surge, pitch = sim.x_eq[0], sim.x_eq[4]
    assert d0 == pytest.approx((surge + st.hub_position[2] * pitch + st.hub_position[0]) / 12.0, abs=0.15)
    assert 1.0 < d0 < 3.0  # ~21 m downwind at 12 m/s: mean surge ~20 m, pitch ~4 deg, overhang 5 m upwind
    assert advection_delay(sim, upwind) == pytest.approx(d0 + 2.0, rel=1e-9)
    n = int(300.0 / sim.dt_int)
    u_ex, _, _, _ = replay_forcing(sim, n, 50.0, None, fixed, np.random.SeedSequence(0))
    tt = 50.0 + np.arange(n + 1) * sim.dt_int
    got = u_ex[:, INPUT_BLOCKS["wind"].start] + lc.wind_speed
    assert np.max(np.abs(got - (12.0 + np.sin(2 * np.pi * 0.05 * (tt - d0))))) < 1e-3


def test_a_fitted_initial_state_lets_a_replay_started_inside_a_record_follow_openfast():
    """OpenFAST's steady-wind run (packaged record, starting 100 s into the run): replayed from its first sample the
    platform's slow modes ring with the cold start of the wave loads; with the initial state fitted over the first
    100 s (then discarded), the next 200 s -- out of sample -- follow OpenFAST's series (truth: the record itself):
    R² at least 0.75-0.8 and the std within 20 %. Measured: R² 0.98, 0.90, 0.97, 0.97 for surge, heave, pitch and
    blade pitch, std 1.12x, 1.15x, 1.01x, 1.06x (1.03x, 1.14x, 0.97x, 0.99x with the platform's restoring turned
    into the fixed axes, ``surrogates.hydro_axes``'s former form; from OpenFAST's own start at t = 0, ``fowt-env
    validate time-domain``, the surge is 1.06x and the heave 0.91x)."""
    from fowt_env.replay import replay_initial_state, replay_record
    from fowt_env.validation import packaged_reference_dir

    path = packaged_reference_dir() / "d_steady12_Hs2p5_Tp10.npz"
    model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS, effects={"rotor_1p": 0.0})
    rec = surrogates.Record.load(path)
    sim = replay_record(path, model=model, transient=100.0, dt=0.05, initial="fit")
    assert sim.t[0] == pytest.approx(rec.t[0] + 100.0)
    for ch, min_r2 in (("PtfmSurge", 0.75), ("PtfmHeave", 0.75), ("PtfmPitch", 0.8), ("BldPitch1", 0.8)):
        ref = np.interp(sim.t, rec.t, rec[ch])
        r2 = 1.0 - np.mean((sim[ch] - ref) ** 2) / np.var(ref)
        assert r2 >= min_r2, (ch, r2)
        assert np.std(sim[ch]) == pytest.approx(np.std(ref), rel=0.2), ch
    start = replay_initial_state(path, model=model, span=100.0)
    assert set(start) >= {"PtfmSurge", "PtfmTVxi", "PtfmHeave", "PtfmTVzi", "RotSpeed"}
    with pytest.raises(ValueError, match="span"):
        replay_initial_state(path, model=model, span=0.0)
    with pytest.raises(ValueError, match="initial must be"):
        replay_record(path, model=model, initial="guess")
