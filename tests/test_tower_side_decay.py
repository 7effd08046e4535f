"""The tower's first side-to-side mode against OpenFAST's tower side-to-side free decays, parked and in operation.

The runs are ``tools/openfast_side_decay_runs.py``'s (OpenFAST v5.0.0 on the shared OC3 deck, still water, output
from t = 0), packaged in ``fowt_env/data/openfast_side_decays/``: the tower top released from 0.3 m side-to-side
with the rotor parked (locked to the nacelle), and operating in steady 8 m/s (region 2) and 12 m/s wind. The
surrogate starts from the same ElastoDyn initial conditions. The decay is ``TTDspSS`` band-passed at 0.3-0.8 Hz
(the platform's slow settling in the operating runs is far below), its frequency and damping from the positive
peaks of the eight cycles after the first 2 s (the free decays' damping criterion, 25 %, is read over three cycles
there; a 1 % damped mode loses only 17 % of its amplitude in three, so eight measure it better).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import butter, find_peaks, sosfiltfilt
from side_decays import decay_model, decay_run  # tests/ is on sys.path (pytest prepend mode)

import surrogates
from fowt_env.validation import DECAY_TOLERANCE

N_CYCLES = 8


def _decay(t: np.ndarray, x: np.ndarray) -> tuple[float, float]:
    """(frequency in Hz, damping ratio) of the band-passed decay: mean peak spacing and log decrement."""
    fs = 1.0 / float(np.median(np.diff(t)))
    y = sosfiltfilt(butter(2, [0.3, 0.8], btype="band", fs=fs, output="sos"), x)
    peaks, _ = find_peaks(y)
    peaks = peaks[t[peaks] > 2.0][: N_CYCLES + 1]
    assert peaks.size == N_CYCLES + 1
    delta = float(np.log(y[peaks[0]] / y[peaks[-1]])) / N_CYCLES
    return 1.0 / float(np.mean(np.diff(t[peaks]))), delta / float(np.sqrt(4.0 * np.pi**2 + delta**2))


def _pair(name: str) -> tuple[tuple[float, float], tuple[float, float]]:
    rec, case = decay_run(name)
    if case["wind_speed"] > 0:
        lc = surrogates.operating_case(float(case["wind_speed"]), 0.0, 10.0, turbulence_intensity=0.0)
        start = case["start"]
    else:
        lc, start = None, case["initial"]
    sim = surrogates.simulate(decay_model(), lc, float(case["duration_s"]), 0.0125, 0, transient=0.0, noise=False,
                              initial=start)
    return (_decay(np.asarray(rec.t), np.asarray(rec["TTDspSS"])),
            _decay(np.asarray(sim.t), np.asarray(sim["TTDspSS"])))


@pytest.mark.parametrize("name", ["sd_op08_ss0p3", "sd_op12_ss0p3"])
def test_the_operating_side_to_side_tower_decay_is_openfasts(name):
    """In operation, region 2 (8 m/s) and 3 (12 m/s): frequency within 3 % and damping within 25 % of OpenFAST's
    (the issue's free-decay criteria); measured (surrogate / OpenFAST) 0.4954 / 0.4969 Hz and 0.94 / 1.06 % at
    8 m/s, 0.4954 / 0.4969 Hz and 1.09 / 1.08 % at 12 m/s (0.97 and 1.00 % before the rotor's force along its
    lateral in-plane wind grew with the blades' bend, :func:`surrogates.aero.inplane_wind_loads`). The rotor turns
    free of the nacelle's roll (``rotor_free_inertia``): locked, the mode is at 0.48 Hz. The 3P line of a turbulent
    12 m/s run whose rotor falls into region 2 sits on this mode, so its frequency and damping set that resonance."""
    (f_of, z_of), (f_sur, z_sur) = _pair(name)
    assert 0.48 < f_of < 0.52  # the record is the operating side-to-side tower decay
    assert f_sur == pytest.approx(f_of, rel=DECAY_TOLERANCE["period"])
    assert z_sur == pytest.approx(z_of, rel=DECAY_TOLERANCE["damping"])


@pytest.mark.xfail(strict=True, reason="the blades' edgewise flexibility is not modelled: parked, the locked rotor's "
                                       "roll inertia meets it (OpenFAST 0.457 Hz, 0.469 Hz with EdgeDOF off)")
def test_the_parked_side_to_side_tower_decay_is_openfasts():
    """Parked (the rotor locked to the nacelle): frequency within 3 % of OpenFAST's. It misses: 0.4787 against
    0.4568 Hz (+4.8 %). By hand, OpenFAST with the blades' edgewise DOF off gives 0.4689 Hz (rigid blades 0.4692):
    the locked rotor rolls with the nacelle, and its edgewise-flexible blades, whose mode (~1.1 Hz) is not far
    above, add to its roll inertia; the rest (+2.0 %) is within the criterion. In operation the rotor turns free of
    the roll and the two agree (above)."""
    (f_of, _), (f_sur, _) = _pair("sd_parked_ss0p3")
    assert 0.44 < f_of < 0.47  # the record is the parked side-to-side tower decay
    assert f_sur == pytest.approx(f_of, rel=DECAY_TOLERANCE["period"])
