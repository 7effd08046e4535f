"""Parameter multipliers of the surrogate (the discrepancy workflow's parametric candidates)."""

import numpy as np
import pytest

import surrogates
from surrogates.mooring import tangent_stiffness
from surrogates.parameters import PARAMETERS, ParametricModel, line_tangent_stiffness, resolve_parameters


def test_the_three_lines_add_up_to_the_catenary_tangent_stiffness():
    total = sum(line_tangent_stiffness(i) for i in range(3))
    ref = tangent_stiffness()
    assert np.allclose(total, 0.5 * (ref + ref.T), rtol=0, atol=1e-6 * np.max(np.abs(ref)))
    # line 1 is downwind: it carries more of the surge stiffness than of the sway stiffness
    k1 = line_tangent_stiffness(0)
    assert k1[0, 0] > 10 * k1[1, 1]


def test_nominal_parameters_are_the_nominal_model():
    nominal = surrogates.FOWTModel()
    same = ParametricModel()
    assert same.structure is nominal.structure
    assert np.array_equal(same.system(7).A, nominal.system(7).A)


@pytest.mark.parametrize(("name", "mode", "direction"), [
    ("tower_fa_stiffness", "tower_fa_2", +1), ("tower_ss_stiffness", "tower_ss_2", +1),
    ("platform_inertia", "yaw", -1), ("added_mass", "surge", -1), ("mooring_line_1", "surge", +1),
])
def test_a_multiplier_moves_its_mode(name, mode, direction):
    """Stiffer -> higher, heavier -> lower: each multiplier above 1 moves the mode it acts on that way."""
    f0 = ParametricModel().modal_analysis().frequency(mode)
    f1 = ParametricModel(parameters={name: 1.2}).modal_analysis().frequency(mode)
    assert np.sign(f1 - f0) == direction and abs(f1 / f0 - 1) > 0.01


def test_a_stiffness_loss_lowers_the_mode_by_its_square_root_when_the_mode_is_tower_only():
    """The 2nd fore-aft tower mode is nearly pure tower bending: its frequency scales as sqrt(EI)."""
    f0 = ParametricModel().modal_analysis().frequency("tower_fa_2")
    f1 = ParametricModel(parameters={"tower_fa_stiffness": 0.81}).modal_analysis().frequency("tower_fa_2")
    assert f1 / f0 == pytest.approx(0.9, abs=0.015)


def test_drag_coefficient_scales_the_drag_strips():
    m = ParametricModel(parameters={"drag_cd": 2.0})
    nominal = surrogates.FOWTModel().system(7).drag
    assert np.allclose(m.system(7).drag.coef, 2.0 * nominal.coef)


def test_copies_keep_the_parameters_and_round_trip():
    m = ParametricModel({"rotor_3p": 0.5}, parameters={"mooring_line_2": 0.7})
    assert m.with_effects(p_delta=0.0).parameters["mooring_line_2"] == 0.7
    assert m.with_noise(scale=0.0).parameters["mooring_line_2"] == 0.7
    back = ParametricModel.from_dict(m.to_dict())
    assert back.parameters == m.parameters and back.effects == m.effects


def test_bad_parameters():
    with pytest.raises(ValueError, match="unknown parameter"):
        resolve_parameters({"flux": 1.0})
    with pytest.raises(ValueError, match="> 0"):
        resolve_parameters({"drag_cd": 0.0})
    for p in PARAMETERS.values():
        assert p.bounds[0] < 1.0 < p.bounds[1] and p.bounds[0] <= p.probe <= p.bounds[1]
