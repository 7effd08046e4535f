"""The discrepancy workflow with replay (``discrepancy.run(..., replay=True)``): the model is driven by the record's
own wave elevation and wind and the residuals are compared. The truth is set here; the workflow only sees the
record, the candidate model and the load case."""

import json
from pathlib import Path

import numpy as np
import pytest

import fowt_env
import surrogates
from fowt_env import discrepancy, discrepancy_replay
from fowt_env.cli import main
from fowt_env.replay import band_r2
from fowt_env.wind_estimate import rotor_effective_wind

FULL = surrogates.FOWTModel()
DUR, DT = 1200.0, 0.1
OPENFAST_RUN = Path(fowt_env.__file__).parent / "data" / "openfast_reference" / "c_op12_Hs2p5_Tp10.npz"


def _measure(model, olc, seed, duration=DUR, **kw):
    return surrogates.simulate(model, olc, duration=duration, dt=DT, seed=seed, **kw)


@pytest.fixture(scope="module")
def short_record():
    return _measure(FULL, 7, seed=11, duration=300.0)


# ------------------------------------------------------------------------------------------------ bad input
@pytest.mark.parametrize("missing", ["Wave1Elev", "Wind1VelX"])
def test_replay_on_a_record_without_its_forcing_is_a_value_error_naming_the_channel(short_record, missing):
    rec = short_record.select([c for c in short_record.channels if c != missing])
    with pytest.raises(ValueError, match=missing):
        discrepancy.run(rec, FULL, 7, replay=True)
    discrepancy.features(rec, surrogates.load_case(7))  # the statistical mode does not need it


def test_replay_on_a_record_with_a_gap_in_its_wind_says_so(short_record):
    y = short_record.y.copy()
    y[100, short_record.channels.index("Wind1VelX")] = np.nan
    with pytest.raises(ValueError, match="Wind1VelX.*NaN"):
        discrepancy.run(short_record.replace(y=y), FULL, 7, replay=True)


def test_cli_replay_without_a_wave_elevation_is_a_one_line_error(short_record, tmp_path, capsys):
    path = short_record.select([c for c in short_record.channels if c != "Wave1Elev"]).save(tmp_path / "m.npz")
    assert main(["discrepancy", str(path), "--case", "7", "--replay"]) == 2
    err = capsys.readouterr().err
    assert "Wave1Elev" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


# --------------------------------------------------------------------------------------------- the replay
def test_a_noise_free_record_in_steady_wind_is_reproduced_by_its_own_model():
    """Truth: the record's own model, with nothing unresolved (steady wind, no sensor noise): replayed from the
    record's waves and wind it reproduces the record in the wave band (R² > 0.97: the platform's start-up from the
    record's first sample is not over after 60 s, R² 0.986 for pitch, 0.999 after 200 s), and the power-ratio
    features nearly vanish."""
    case = surrogates.load_case(7).replace(turbulence_intensity=0.0)
    rec = surrogates.simulate(FULL, case, duration=400.0, dt=DT, seed=3, noise=False)
    rep = discrepancy_replay.replay_model(FULL, rec, case)
    assert rep.t[0] == pytest.approx(rec.t[0] + discrepancy_replay.REPLAY_TRANSIENT)
    i0 = int(np.searchsorted(rec.t, rep.t[0] - 1e-6))
    for ch in ("PtfmPitch", "TwHt1MLyt", "TwHt9ALxt"):
        y = rec[ch][i0:i0 + rep.n_samples]
        assert band_r2(y, rep[ch], rec.fs, (0.05, 0.2)) > 0.97, ch
    f = discrepancy_replay.replay_features(rec, rep, case)
    ratio = dict(zip(f.names, f.values, strict=True))
    for ch in ("PtfmPitch", "TwHt1MLyt", "TwHt9ALxt"):
        assert abs(ratio[f"{ch}:wave_ratio"]) < 0.05, ch  # replayed / measured wave-band power within 5 %


def test_the_rotor_effective_wind_estimate_resolves_the_slow_surge_the_hub_wind_does_not():
    """Truth: the record's own model (20 minutes of OLC 7). Replayed from the hub wind it explains three quarters
    of the platform-band surge (the rotor-effective wind that drives it is not the hub point's); replayed from the
    wind its own rotor thrust, speed and pitch say, nearly all of it (band R² 0.750 and 0.885: the bound is on the
    gap, which a hub bound of 0.75 met by 7e-5 before the disc-rate lag)."""
    case = surrogates.load_case(7)
    rec = _measure(FULL, 7, seed=104)
    est = rotor_effective_wind(rec)
    assert est.level == "rotor_effective"
    assert abs(float(est.rotor_effective.mean()) - float(rec["Wind1VelX"].mean())) < 1.0  # m/s
    r2 = {}
    for name, wind in (("hub", None), ("rotor", est)):
        rep = discrepancy_replay.replay_model(FULL, rec, case, wind=wind)
        i0 = int(np.searchsorted(rec.t, rep.t[0] - 1e-6))
        r2[name] = band_r2(rec["PtfmSurge"][i0:i0 + rep.n_samples], rep["PtfmSurge"], rec.fs, (0.004, 0.05))
    assert r2["rotor"] > 0.85 and r2["rotor"] > r2["hub"] + 0.1, r2


