"""Damage-equivalent loads from Python (fowt_env.validation.record_dels) and the CLI (fowt-env fatigue), against
closed forms and the rainflow package's own reference case (issue 19, item 7).

Truths: a sine of amplitude A is one cycle of range 2A per period, so with N_eq = its number of cycles the DEL is
2A for any Woehler exponent, and with N_eq = 1 Hz x duration it is 2A (f / 1 Hz)^(1/m). The series
[-2, 1, -3, 5, -1, 3, -4, 4, -2] is the ASTM E1049-85 example the rainflow package documents: ranges 3 (half),
4 (1.5 cycles), 6 (half), 8 (one), 9 (half).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fowt_env.cli import main
from fowt_env.io import save_record
from fowt_env.validation import record_dels
from surrogates import Record


def _sine_record(amplitude: float, f_hz: float, duration: float = 200.0, dt: float = 0.01) -> Record:
    t = np.arange(0.0, duration + dt / 2, dt)
    y = np.c_[amplitude * np.sin(2 * np.pi * f_hz * t), 0.3 * amplitude * np.cos(2 * np.pi * f_hz * t),
              np.ones_like(t)]
    return Record(t, y, ["TwrBsMyt", "TwHt5MLxt", "RotSpeed"], ["kN-m", "kN-m", "rpm"])


@pytest.mark.parametrize("m", [3.0, 4.0, 10.0])
def test_del_of_a_sine_is_its_range(m):
    rec = _sine_record(750.0, 0.5)
    dels = record_dels(rec, m=m, frequency_hz=0.5)  # N_eq = the sine's own cycle count
    assert list(dels) == ["TwrBsMyt", "TwHt5MLxt"]  # the moments only, in record order
    assert dels["TwrBsMyt"] == pytest.approx(1500.0, rel=2e-3)
    assert dels["TwHt5MLxt"] == pytest.approx(450.0, rel=2e-3)
    at_1hz = record_dels(rec, ["TwrBsMyt"], m=m)["TwrBsMyt"]
    assert at_1hz == pytest.approx(1500.0 * 0.5 ** (1 / m), rel=2e-3)


def test_cli_fatigue_of_a_sine_and_of_the_astm_example(tmp_path, capsys):
    path = save_record(_sine_record(750.0, 0.5), tmp_path / "sine.npz")
    assert main(["fatigue", str(path), "--frequency", "0.5", "--json", str(tmp_path / "d.json")]) == 0
    out = json.loads((tmp_path / "d.json").read_text())
    assert out["dels"]["TwrBsMyt"]["del"] == pytest.approx(1500.0, rel=2e-3)
    assert out["dels"]["TwrBsMyt"]["unit"] == "kN-m" and "RotSpeed" not in out["dels"]
    assert "TwrBsMyt" in capsys.readouterr().out

    series = np.array([-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0])
    rec = Record(np.arange(series.size, dtype=float), series[:, None], ["TwrBsMxt"], ["kN-m"])
    path = save_record(rec, tmp_path / "astm.npz")
    assert main(["fatigue", str(path), "--m", "3", "--json", str(tmp_path / "a.json")]) == 0
    damage = 0.5 * 3**3 + 1.5 * 4**3 + 0.5 * 6**3 + 1.0 * 8**3 + 0.5 * 9**3
    expected = (damage / (1.0 * (series.size - 1))) ** (1 / 3)
    assert json.loads((tmp_path / "a.json").read_text())["dels"]["TwrBsMxt"]["del"] == pytest.approx(expected)


def test_fatigue_errors_are_one_line(tmp_path, capsys):
    path = save_record(_sine_record(1.0, 0.5), tmp_path / "s.npz")
    assert main(["fatigue", str(path), "--channels", "TwrBsMzt"]) == 2
    assert "not in the record" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_:
        main(["fatigue", str(path), "--m", "0"])
    assert exit_.value.code == 2
    rec = Record(np.arange(10.0), np.ones((10, 1)), ["RotSpeed"], ["rpm"])
    with pytest.raises(ValueError, match="no tower moment channel"):
        record_dels(rec)
