"""The seed paper's operational load cases and LoadCase validation."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from surrogates.load_cases import (
    DEFAULT_JONSWAP_GAMMA,
    LOAD_CASES,
    LoadCase,
    iec_ntm_turbulence_intensity,
    load_case,
)

# Abaei et al., "Equation-Free Digital Twins for Nonlinear Structural Dynamics", Table 1 (the paper's inputs):
# case -> (Hs (m), Tp (s), wave direction relative to the wind (deg)); wind 12 m/s, rotor 12.1 rpm for all.
ABAEI_TABLE_1 = {
    1: (1.0, 6.0, 0.0),
    2: (1.0, 9.0, 45.0),
    3: (1.0, 12.0, 90.0),
    4: (2.0, 8.0, 0.0),
    5: (2.0, 10.0, 45.0),
    6: (2.0, 14.0, 90.0),
    7: (3.0, 10.0, 0.0),
    8: (3.0, 12.0, 45.0),
    9: (3.0, 16.0, 90.0),
    10: (4.0, 9.0, 0.0),
    11: (4.0, 12.0, 45.0),
    12: (4.0, 20.0, 90.0),
}


def valid_kwargs(**overrides):
    kwargs = dict(
        hs=2.0,
        tp=10.0,
        wave_dir_deg=45.0,
        wind_speed=12.0,
        rotor_rpm=12.1,
        turbulence_intensity=0.17,
        gamma=3.3,
    )
    kwargs.update(overrides)
    return kwargs


@pytest.mark.parametrize("n", sorted(ABAEI_TABLE_1))
def test_abaei_table_1_values(n):
    hs, tp, direction = ABAEI_TABLE_1[n]
    case = load_case(n)
    assert (case.hs, case.tp, case.wave_dir_deg) == (hs, tp, direction)
    assert case.wind_speed == 12.0
    assert case.rotor_rpm == pytest.approx(12.1, abs=0.01)  # NREL 5 MW rated speed (Jonkman 2009, table 1-1)
    assert case.name == f"OLC{n}"
    assert LOAD_CASES[n] == case


def test_twelve_cases():
    assert sorted(LOAD_CASES) == list(range(1, 13))


def test_assumed_gamma_and_iec_turbulence_intensity():
    # IEC 61400-1 NTM, class B: sigma_1 = I_ref (0.75 V + 5.6), I_ref = 0.14, at V = 12 m/s.
    expected_ti = 0.14 * (0.75 * 12.0 + 5.6) / 12.0
    assert expected_ti == pytest.approx(0.170333, abs=1e-6)
    assert iec_ntm_turbulence_intensity(12.0) == pytest.approx(expected_ti, rel=1e-14)
    assert iec_ntm_turbulence_intensity(12.0, i_ref=0.16) == pytest.approx(0.16 * 14.6 / 12.0)
    for case in LOAD_CASES.values():
        assert case.turbulence_intensity == pytest.approx(expected_ti, rel=1e-14)
        assert case.gamma == DEFAULT_JONSWAP_GAMMA == 3.3


@pytest.mark.parametrize("bad", [0, 13, -1, 1.0, "7", True, None])
def test_unknown_case_number_lists_valid(bad):
    with pytest.raises(ValueError, match=r"\[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12\]"):
        load_case(bad)


def test_numpy_integer_case_number():
    assert load_case(np.int64(3)).name == "OLC3"


def test_load_cases_is_read_only():
    with pytest.raises(TypeError):
        LOAD_CASES[1] = LOAD_CASES[2]  # type: ignore[index]


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("hs", -0.1),
        ("tp", 0.0),
        ("tp", -5.0),
        ("wave_dir_deg", math.inf),
        ("wind_speed", -1.0),
        ("rotor_rpm", -0.5),
        ("turbulence_intensity", -0.01),
        ("turbulence_intensity", 1.0),
        ("gamma", 0.99),
        ("gamma", 10.5),
        ("hs", math.nan),
        ("tp", "10"),
        ("gamma", True),
    ],
)
def test_validation_names_the_argument(field, value):
    with pytest.raises(ValueError, match=field):
        LoadCase(**valid_kwargs(**{field: value}))


def test_validation_of_name():
    with pytest.raises(ValueError, match="name"):
        LoadCase(**valid_kwargs(), name=3)


def test_boundary_values_accepted():
    case = LoadCase(**valid_kwargs(hs=0, turbulence_intensity=0.0, gamma=1, wind_speed=0, rotor_rpm=0))
    assert case.hs == 0.0 and isinstance(case.hs, float)
    assert LoadCase(**valid_kwargs(gamma=10.0)).gamma == 10.0


def test_frozen():
    case = load_case(1)
    with pytest.raises(AttributeError):
        case.hs = 5.0  # type: ignore[misc]


def test_dict_round_trip_through_json():
    case = load_case(8)
    data = json.loads(json.dumps(case.to_dict()))
    assert LoadCase.from_dict(data) == case
    assert set(data) == {
        "hs",
        "tp",
        "wave_dir_deg",
        "wind_speed",
        "rotor_rpm",
        "turbulence_intensity",
        "gamma",
        "name",
    }


def test_from_dict_errors():
    data = load_case(1).to_dict()
    with pytest.raises(ValueError, match="unknown"):
        LoadCase.from_dict({**data, "hsig": 1.0})
    missing = dict(data)
    del missing["tp"]
    with pytest.raises(ValueError, match="tp"):
        LoadCase.from_dict(missing)
    with pytest.raises(ValueError, match="mapping"):
        LoadCase.from_dict([1, 2])  # type: ignore[arg-type]
    no_name = dict(data)
    del no_name["name"]
    assert LoadCase.from_dict(no_name).name == "custom"


def test_replace_validates():
    case = load_case(4)
    other = case.replace(hs=2.5, name="OLC4b")
    assert (other.hs, other.name, other.tp) == (2.5, "OLC4b", case.tp)
    assert case.hs == 2.0
    with pytest.raises(ValueError, match="hs"):
        case.replace(hs=-1.0)
    with pytest.raises(ValueError, match="unknown"):
        case.replace(height=1.0)


def test_si_conversions():
    case = load_case(3)
    assert case.wave_dir_rad == pytest.approx(math.pi / 2)
    assert case.rotor_speed_rad_s == pytest.approx(12.1 * 2 * math.pi / 60)


def test_iec_ti_validation():
    with pytest.raises(ValueError, match="wind_speed"):
        iec_ntm_turbulence_intensity(0.0)
    with pytest.raises(ValueError, match="i_ref"):
        iec_ntm_turbulence_intensity(10.0, i_ref=-0.1)
