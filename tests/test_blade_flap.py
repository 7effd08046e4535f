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
    NREL/TP-500-38060, Table 9-1; land-based, but the spar moves little at 0.7 Hz). The cyclic (tilt and yaw)
    flap modes lie near it: FAST's land-based asymmetric flap modes are 0.6664-0.6675 Hz, and on the spar the
    rotor plane's yaw is freer (the platform's, not a stiff tower's), which raises the yaw one."""
    modal = surrogates.FOWTModel().modal_analysis()
    assert modal.frequency("blade_flap") == pytest.approx(0.6993, rel=0.03)
    assert modal.frequency("blade_flap_tilt") == pytest.approx(0.6675, rel=0.03)
    assert 0.6664 < modal.frequency("blade_flap_yaw") < 1.08 * 0.6664
    # the blade alone on a rigid hub, from the same mode shape: the coupled collective mode sits above it (the hub
    # moves against the blades), and the turning rotor stiffens it
    mode = surrogates.FOWTModel().structure.data.blade_flap
    assert mode.frequency_hz(0.0) < modal.frequency("blade_flap")
    assert mode.frequency_hz(12.1) > 1.05 * mode.frequency_hz(0.0)


def _hankel_dmd_modes(y: np.ndarray, dt: float, delays: int, rank: int) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (Hz) and damping ratios of the delay-embedded linear fit of ``y`` (channels x samples)."""
    n = y.shape[1]
    h = np.vstack([y[:, i:n - delays + i] for i in range(delays)])
    u = np.linalg.svd(h, full_matrices=False)[0][:, :rank]
    a = u.T @ h[:, 1:] @ np.linalg.pinv(u.T @ h[:, :-1])
    lam = np.log(np.linalg.eigvals(a).astype(complex)) / dt
    return lam.imag / (2 * np.pi), -lam.real / np.abs(lam)


@pytest.mark.skipif(not RUNS.is_dir(), reason="needs ../shared/reference/openfast (full OpenFAST outputs)")
def test_parked_flap_modes_the_tower_decay_excites_are_openfasts():
    """OpenFAST's parked tower fore-aft decay rings the blades' flap modes (blade 1 up: its tip swings by up to
    2 m, ``OoPDefl1``); a delay-embedded fit of ``OoPDefl1``, ``TTDspFA`` and ``YawBrTAxp`` finds them at 0.651,
    0.677 and 0.709 Hz. The two that the fore-aft motion drives in the surrogate, the collective and the tilt
    (cyclic) flap, mixed through the tower top, are within 2 % of two of them."""
    from fowt_env.io import load_record

    ref = load_record(RUNS / "b_decay_towerFA0p3m" / "b_decay_towerFA0p3m.outb", unknown_channels="keep")
    y = np.array([ref[c] for c in ("OoPDefl1", "TTDspFA", "YawBrTAxp")], dtype=float)[:, ::4]
    y = (y - y.mean(axis=1, keepdims=True)) / y.std(axis=1, keepdims=True)
    f, zeta = _hankel_dmd_modes(y, 4 * float(ref.t[1] - ref.t[0]), delays=200, rank=16)
    found = f[(f > 0.6) & (f < 0.8) & (zeta > 0) & (zeta < 0.05)]
    assert found.size >= 2, f
    modal = surrogates.FOWTModel().modal_analysis()
    for label in ("blade_flap", "blade_flap_tilt"):
        assert np.min(np.abs(found - modal.frequency(label)) / found) < 0.02, (label, found)


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
@pytest.mark.parametrize("run", [
    pytest.param("c_op08_Hs2p0_Tp9", marks=pytest.mark.xfail(strict=True, reason=(
        "measured -12.8 % (2.80 m against 3.21): the flap mode takes the thrust at one fixed centre, where OpenFAST's "
        "moves outboard at fine pitch (8.6 mm of tip per kN of aerodynamic thrust at 8 m/s, 7.6 at 12 m/s); it was "
        "-11.6 % until the bent blades' lower thrust (blade_deflection) took another 0.5 %, -12.0 % until the "
        "equilibrium held the controller's steady state with the inclined rotor"))),
    "d_steady12_Hs2p5_Tp10"])
def test_static_tip_deflection_in_operation_is_openfasts(run):
    """The blades' tip deflection at the equilibrium against OpenFAST's mean ``OoPDefl1`` (3.21 m at 8 m/s, 5.10 m
    in steady 12 m/s wind; not in the packaged records). In steady wind the equilibrium is the mean; in turbulent
    wind near rated it is not (OpenFAST's turbulent 12 m/s run: 4.26 m, the mean thrust under turbulence is lower
    than the steady thrust at the mean wind, ``surrogates.simulate.turbulent_thrust_ratio``). At 18 m/s (pitch
    14 deg) the surrogate's 2.6 m is 52 % above OpenFAST's 1.69 m: its flap mode bends along the shaft,
    ElastoDyn's along the pitched blade's principal axes. At 8 m/s it is 12.8 % below (a strict xfail: the fixed
    thrust centre of the flap's modal load)."""
    from fowt_env.io import load_record

    ref = load_record(RUNS / run / f"{run}.outb", unknown_channels="keep")
    measured = float(np.mean(ref["OoPDefl1"][ref.t >= ref.t[0] + 100.0]))
    case = load_reference(RUNS, runs=[run])[0][0].case
    model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS)
    sim = Simulator(model, surrogate_case(case))
    tip = sim.x_eq[model.structure.labels.index("blade_flap")]
    assert tip == pytest.approx(measured, rel=0.12)
