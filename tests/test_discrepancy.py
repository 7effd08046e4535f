"""The discrepancy workflow on data in which an effect or a parameter change is hidden (and on data in which
nothing is): the truth is set here, the workflow only sees the record, the candidate model and the load case."""

import json
import os

import numpy as np
import pytest

import surrogates
from fowt_env import discrepancy
from surrogates.parameters import ParametricModel

FULL = surrogates.FOWTModel()
DUR, DT = 1200.0, 0.1


def _measure(model, olc, seed, duration=DUR):
    return surrogates.simulate(model, olc, duration=duration, dt=DT, seed=seed)


def _log(kind, name, truth, case, seed, rep):
    """Append the answer to the file named by ``FOWT_HIDDEN_TRUTH_LOG`` (JSON lines), if set: what
    ``tools/discrepancy_hidden_truths.py`` turns into the README's table. The assertions do not depend on it."""
    path = os.environ.get("FOWT_HIDDEN_TRUTH_LOG")
    if path:
        row = {"kind": kind, "name": name, "truth": truth, "case": case.name, "seed": seed, "verdict": rep.verdict,
               "fits": rep.fits, "alternatives": rep.alternatives, "at_bound": rep.at_bound,
               "gap_before": rep.gap_before, "gap_after": rep.gap_after, "accept": rep.accept_gap,
               "detect": rep.detect_gap, "warnings": rep.warnings, "n_simulations": rep.n_simulations}
        with open(path, "a", encoding="utf-8") as f:
            f.write(json.dumps(row, default=float) + "\n")


def _assert_names_nothing(rep, candidate):
    assert rep.effect is None and rep.effects == [] and rep.fits == [] and rep.strength is None
    assert rep.updated_model is candidate  # nothing added
    assert "named" not in rep.summary()


def test_no_hidden_effect_names_none():
    meas = _measure(FULL, 3, seed=21)  # same physics as the candidate, another seed
    rep = discrepancy.run(meas, FULL, surrogates.load_case(3), n_seeds=3)
    assert rep.verdict == "none"
    _assert_names_nothing(rep, FULL)
    assert rep.gap_after == rep.gap_before <= rep.detect_gap
    assert "no significant discrepancy" in rep.summary()
    assert not rep.warnings  # 20 minutes: long enough


# ------------------------------------------------------------------ blade passing in steady wind: quick checks
STEADY = surrogates.load_case(4).replace(turbulence_intensity=0.0)


@pytest.fixture(scope="module")
def steady_3p():
    """In steady wind: the 3P amplitudes are OpenFAST's in steady 12 m/s wind (tower shadow and shear, 1.6 % of the
    thrust, ``surrogates.RotorHarmonics``), and under OLC 4's 17 % turbulence the rotationally sampled turbulence
    puts over ten times more power in the 3P band than they do, so no feature can see them there -- as in OpenFAST,
    where turbulence dominates 3P. In steady wind 300 s suffice."""
    return surrogates.simulate(FULL, STEADY, duration=300.0, dt=DT, seed=3)


def test_findings_localise_a_hidden_3p_effect_and_its_interval_holds_the_truth(steady_3p, tmp_path):
    rep = discrepancy.run(steady_3p, FULL.without("rotor_3p"), STEADY, n_seeds=3,
                          candidates=["rotor_3p", "p_delta"])
    assert rep.findings and all(f["band_or_statistic"] == "3P" for f in rep.findings[:3])
    assert rep.verdict == "explained" and rep.effect == "rotor_3p"
    (fit,) = rep.fits
    assert fit["interval"][0] <= 1.0 <= fit["interval"][1]  # the hidden truth is 1.0
    assert fit["interval"][1] - fit["interval"][0] < 1.0
    assert rep.gap_after <= rep.accept_gap
    assert any("300 s long" in w for w in rep.warnings)  # shorter than the verified length: said so
    path = rep.plot(tmp_path / "d.png")
    assert path.stat().st_size > 10_000
    d = rep.to_dict()
    assert d["effect"] == "rotor_3p" and d["verdict"] == "explained" and "features" in d


