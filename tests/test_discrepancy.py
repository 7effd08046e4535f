"""The discrepancy workflow on data in which an effect is hidden (and on data in which nothing is)."""

import numpy as np
import pytest

import surrogates
from fowt_env import discrepancy

FULL = surrogates.FOWTModel()
DUR, DT = 1200.0, 0.1


def _measure(model, olc, seed):
    return surrogates.simulate(model, olc, duration=DUR, dt=DT, seed=seed)


def test_no_hidden_effect_names_none():
    meas = _measure(FULL, 3, seed=21)  # same physics as the candidate, another seed
    rep = discrepancy.run(meas, FULL, surrogates.load_case(3), n_seeds=3)
    assert rep.effect is None and rep.effects == []
    assert rep.gap_after == rep.gap_before
    assert "no significant discrepancy" in rep.summary()


@pytest.mark.slow
@pytest.mark.parametrize(
    "effect, strength, olc, seed",
    [
        ("aero_damping", 1.0, 7, 31),
        ("mooring_nonlinear", 1.0, 4, 32),
        ("mooring_nonlinear", 1.6, 10, 33),
        ("rotor_3p", 0.7, 4, 34),
        ("p_delta", 1.0, 12, 35),
        ("p_delta", 0.6, 7, 36),
        ("gyroscopic", 1.0, 8, 37),
        ("rotor_1p", 2.0, 7, 38),
    ],
)
def test_hidden_effect_is_named_and_the_gap_halves(effect, strength, olc, seed):
    measured = _measure(FULL.with_effects(**{effect: strength}), olc, seed)
    candidate = FULL.without(effect)
    before = candidate.effects
    rep = discrepancy.run(measured, candidate, surrogates.load_case(olc), n_seeds=3)
    assert rep.effect == effect, rep.summary()
    assert rep.gap_after <= 0.5 * rep.gap_before
    assert candidate.effects == before  # the given model is never modified
    assert rep.updated_model.effects[effect] == pytest.approx(rep.strength)


@pytest.mark.slow
def test_two_hidden_effects_are_both_named():
    measured = _measure(FULL, 7, seed=41)
    candidate = FULL.without("rotor_3p", "aero_damping")
    rep = discrepancy.run(measured, candidate, surrogates.load_case(7), n_seeds=3)
    assert {name for name, _ in rep.effects} == {"rotor_3p", "aero_damping"}, rep.summary()
    assert rep.gap_after <= 0.5 * rep.gap_before


def test_findings_localise_a_hidden_3p_effect(tmp_path):
    """Quick check of 'where': a missing blade-passing effect shows up in the 3P bands.

    In steady wind: the 3P amplitudes are OpenFAST's in steady 12 m/s wind (tower shadow and shear, 1.6 % of the
    thrust, ``surrogates.RotorHarmonics``), and under OLC 4's 17 % turbulence the rotationally sampled turbulence
    puts over ten times more power in the 3P band than they do (their band powers change by < 0.1 in log, inside the
    seed scatter), so no feature can see them there -- as in OpenFAST, where turbulence dominates 3P.
    """
    case = surrogates.load_case(4).replace(turbulence_intensity=0.0)
    measured = surrogates.simulate(FULL, case, duration=300.0, dt=DT, seed=3)  # steady wind: 300 s suffice
    rep = discrepancy.run(measured, FULL.without("rotor_3p"), case, n_seeds=3, candidates=["rotor_3p", "p_delta"])
    assert rep.findings and all(f["band_or_statistic"] == "3P" for f in rep.findings[:3])
    assert rep.effect == "rotor_3p"
    path = rep.plot(tmp_path / "d.png")
    assert path.stat().st_size > 10_000
    d = rep.to_dict()
    assert d["effect"] == "rotor_3p" and "features" in d


def test_bad_input():
    rec = surrogates.simulate(FULL, 4, duration=150.0, dt=DT, seed=0)
    with pytest.raises(ValueError, match="PtfmPitch"):
        discrepancy.run(rec.select([c for c in rec.channels if c != "PtfmPitch"]), FULL, 4)
    with pytest.raises(ValueError, match="candidates"):
        discrepancy.run(rec, FULL, 4, candidates=["flux_capacitor"])
    with pytest.raises(ValueError, match="n_seeds"):
        discrepancy.run(rec, FULL, 4, n_seeds=1)
    low = surrogates.Record(rec.t[::20], rec.y[::20], rec.channels, rec.units)
    with pytest.raises(ValueError, match="sample rate"):
        discrepancy.run(low, FULL, 4)
    irregular_t = rec.t.copy()
    irregular_t[10:] += 0.01
    with pytest.raises(ValueError, match="uniformly sampled"):
        discrepancy.run(surrogates.Record(irregular_t, rec.y, rec.channels, rec.units), FULL, 4)
    with pytest.raises(ValueError, match="model"):
        discrepancy.run(rec, "model", 4)
    assert np.all(np.isfinite(rec.y))
