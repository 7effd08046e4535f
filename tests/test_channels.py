"""Channel names, order and units (OpenFAST conventions)."""

from __future__ import annotations

import numpy as np
import pytest

from surrogates.channels import (
    ALL_CHANNELS,
    ENVIRONMENT_CHANNELS,
    GAUGE_HEIGHTS,
    PLATFORM_CHANNELS,
    ROTOR_CHANNELS,
    TOWER_EXTRA_CHANNELS,
    UNITS,
    UnknownChannelError,
    channel_index,
    channel_units,
    tower_channels,
)


def test_gauge_heights_equally_spaced_from_10_to_87_6_m():
    assert GAUGE_HEIGHTS.shape == (9,)
    assert GAUGE_HEIGHTS[0] == pytest.approx(10.0)
    assert GAUGE_HEIGHTS[-1] == pytest.approx(87.6)
    np.testing.assert_allclose(np.diff(GAUGE_HEIGHTS), (87.6 - 10.0) / 8, rtol=1e-12)


def test_gauge_heights_read_only():
    with pytest.raises(ValueError):
        GAUGE_HEIGHTS[0] = 0.0


def test_channel_counts():
    assert len(tower_channels("FA")) == 18
    assert len(tower_channels("SS")) == 18
    assert len(tower_channels()) == 36
    assert len(ALL_CHANNELS) == 55
    assert len(set(ALL_CHANNELS)) == 55


def test_fa_planar_order_accelerations_then_moments():
    expected = [f"TwHt{i}ALxt" for i in range(1, 10)] + [f"TwHt{i}MLyt" for i in range(1, 10)]
    assert tower_channels("FA") == expected


def test_ss_planar_order_accelerations_then_moments():
    expected = [f"TwHt{i}ALyt" for i in range(1, 10)] + [f"TwHt{i}MLxt" for i in range(1, 10)]
    assert tower_channels("SS") == expected


def test_all_tower_channels_order():
    names = tower_channels(None)
    assert names[:9] == tower_channels("FA")[:9]  # FA accelerations
    assert names[9:18] == tower_channels("SS")[:9]  # SS accelerations
    assert names[18:27] == tower_channels("FA")[9:]  # FA moments
    assert names[27:] == tower_channels("SS")[9:]  # SS moments


def test_plane_is_case_insensitive_and_returns_a_new_list():
    assert tower_channels("fa") == tower_channels("FA")
    first = tower_channels("FA")
    first.append("junk")
    assert len(tower_channels("FA")) == 18


@pytest.mark.parametrize("plane", ["XY", "", "fore-aft", 1])
def test_unknown_plane(plane):
    with pytest.raises(ValueError, match="plane"):
        tower_channels(plane)


def test_all_channels_order():
    assert ALL_CHANNELS == (tower_channels() + PLATFORM_CHANNELS + ENVIRONMENT_CHANNELS + ROTOR_CHANNELS
                            + TOWER_EXTRA_CHANNELS)
    assert len(ALL_CHANNELS) == len(set(ALL_CHANNELS)) == 55
    assert ROTOR_CHANNELS == ["BldPitch1", "GenTq", "GenPwr", "RotThrust"]
    assert TOWER_EXTRA_CHANNELS == ["TwrBsMxt", "TwrBsMyt", "YawBrTAxp", "YawBrTAyp", "TTDspFA", "TTDspSS"]
    assert PLATFORM_CHANNELS == ["PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw"]
    assert ENVIRONMENT_CHANNELS == ["RotSpeed", "Wave1Elev", "Wind1VelX"]


def test_units_openfast_strings():
    assert set(UNITS) == set(ALL_CHANNELS)
    for i in range(1, 10):
        assert UNITS[f"TwHt{i}ALxt"] == UNITS[f"TwHt{i}ALyt"] == "m/s^2"
        assert UNITS[f"TwHt{i}MLxt"] == UNITS[f"TwHt{i}MLyt"] == "kN-m"
    assert [UNITS[n] for n in PLATFORM_CHANNELS] == ["m", "m", "m", "deg", "deg", "deg"]
    assert [UNITS[n] for n in ENVIRONMENT_CHANNELS] == ["rpm", "m", "m/s"]
    assert channel_units(["RotSpeed", "TwHt2MLyt"]) == ["rpm", "kN-m"]


def test_channel_index_order_and_single_name():
    fa = tower_channels("FA")
    np.testing.assert_array_equal(channel_index(fa, ["TwHt1MLyt", "TwHt1ALxt"]), [9, 0])
    idx = channel_index(ALL_CHANNELS, "Wind1VelX")
    assert idx.tolist() == [44]
    assert np.issubdtype(idx.dtype, np.integer)
    assert channel_index(fa, []).shape == (0,)


def test_channel_index_unknown_lists_all_and_suggests():
    with pytest.raises(ValueError, match="unknown channel") as info:
        channel_index(ALL_CHANNELS, ["PtfmPich", "TwHt1ALxt", "nonsense_xyz"])
    message = str(info.value)
    assert "'PtfmPich'" in message and "did you mean 'PtfmPitch'" in message
    assert "'nonsense_xyz'" in message
    assert "TwHt1ALxt'" not in message.split(";")[0]  # known names are not reported as unknown


def test_channel_index_case_mistake_gets_suggestion():
    with pytest.raises(ValueError, match="did you mean 'TwHt3MLxt'"):
        channel_index(ALL_CHANNELS, "twht3mlxt")


def test_unknown_channel_error_is_value_and_key_error():
    with pytest.raises(KeyError):
        channel_index(["a"], "b")
    assert issubclass(UnknownChannelError, ValueError)


def test_channel_index_rejects_duplicate_available_names_and_non_strings():
    with pytest.raises(ValueError, match="names must be unique"):
        channel_index(["a", "a"], "a")
    with pytest.raises(ValueError, match="wanted"):
        channel_index(["a"], [1])
    with pytest.raises(ValueError, match="unknown"):
        channel_units(["NotAChannel"])