def test_a_fit_at_the_edge_of_the_search_range_is_a_bound_not_a_value(steady_3p):
    """The truth (1.0) lies outside a search grid that ends at 0.7: the answer is 'at least 0.7', not 0.7. (The
    grid ended at 0.5, where the gap fell only 9.1 -> 8.6, at the edge of the information criterion that calls a
    bound; at 0.7 it falls to 3.4.)"""
    rep = discrepancy.run(steady_3p, FULL.without("rotor_3p"), STEADY, n_seeds=3, candidates=["rotor_3p"],
                          strengths=(0.0, 0.35, 0.7))
    assert rep.verdict in ("at_bound", "unexplained")
    assert rep.effect is None and rep.fits == []
    (b,) = rep.at_bound
    assert b["name"] == "rotor_3p" and b["side"] == "upper" and b["bound"] == pytest.approx(0.7)
    assert ">= 0.70" in rep.summary() and any("search range" in w for w in rep.warnings)


def test_a_truth_outside_the_candidates_is_unexplained_and_localised(steady_3p):
    """Blade passing hidden, but not among the candidates: the 3P findings are reported, nothing is named."""
    candidate = FULL.without("rotor_3p")
    rep = discrepancy.run(steady_3p, candidate, STEADY, n_seeds=3, candidates=["p_delta", "gyroscopic"])
    assert rep.verdict == "unexplained"
    _assert_names_nothing(rep, candidate)
    assert rep.gap_before > rep.detect_gap
    assert [f["band_or_statistic"] for f in rep.findings[:3]] == ["3P"] * 3
    assert "unexplained" in rep.summary()


def test_bad_input():
    rec = surrogates.simulate(FULL, 4, duration=150.0, dt=DT, seed=0)
    with pytest.raises(ValueError, match="PtfmPitch"):
        discrepancy.run(rec.select([c for c in rec.channels if c != "PtfmPitch"]), FULL, 4)
    with pytest.raises(ValueError, match="candidates"):
        discrepancy.run(rec, FULL, 4, candidates=["flux_capacitor"])
    with pytest.raises(ValueError, match="n_seeds"):
        discrepancy.run(rec, FULL, 4, n_seeds=1)
    with pytest.raises(ValueError, match="strengths"):
        discrepancy.run(rec, FULL, 4, strengths=(1.0,))
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


# ------------------------------------------------------------------------------ hidden truths, 20-minute records
# Each case gives the workflow the hidden truth among a few plausible decoys (the full candidate set is the
# benchmark's job: benchmarks/discrepancy.py); the truth is set here, never read from the workflow's output.
# a parked rotor in a 16 s swell from ahead: without the rotor's aerodynamic damping the platform's pitch resonance
# (about 30 s) rings, and its frequency and damping show the platform's inertia and drag
SWELL_PARKED = surrogates.load_case(12).replace(tp=16.0, wave_dir_deg=0.0, wind_speed=0.0, rotor_rpm=0.0,
                                                turbulence_intensity=0.0, name="parked, 16 s swell from ahead")

# Every parameter of surrogates.parameters but the drag coefficient hidden at two strengths, on either side of
# nominal where the physics allows, under two load cases; the workflow searches all 21 candidates (11 effects + 10
# parameters). The values are where 20 minutes of the channels show the change; smaller ones are not seen (README,
# "Detection limits": e.g. structural damping x0.5, added mass x1.1, drag Cd x0.4-2.5, platform inertia at 12 m/s).
PARAMETER_TRUTHS = [
    ("tower_fa_stiffness", 0.90, 7, 51), ("tower_fa_stiffness", 0.95, 10, 131),
    ("tower_ss_stiffness", 0.90, 7, 101), ("tower_ss_stiffness", 0.80, 4, 132),
    ("platform_mass", 1.03, 4, 55), ("platform_mass", 0.97, 10, 133),
    ("added_mass", 0.75, 4, 112), ("added_mass", 1.25, 7, 134),
    ("mooring_line_1", 0.60, 10, 54), ("mooring_line_1", 0.80, 7, 135),
    ("mooring_line_2", 0.60, 7, 105), ("mooring_line_2", 0.80, 10, 136),
    ("mooring_line_3", 0.60, 4, 106), ("mooring_line_3", 0.80, 7, 137),
    ("structural_damping", 2.0, 7, 107), ("structural_damping", 0.3, 4, 138),
    ("platform_inertia", 0.60, SWELL_PARKED, 141), ("platform_inertia", 1.40, SWELL_PARKED, 143),
]


def _case(olc):
    return olc if isinstance(olc, surrogates.LoadCase) else surrogates.load_case(olc)


def _recovered(rep, name, truth):
    """The fit of ``name`` -- named, or reported as an equally consistent alternative to the named one."""
    for fit in [*rep.fits, *rep.alternatives]:
        if fit["name"] == name:
            return fit
    raise AssertionError(f"{name} (truth {truth}) neither named nor an alternative:\n{rep.summary()}")


