"""The model-error axis (issue 17): records from a perturbed truth model, model-based sensors on the nominal one.

Expectations from closed forms (frequency ~ sqrt(stiffness / mass), the reference platform mass of Jonkman
2010, the NREL 5 MW blade's mass and centre of mass) and from the physics of a filter given the wrong model,
never from numbers the harness printed.
"""

import numpy as np
import pytest

import surrogates
from fowt_env import compare as C
from surrogates.model_error import STANDARD_PERTURBATIONS, check_perturbations, perturbed_model

NOMINAL = surrogates.FOWTModel()


def _freq(model, label):
    return model.modal_analysis().frequency(label)


def test_tower_stiffness_moves_both_first_tower_modes_by_its_square_root():
    soft = perturbed_model({"tower_stiffness": 0.95})
    for label in ("tower_fa_1", "tower_ss_1"):
        assert _freq(soft, label) / _freq(NOMINAL, label) == pytest.approx(np.sqrt(0.95), abs=0.002), label


def test_mooring_stiffness_moves_surge_by_its_square_root():
    # surge is restored by the mooring alone (a spar has no water-plane surge stiffness)
    weak = perturbed_model({"mooring_stiffness": 0.7})
    assert _freq(weak, "surge") / _freq(NOMINAL, "surge") == pytest.approx(np.sqrt(0.7), rel=0.01)
    assert _freq(weak, "heave") == pytest.approx(_freq(NOMINAL, "heave"), rel=0.01)  # heave: hydrostatics


def test_platform_mass_adds_three_percent_of_the_reference_spar_mass_to_surge():
    heavy = perturbed_model({"platform_mass": 1.03})
    # Jonkman 2010: platform mass 7,466,330 kg (DESIGN.md reference values)
    assert heavy.structure.mass[0, 0] - NOMINAL.structure.mass[0, 0] == pytest.approx(0.03 * 7_466_330, rel=1e-3)


def test_rotor_mass_imbalance_is_a_fraction_of_one_blades_first_mass_moment():
    # NREL 5 MW blade: 17,740 kg, centre of mass 20.475 m from the root, hub radius 1.5 m (Jonkman et al. 2009)
    m = perturbed_model({"rotor_mass_imbalance": 0.02})
    assert m.harmonics.mass_imbalance == pytest.approx(0.02 * 17_740 * (20.475 + 1.5), rel=0.01)
    assert perturbed_model({}).harmonics.mass_imbalance == NOMINAL.harmonics.mass_imbalance


def test_drag_coefficient_scales_the_linearised_drag():
    from surrogates.drag import drag_strips

    d1 = perturbed_model({"drag_cd": 1.5}).system(surrogates.load_case(7)).drag  # linearised about OLC 7's sea
    assert np.allclose(d1.coef, 1.5 * drag_strips().coef)


def test_unknown_or_bad_perturbations_are_clear_errors():
    with pytest.raises(ValueError, match="unknown perturbation 'tower_stifness'"):
        check_perturbations({"tower_stifness": 0.9})
    with pytest.raises(ValueError, match="> 0"):
        check_perturbations({"tower_stiffness": 0.0})
    with pytest.raises(ValueError, match="records from files are their own truth"):
        C.CompareSettings(train_files=("a.npz",), test_files=("b.npz",), truth_effects={"drag_cd": 1.5})


def test_truth_effects_change_the_records_not_the_kalman_model():
    settings = C.CompareSettings(train_cases=(1,), train_duration=10.0, duration=10.0,
                                 truth_effects={"tower_stiffness": 0.8})
    noisy, truth = C.held_out_data(7, 0, settings)
    own = surrogates.simulate(perturbed_model({"tower_stiffness": 0.8}), 7, duration=10.0, seed=0,
                              return_truth=True)[1].planar("FA").y
    assert np.array_equal(truth, own)
    # the filter keeps the nominal linearisation: its first fore-aft tower mode is the nominal 0.49 Hz, not the
    # truth's sqrt(0.8) x 0.49 = 0.44 Hz
    kf = C._new_sensor("kalman", None, settings)
    lam = np.linalg.eigvals(kf.system.A)
    lam = lam[-lam.real < 0.2 * np.abs(lam)]  # lightly damped poles (the blades' flap modes are damped 40-70 %)
    f = np.abs(lam.imag) / (2 * np.pi)
    nominal = NOMINAL.modal_analysis(settings.train_cases[0]).frequency("tower_fa_1")  # where the filter works
    assert np.min(np.abs(f - nominal)) < 0.005
    assert np.min(np.abs(f - np.sqrt(0.8) * nominal)) > 0.03


def _kalman_band_r2(truth: dict, filter_model: dict | None, seeds=(0, 1)) -> np.ndarray:
    """Median band-passed R² of the hidden channels per seed: scenario B (OLC 7) on records of ``truth``,
    the Kalman filter on the nominal model or (``filter_model``) on a perturbed one."""
    opts = {"kalman": {"model_perturbation": filter_model}} if filter_model else {}
    settings = C.CompareSettings(train_cases=(1, 4, 6, 10), train_duration=200.0, duration=240.0,
                                 truth_effects=truth, estimator_options=opts, trace_seconds=0.0)
    res = C.compare(["B"], ["kalman"], seeds=list(seeds), settings=settings, lyapunov_time=None)
    return np.array([r["median_r2_band"] for r in res.runs])


@pytest.mark.slow
def test_a_wrong_tower_stiffness_costs_the_nominal_kalman_filter_on_every_seed():
    """EI x0.8 moves the tower modes (-11 % in frequency) the filter relates hidden and live gauges through: given
    the nominal model it must do worse than given the true one, seed by seed (3-6e-4 in band-passed R²). The
    table's x0.95 cost 1.6-5.4e-5 while the tower moments were reported in fixed axes; in the sections' axes it
    costs nothing measurable (-1e-5 to -2e-5 on seeds 0-1, below the other model errors of the linear filter)."""
    truth = {"tower_stiffness": 0.8}
    wrong, right = _kalman_band_r2(truth, None), _kalman_band_r2(truth, truth)
    assert np.all(wrong < right - 1e-4), (wrong, right)


@pytest.mark.slow
@pytest.mark.matrix  # ~2 min of CPU for the four; .ci/run keeps the tower-stiffness direction test
@pytest.mark.parametrize("label", [k for k in STANDARD_PERTURBATIONS if "tower" not in k])
def test_platform_drag_mooring_and_imbalance_errors_are_below_the_seed_scatter(label):
    """Measured (README, model-error table): with 14 of 18 gauges live every sample, the platform-level errors
    do not resolve in scenario B -- the nominal-model filter is within 1e-4 in band-passed R² of the true-model
    one (for platform mass and drag it is even marginally better), less than the seed-to-seed scatter. The
    rotor imbalance's 1P load is in no linearisation: its true-model filter is the nominal one, compared here on
    the nominal turbine's records. If a physics change makes one of these resolvable, this test says so."""
    truth = STANDARD_PERTURBATIONS[label]
    wrong = _kalman_band_r2(truth, None)
    right = _kalman_band_r2({}, None) if "rotor_mass_imbalance" in truth else _kalman_band_r2(truth, truth)
    scatter = np.ptp(right)
    assert np.all(np.abs(wrong - right) < max(1e-4, scatter)), (wrong, right)