def test_the_wind_estimate_needs_the_rotor_channels(short_record):
    with pytest.raises(ValueError, match="RotThrust"):
        rotor_effective_wind(short_record.select([c for c in short_record.channels if c != "RotThrust"]))
    with pytest.raises(ValueError, match="RotThrust"):
        discrepancy.run(short_record.select([c for c in short_record.channels if c != "RotThrust"]), FULL, 7,
                        replay="rotor")
    assert discrepancy_replay.choose_wind(short_record, surrogates.load_case(7)) == "rotor"
    assert discrepancy_replay.choose_wind(short_record.select([c for c in short_record.channels
                                                               if c != "RotThrust"]), surrogates.load_case(7)) == "hub"


def test_a_replay_report_of_the_models_own_record_names_nothing_and_says_its_mode(short_record):
    rep = discrepancy.run(short_record, FULL, 7, replay=True, candidates=["drag_cd"], n_scatter=4)
    assert rep.mode == "replay" and rep.to_dict()["mode"] == "replay"
    assert rep.replay_wind == "rotor" and rep.to_dict()["replay_wind"] == "rotor"  # it has the rotor channels
    assert rep.summary().startswith("replay mode")
    assert rep.effects == [] and rep.updated_model is FULL
    assert any(n.endswith("_residual") for n in rep.feature_names)
    assert any(n.endswith("_ratio") for n in rep.feature_names)
    assert discrepancy.run.__defaults__ is not None  # the statistical mode stays the default:
    stat = discrepancy.run(short_record, FULL, 7, candidates=["drag_cd"], n_scatter=4)
    assert stat.mode == "statistics"


# ------------------------------------------------------------------------ hidden truths (slow, 20 minutes)
def _assert_names_nothing(rep, candidate):
    assert rep.effect is None and rep.effects == [] and rep.fits == []
    assert rep.updated_model is candidate


@pytest.mark.slow
@pytest.mark.parametrize(("olc", "seed", "wind"), [
    (7, 106, True), (3, 201, True),
    pytest.param(10, 202, True, marks=pytest.mark.matrix), pytest.param(7, 106, "hub", marks=pytest.mark.matrix)])
def test_replay_of_the_candidates_own_record_names_nothing(olc, seed, wind):
    """Truth: the candidate model itself (another seed). Replayed from its hub wind, OLC 7 seed 106 is the record
    whose roll residual was the largest of those tried (z = +6 to +9 in four roll bands against eight of the
    model's own records)."""
    meas = _measure(FULL, olc, seed)
    rep = discrepancy.run(meas, FULL, surrogates.load_case(olc), replay=wind)
    assert rep.mode == "replay" and rep.replay_wind == ("rotor" if wind is True else "hub")
    assert rep.verdict == "none"
    _assert_names_nothing(rep, FULL)
    assert rep.gap_before <= rep.detect_gap


def _names_the_truth_or_nothing(rep, name, truth, candidate):
    """Never a wrong answer: the hidden candidate with an interval that holds the truth, or nothing named."""
    if rep.effects:
        assert [n for n, _ in rep.effects] == [name]
        (fit,) = rep.fits
        assert fit["interval"][0] <= truth <= fit["interval"][1]
    else:
        _assert_names_nothing(rep, candidate)


@pytest.mark.slow
@pytest.mark.matrix  # ~110 s; .ci/run keeps replay mode's parked drag-coefficient test
@pytest.mark.xfail(strict=True, reason="since issue 15's rotor physics the replay without the drag leaves the slow "
                                       "surge residual at z = +3.7 and the gap at 1.76, under its level 2.44: "
                                       "nothing is named (before: gap 3.70 -> 1.01, quadratic_drag 0.90)")
def test_replay_names_a_missing_quadratic_drag_at_rated_wind():
    """Truth: the full model; the candidate lacks ``quadratic_drag`` (OLC 7, 12 m/s, Hs 3 m). The statistical
    mode sees nothing (gap 1.31 against its level 2.73), nor does a replay from the hub wind alone: the
    rotor-effective wind that drives the slow surge is what the replay needs, and the record's rotor says it.
    The detection was marginal (README, "Replay"); on the current physics it is missed (the xfail's reason)."""
    candidate = FULL.without("quadratic_drag")
    meas = _measure(FULL, 7, seed=104)
    rep = discrepancy.run(meas, candidate, surrogates.load_case(7), replay=True,
                          candidates=["quadratic_drag", "drag_cd", "added_mass", "aero_damping"])
    assert rep.replay_wind == "rotor"
    assert rep.verdict == "explained" and rep.effect == "quadratic_drag"
    (fit,) = rep.fits
    assert fit["interval"][0] <= 1.0 <= fit["interval"][1]
    assert rep.gap_after <= rep.accept_gap < rep.gap_before
    assert any(f["channel"] == "PtfmSurge" for f in rep.findings[:2])  # where: the slow surge