# the cases .ci/run checks on every change; the rest carry the `matrix` mark and are run by hand (about 25 minutes
# of CPU): `python -m pytest -m slow tests/test_discrepancy.py` or `python tools/discrepancy_hidden_truths.py`
CI_PARAMETER_TRUTHS = {("tower_fa_stiffness", 0.90), ("mooring_line_2", 0.60)}
# the truths the statistics no longer establish on issue 15's physics (measured at 2c80b68 and again after the
# inclined rotor's moment followed the blade pitch, the same answers to two digits; README, "Detection limits")
MISSED_PARAMETER_TRUTHS = {
    ("tower_fa_stiffness", 0.95): "named 0.92 (0.83-1.00 excl.), but its gap before, 2.6, is under the level 2.85",
    ("platform_mass", 1.03): "not seen: gap 2.4-2.5 under the level 2.7",
    ("structural_damping", 2.0): "not seen: gap 1.6 under the level 2.8",
    ("structural_damping", 0.3): "not seen: gap 1.7 under the level 2.7",
}


def _truth_marks(row: tuple) -> list:
    marks = [] if row[:2] in CI_PARAMETER_TRUTHS else [pytest.mark.matrix]
    if row[:2] in MISSED_PARAMETER_TRUTHS:
        marks.append(pytest.mark.xfail(strict=True, reason=MISSED_PARAMETER_TRUTHS[row[:2]]))
    return marks


@pytest.mark.slow
@pytest.mark.parametrize(("name", "truth", "olc", "seed"), [
    pytest.param(*row, id=f"{row[0]}={row[1]}-" + (f"OLC{row[2]}" if isinstance(row[2], int) else "parked_swell"),
                 marks=_truth_marks(row))
    for row in PARAMETER_TRUTHS])
def test_a_hidden_parameter_change_is_recovered_within_its_interval(name, truth, olc, seed):
    case = _case(olc)
    measured = _measure(ParametricModel(parameters={name: truth}), case, seed)
    rep = discrepancy.run(measured, FULL, case)
    _log("parameter", name, truth, case, seed, rep)
    assert rep.verdict == "explained", rep.summary()
    fit = _recovered(rep, name, truth)
    assert fit["interval"][0] <= truth <= fit["interval"][1], rep.summary()
    assert not (fit["interval"][0] < 1.0 < fit["interval"][1]), rep.summary()  # the change is established
    if any(fit.get("interval_at_bound", ())):  # an open end is said to be one
        assert "(search bound)" in rep.summary()
    if rep.effect == name:
        assert rep.updated_model.parameters[name] == pytest.approx(rep.strength)
    assert rep.gap_after <= rep.accept_gap < rep.gap_before


@pytest.mark.slow
@pytest.mark.matrix
@pytest.mark.parametrize(
    "effect, strength, olc, seed, decoys",
    [
        ("aero_damping", 1.0, 7, 31, ["p_delta", "structural_damping", "drag_cd"]),
        ("mooring_nonlinear", 1.0, 4, 32, ["rotor_3p", "platform_mass", "mooring_line_1"]),
    ],
    ids=["aero_damping", "mooring_nonlinear"],
)
def test_a_hidden_effect_is_named_within_its_interval(effect, strength, olc, seed, decoys):
    """The earlier matrix, re-based: the effect is switched off in the candidate and present in the truth."""
    measured = _measure(FULL.with_effects(**{effect: strength}), olc, seed)
    candidate = FULL.without(effect)
    before = candidate.effects
    rep = discrepancy.run(measured, candidate, surrogates.load_case(olc), candidates=[effect, *decoys])
    assert rep.verdict == "explained" and rep.effect == effect, rep.summary()
    (fit,) = rep.fits
    assert fit["interval"][0] <= strength <= fit["interval"][1], rep.summary()
    assert rep.gap_after <= 0.5 * rep.gap_before
    assert candidate.effects == before  # the given model is never modified
    assert rep.updated_model.effects[effect] == pytest.approx(rep.strength)


def _stiffness_loss():
    return ParametricModel(parameters={"tower_fa_stiffness": 0.85})


def _rotor_imbalance():
    return FULL.with_effects(rotor_1p=4.0)


