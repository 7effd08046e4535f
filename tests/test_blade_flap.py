"""The blades' collective first flap mode against independent references: FAST's full-system frequency (Jonkman
et al. 2009), OpenFAST's parked tower decay (packaged record) and OpenFAST's mean tip deflection in operation
(shared runs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import surrogates
from fowt_env.validation import decay_analysis, load_reference, surrogate_case
from surrogates.simulate import Simulator

RUNS = Path(__file__).resolve().parents[1] / "../shared/reference/openfast/runs"


def test_parked_collective_flap_frequency_is_fasts():
    """NREL 5 MW, 1st blade collective flap, parked: 0.6993 Hz in FAST, 0.7008 Hz in ADAMS (Jonkman et al. 2009,
    NREL/TP-500-38060, Table 9-1; land-based, but the spar moves little at 0.7 Hz)."""
    modal = surrogates.FOWTModel().modal_analysis()
    assert modal.frequency("blade_flap") == pytest.approx(0.6993, rel=0.02)
    # the blade alone on a rigid hub, from the same mode shape: the coupled mode sits above it (the hub moves
    # against the blades), and the turning rotor stiffens it
    mode = surrogates.FOWTModel().structure.data.blade_flap
    assert mode.frequency_hz(0.0) < modal.frequency("blade_flap")
    assert mode.frequency_hz(12.1) > 1.05 * mode.frequency_hz(0.0)


def test_flexible_blades_lengthen_the_tower_period_and_make_its_decay_beat():
    """OpenFAST's parked tower fore-aft decay (packaged record): period 2.107 s; its peaks beat with the flap mode,
    so the damping fitted over three cycles exceeds the one over ten. With rigid blades the surrogate's period
    was 2.047 s (-2.9 %) and its decay did not beat."""
    run = load_reference(None, runs=["b_decay_towerFA0p3m"])[0][0]
    model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS)
    sim = surrogates.simulate(model, None, duration=60.0, initial={"TTDspFA": 0.3}, transient=0.0, seed=0,
                              noise=False)
    of3 = decay_analysis(run.record.t, run.record["TTDspFA"], n_cycles=3)
    of10 = decay_analysis(run.record.t, run.record["TTDspFA"], n_cycles=10)
    s3 = decay_analysis(sim.t, sim["TTDspFA"], n_cycles=3)
    s10 = decay_analysis(sim.t, sim["TTDspFA"], n_cycles=10)
    assert s3.period_s == pytest.approx(of3.period_s, rel=0.025)
    assert of3.damping_ratio > 1.5 * of10.damping_ratio  # OpenFAST beats ...
    assert s3.damping_ratio > 1.2 * s10.damping_ratio  # ... and so does the surrogate now, less strongly


@pytest.mark.skipif(not RUNS.is_dir(), reason="needs ../shared/reference/openfast (full OpenFAST outputs)")
@pytest.mark.parametrize("run", ["c_op08_Hs2p0_Tp9", "c_op12_Hs2p5_Tp10"])
def test_static_tip_deflection_in_operation_is_openfasts(run):
    """The blades' tip deflection at the operating point against OpenFAST's mean ``OoPDefl1`` (3.21 m at 8 m/s,
    4.26 m at 12 m/s; not in the packaged records). At 18 m/s (pitch 14 deg) the surrogate's 2.5 m is 46 % above
    OpenFAST's 1.69 m: its flap mode bends along the shaft, ElastoDyn's along the pitched blade's principal axes."""
    from fowt_env.io import load_record

    ref = load_record(RUNS / run / f"{run}.outb", unknown_channels="keep")
    measured = float(np.mean(ref["OoPDefl1"][ref.t >= ref.t[0] + 100.0]))
    case = load_reference(RUNS, runs=[run])[0][0].case
    model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS)
    sim = Simulator(model, surrogate_case(case))
    tip = sim.x_eq[model.structure.labels.index("blade_flap")]
    assert tip == pytest.approx(measured, rel=0.12)