@pytest.mark.slow
@pytest.mark.matrix
def test_a_drag_coefficient_of_one_and_a_half_is_never_misnamed_with_replay():
    """Truth: ``drag_cd`` x1.5 (OLC 10, Hs 4 m); the candidate is nominal. Not found (gap 0.84 against a level of
    2.72, as the statistics: 1.18 against 2.56); never a decoy either."""
    meas = _measure(surrogates.parameters.ParametricModel(parameters={"drag_cd": 1.5}), 10, seed=104)
    rep = discrepancy.run(meas, FULL, surrogates.load_case(10), replay=True,
                          candidates=["drag_cd", "quadratic_drag", "added_mass", "structural_damping"])
    _names_the_truth_or_nothing(rep, "drag_cd", 1.5, FULL)


def _parked(hs, tp):
    return surrogates.LoadCase(hs=hs, tp=tp, wave_dir_deg=0.0, wind_speed=0.0, rotor_rpm=0.0,
                               turbulence_intensity=0.0, gamma=3.3, name=f"parked, Hs {hs:g} m, Tp {tp:g} s")


# The drag coefficient, which the statistics never see (README, "Detection limits"), hidden in parked seas where
# nothing but the waves drives the spar: under the record's own waves the Morison drag's share of the wave-band
# load (~5 % at Hs 4 m) is measurable. Every candidate is searched (the matrix); .ci/run runs x1.5 among six
# decoys.
DRAG_DECOYS = ["drag_cd", "quadratic_drag", "added_mass", "structural_damping", "platform_inertia", "platform_mass"]
DRAG_TRUTHS = [
    pytest.param(1.5, 4.0, 10.0, 102, DRAG_DECOYS, id="x1.5-Hs4-decoys"),
    pytest.param(1.5, 4.0, 10.0, 102, None, id="x1.5-Hs4", marks=pytest.mark.matrix),
    pytest.param(0.6, 4.0, 10.0, 103, None, id="x0.6-Hs4", marks=pytest.mark.matrix),
    pytest.param(2.0, 6.0, 12.0, 101, None, id="x2.0-Hs6", marks=pytest.mark.matrix),
]


@pytest.mark.slow
@pytest.mark.parametrize(("truth", "hs", "tp", "seed", "candidates"), DRAG_TRUTHS)
def test_replay_recovers_a_hidden_drag_coefficient_in_parked_seas(truth, hs, tp, seed, candidates):
    """Measured (all candidates): x1.5 -> 1.50 (1.21-1.79), gap 3.97 -> 0.60; x0.6 -> 0.68 (0.26-0.95), 2.24 ->
    0.81; x2.0 at Hs 6 m -> 2.04 (1.78-2.32), 19.2 -> 0.79. The residual powers are quadratic in the strength with
    their minimum at the truth, which the straight-line screening could not place (x1.5 was 'unexplained')."""
    case = _parked(hs, tp)
    meas = _measure(surrogates.parameters.ParametricModel(parameters={"drag_cd": truth}), case, seed=seed)
    rep = discrepancy.run(meas, FULL, case, replay=True, candidates=candidates)
    assert rep.mode == "replay"
    assert rep.verdict == "explained" and rep.effect == "drag_cd", rep.summary()
    (fit,) = rep.fits
    assert fit["interval"][0] <= truth <= fit["interval"][1]
    assert not (fit["interval"][0] <= 1.0 <= fit["interval"][1])
    assert rep.gap_after <= rep.accept_gap < rep.gap_before


@pytest.mark.slow
@pytest.mark.matrix  # ~120 s
def test_replay_names_an_added_mass_ten_percent_high_that_the_statistics_miss():
    """Truth: added mass x1.1 (OLC 7, seed 105). The statistical mode finds no significant discrepancy in this
    record (gap 1.51 against its level 2.55); under the record's own waves the wave-band response of every channel
    is known to a fraction of a percent, and replay mode sees the shifted transfer function."""
    meas = _measure(surrogates.parameters.ParametricModel(parameters={"added_mass": 1.1}), 7, seed=105)
    rep = discrepancy.run(meas, FULL, surrogates.load_case(7), replay=True,
                          candidates=["added_mass", "platform_mass", "platform_inertia", "drag_cd"])
    assert rep.verdict == "explained" and rep.effect == "added_mass"
    (fit,) = rep.fits
    assert fit["interval"][0] <= 1.1 <= fit["interval"][1]
    assert not any(fit["interval_at_bound"])
    assert rep.gap_after <= rep.accept_gap < rep.gap_before


@pytest.mark.slow
@pytest.mark.matrix
def test_cli_replay_on_the_packaged_openfast_run(tmp_path, capsys):
    out = tmp_path / "rep.json"
    code = main(["discrepancy", str(OPENFAST_RUN), "--replay", "--candidates", "added_mass,drag_cd",
                 "--json", str(out)])
    text = capsys.readouterr().out
    assert code == 0
    assert "OpenFAST record: the model has OpenFAST's gauge heights and no sensor noise" in text
    assert "replay mode" in text
    d = json.loads(out.read_text())
    assert d["mode"] == "replay" and d["verdict"] in ("none", "explained", "at_bound", "unexplained")