@pytest.mark.slow
@pytest.mark.parametrize(
    "truth, sea, candidates, olc, seed, bands, channels",
    [
        # a fore-aft stiffness loss with no stiffness candidate: the fore-aft tower peaks move down
        (_stiffness_loss, {}, ["p_delta", "platform_mass", "platform_inertia", "added_mass", "structural_damping",
                               "aero_damping"], 7, 52, {"tower_1_frequency", "tower_2_frequency"},
         {"TwHt9ALxt", "TwHt1MLyt", "PtfmSurge", "PtfmPitch"}),
        # a rotor four times as unbalanced as the nominal one, rotor_1p not a candidate: side-to-side 1P
        (_rotor_imbalance, {}, ["rotor_3p", "rotor_asymmetry", "aero_damping", "tower_ss_stiffness", "gyroscopic"],
         7, 53, {"1P"}, {"TwHt9ALyt", "TwHt1MLxt", "PtfmSway", "PtfmYaw"}),
        # the sea has a Pierson-Moskowitz shape (gamma 1) where the model assumes JONSWAP gamma 3.3: the broader
        # spectrum's tail drives the fore-aft response above the wave band (the 1P band at 0.2 Hz)
        pytest.param(lambda: FULL, {"gamma": 1.0}, ["drag_cd", "added_mass", "platform_mass", "quadratic_drag",
                                                     "platform_inertia"], 7, 61, {"1P", "wave"},
                     {"PtfmSurge", "PtfmPitch", "TwHt9ALxt", "TwHt1MLyt"}, marks=pytest.mark.matrix),
    ],
    ids=["stiffness_loss", "rotor_imbalance", "wave_spectrum_shape"],
)
def test_a_truth_outside_the_candidate_set_is_unexplained(truth, sea, candidates, olc, seed, bands, channels):
    case = surrogates.load_case(olc)
    measured = surrogates.simulate(truth(), case.replace(**sea), duration=DUR, dt=DT, seed=seed)
    rep = discrepancy.run(measured, FULL, case, candidates=candidates)
    assert rep.verdict == "unexplained", rep.summary()
    _assert_names_nothing(rep, FULL)
    top = rep.findings[:3]
    assert top and all(f["band_or_statistic"] in bands and f["channel"] in channels for f in top), rep.summary()
    assert all(abs(f["z"]) > 3 for f in top)


# twenty records of the candidate model itself (another seed each) over the twelve OLCs
NULL_RECORDS = [(7, 71), (4, 72), (10, 73), (3, 74), (7, 75)] + [(1 + i % 12, 200 + i) for i in range(15)]


@pytest.mark.slow
def test_with_nothing_hidden_nothing_is_named_in_19_of_20_records():
    """The null case with every candidate (21): the same physics as the model, twenty other seeds. The workflow's
    level is the 99th percentile of its null gap, so about one record in a hundred may be called significant; a
    named effect in more than one of twenty would be a false discovery rate the level does not promise."""
    answers = []
    for olc, seed in NULL_RECORDS:
        rep = discrepancy.run(_measure(FULL, olc, seed), FULL, surrogates.load_case(olc))
        _log("null", None, None, surrogates.load_case(olc), seed, rep)
        answers.append((olc, seed, rep.verdict, rep.effect, round(rep.gap_before, 2), round(rep.detect_gap, 2)))
        if rep.verdict == "none":
            _assert_names_nothing(rep, FULL)
    assert sum(a[2] != "none" for a in answers) <= 1, answers
    assert sum(a[3] is not None for a in answers) <= 1, answers


@pytest.mark.slow
@pytest.mark.matrix
def test_ten_minutes_of_a_missing_aerodynamic_damping_give_an_interval_or_say_the_record_is_short():
    """The newcomer's case (issue 17): the candidate lacks aero_damping, 600 s of OLC 7, every candidate. The
    answer is the truth (1.0) inside an interval, or no value at all -- never a search bound as a strength --
    and the report says that 600 s is shorter than the verified length."""
    measured = surrogates.simulate(FULL, 7, duration=600.0, dt=DT, seed=1)
    rep = discrepancy.run(measured, FULL.without("aero_damping"), surrogates.load_case(7))
    assert any("600 s long" in w for w in rep.warnings)
    for fit in rep.fits:
        assert not any(fit["interval_at_bound"]), rep.summary()
    if rep.verdict == "explained":
        assert rep.effect == "aero_damping", rep.summary()
        lo, hi = rep.fits[0]["interval"]
        assert lo <= 1.0 <= hi, rep.summary()
    else:
        assert rep.effect is None and rep.fits == []
