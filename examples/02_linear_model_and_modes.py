"""Lesson 2 -- the linear model and its modes: what the floating turbine rings at.

The physics. Linearised about its operating point, the surrogate is ``M q'' + C q' + K q = f``: ten
generalised coordinates q (six rigid platform motions -- surge, sway, heave, roll, pitch, yaw -- and two fore-aft
and two side-to-side tower bending modes), a mass matrix with the water's added mass, hydrostatic and mooring
stiffness, and damping. Its eigenvalues are the natural frequencies and damping ratios; its eigenvectors the
mode shapes. For a spar they fall into two families far apart: the platform rigid-body modes (periods of 30 s to
two minutes, below the waves) and the tower bending modes (about 0.5 Hz and above 2 Hz, above the waves but close
to the rotor's 3P blade passing at 0.6 Hz). Keeping the waves (0.05-0.2 Hz) between the two families is the
design.

What this script does.

1. ``model.modal_analysis()`` in the parked condition (rotor still, no wind, still water -- the conditions of the
   OC3 free-decay tests) against the OC3 reference values (Jonkman 2010 for the platform; the BModes deck for
   the tower), and ``model.modal_analysis(case)`` at the OLC 7 operating point (12 m/s, just above rated, rotor
   turning, pitch controller active) and below rated (8 m/s, variable speed, blades at fine pitch), each also
   with ``aero_damping`` switched off: the difference is the aerodynamic damping. (Parked still water is not
   the baseline for it: the Morison drag is linearised about each sea state's own response, so in waves the
   platform is damped more by the water too.)
2. The mode shapes: lateral displacement along the structure, from the keel (-120 m) to the tower top (87.6 m),
   ``model.structure.point_translation(z) @ shape``.
3. ``model.linearize(case, plane="FA")`` -- a ``control.StateSpace`` -- and its frequency response from the wave
   surge force and from the wind to the tower-base fore-aft bending moment: every mode is a peak, every peak a
   mode. The poles of the state space are the modal frequencies of step 1 (printed as a check).

What to look for.

* Parked, the platform modes agree with the OC3 reference within a few per cent and the tower modes within
  about 2-5 % (the BModes deck's 2nd fore-aft bending mode is at 2.55 Hz; the 1.57 Hz of the seed paper's
  "2nd FA" is the tower's torsion, which the surrogate does not model -- DESIGN.md).
* Operating, aerodynamic damping appears in the 1st fore-aft tower mode (several times its structural damping),
  not in the side-to-side modes (the rotor pushes air fore-aft only). Platform pitch depends on the control
  region. Below rated the blades sit at fine pitch and the thrust grows with the wind relative to the hub:
  pitch is damped several times more than without aerodynamics. Above rated the pitch controller holds the
  power constant, so the thrust *drops* as the platform moves into the wind: the aerodynamics take damping away
  from platform pitch and surge -- the negative-damping mechanism of floating turbines above rated (Larsen and
  Hanson 2007; Jonkman 2008, NREL/CP-500-42589). The OC3 controller was detuned (0.2 rad/s, below the platform
  pitch frequency) so that what is left stays positive.
* The tower modes of a floating turbine are coupled modes: when the tower bends, the whole spar rocks against it
  (the displacement does not vanish at the tower base as it would for a fixed-bottom cantilever; there is a node
  far below the water line). Platform surge and pitch are rigid-body motions: a vertical and a straight line.
* In the frequency response the wave band lies between the platform resonances and the 1st tower mode: no mode
  is driven resonantly by the waves, and the 3P line sits just above the 1st tower mode.

Writes ``02_mode_shapes.png`` and ``02_frequency_response.png``. Next: lesson 3 (``03_switching_effects_on.py``)
leaves the linear world and switches the named nonlinear effects on one at a time.

Usage: python examples/02_linear_model_and_modes.py [--quick] [--out DIR]
"""

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import surrogates

CASE = 7
BELOW_RATED_WIND = 8.0  # m/s, region 2 of the controller (rated wind 11.4 m/s)

# OC3 Hywind reference frequencies (Hz), see DESIGN.md: platform modes from FAST free-decay tests (Jonkman 2010,
# NREL/TP-500-47535); coupled tower modes from the BModes deck that pybmodes ships.
OC3_REFERENCE_HZ = {
    "surge": 0.0080, "sway": 0.0080, "heave": 0.0324, "roll": 0.0342, "pitch": 0.0343, "yaw": 0.1210,
    "tower_fa_1": 0.483, "tower_ss_1": 0.492, "tower_fa_2": 2.554, "tower_ss_2": 2.053,
    # 1st blade flap, parked: collective, asymmetric pitch (tilt) and yaw (FAST; Jonkman et al. 2009,
    # NREL/TP-500-38060, Table 9-1; land-based: on the spar the rotor plane's yaw is freer, which raises the yaw one)
    "blade_flap": 0.6993, "blade_flap_tilt": 0.6675, "blade_flap_yaw": 0.6664,
}
FA_MODES = ("surge", "pitch", "tower_fa_1", "tower_fa_2")  # displacements along x (downwind)
SS_MODES = ("sway", "roll", "tower_ss_1", "tower_ss_2")  # displacements along y (to port)


def deflection(model: surrogates.FOWTModel, shape: np.ndarray, z: np.ndarray, axis: int) -> np.ndarray:
    """Lateral displacement (axis 0 = x, 1 = y) along heights ``z`` of a mode shape in generalised coordinates."""
    return np.array([model.structure.point_translation(zi)[axis] @ shape for zi in z])


def frequency_response(ss, f_hz: np.ndarray, inp: str, out: str) -> np.ndarray:
    """|H(f)| of one input-output pair of a continuous state space: C (j w I - A)^-1 B + D."""
    i, o = ss.input_labels.index(inp), ss.output_labels.index(out)
    A, B, C, D = (np.asarray(m) for m in (ss.A, ss.B, ss.C, ss.D))
    eye = np.eye(A.shape[0])
    h = [C[o] @ np.linalg.solve(2j * np.pi * f * eye - A, B[:, i]) + D[o, i] for f in f_hz]
    return np.abs(np.array(h))


def main(quick: bool = False, out: str = ".") -> dict:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    model = surrogates.FOWTModel()
    case = surrogates.load_case(CASE)
    below = case.replace(wind_speed=BELOW_RATED_WIND)  # rotor speed: the controller's steady state there
    no_aero = model.without("aero_damping")
    parked = model.modal_analysis()  # no argument: parked rotor, no wind, still water
    operating = model.modal_analysis(case)
    operating_no_aero = no_aero.modal_analysis(case)
    below_rated = model.modal_analysis(below)
    below_rated_no_aero = no_aero.modal_analysis(below)

    def zeta(analysis, lab: str) -> float:
        return float(analysis.damping_ratios[analysis.labels.index(lab)])

    print("damping ratio zeta; 'no aero': the same operating point with aero_damping off")
    print(f"{'mode':<16}{'parked f (Hz)':>14}{'OC3 ref (Hz)':>14}{'diff':>8}{'zeta parked':>13}"
          f"{case.name + ' ' + str(case.wind_speed) + ' m/s':>18}{'no aero':>9}"
          f"{str(below.wind_speed) + ' m/s':>10}{'no aero':>9}")
    for lab, f, z in zip(parked.labels, parked.frequencies_hz, parked.damping_ratios, strict=True):
        ref = OC3_REFERENCE_HZ[lab]
        zs = [zeta(a, lab) for a in (operating, operating_no_aero, below_rated, below_rated_no_aero)]
        print(f"{lab:<16}{f:>14.4f}{ref:>14.4f}{100 * (f / ref - 1):>+7.1f}%{100 * z:>12.2f}%"
              f"{100 * zs[0]:>17.2f}%{100 * zs[1]:>8.2f}%{100 * zs[2]:>9.2f}%{100 * zs[3]:>8.2f}%")

    # the poles of the linearised state space are the modes
    ss = model.linearize(case, plane="FA")
    poles = np.linalg.eigvals(np.asarray(ss.A))
    f_poles = np.abs(poles.imag[poles.imag > 0]) / (2 * np.pi)
    f_tower = operating.frequency("tower_fa_1")
    print(f"linearize({case.name}, plane='FA'): {ss.nstates} states, inputs {list(ss.input_labels)}")
    print(f"  pole nearest tower_fa_1: {f_poles[np.argmin(abs(f_poles - f_tower))]:.4f} Hz "
          f"(modal_analysis: {f_tower:.4f} Hz)")

    # figure 1: mode shapes along the structure (parked)
    z = np.linspace(-120.0, 87.6, 209)
    fig, axes = plt.subplots(1, 2, figsize=(10, 6), sharey=True)
    for ax, labels, axis, plane in ((axes[0], FA_MODES, 0, "fore-aft (x)"), (axes[1], SS_MODES, 1,
                                                                           "side-to-side (y)")):
        for lab in labels:
            k = parked.labels.index(lab)
            x = deflection(model, parked.shapes[:, k], z, axis)
            x = x / x[np.argmax(np.abs(x))]
            ax.plot(x, z, lw=1.8, label=f"{lab}  {parked.frequencies_hz[k]:.3f} Hz")
        ax.axhline(0.0, color="tab:blue", lw=0.8, ls="--")
        ax.axhline(10.0, color="0.5", lw=0.8, ls=":")
        ax.text(-1.0, 1.5, "still water level", fontsize=7, color="tab:blue")
        ax.text(-1.0, 11.5, "tower base", fontsize=7, color="0.4")
        ax.axvline(0.0, color="0.7", lw=0.8)
        ax.set_xlim(-1.1, 1.1)
        ax.set_xlabel("normalised lateral displacement (-)")
        ax.set_title(f"{plane} plane")
        ax.legend(fontsize=8, loc="lower left")
    axes[0].set_ylabel("height above still water level (m)")
    fig.suptitle("Mode shapes of the OC3 Hywind surrogate, parked (keel at -120 m, tower top at 87.6 m)")
    fig.tight_layout()
    shapes_path = out / "02_mode_shapes.png"
    fig.savefig(shapes_path, dpi=110)
    plt.close(fig)

    # figure 2: frequency response of the tower-base bending moment at the operating point
    f = np.geomspace(0.003, 4.0, 300 if quick else 1500)
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for ax, inp, unit in ((axes[0], "wave_Fx", "kN·m/N"), (axes[1], "wind_dev", "kN·m/(m/s)")):
        ax.loglog(f, frequency_response(ss, f, inp, "TwHt1MLyt"), color="tab:blue", lw=1.2,
                  label=f"|H| {inp} -> TwHt1MLyt")
        for lab in ("surge", "pitch", "tower_fa_1", "tower_fa_2"):
            ax.axvline(operating.frequency(lab), color="0.5", ls="--", lw=0.8)
            ax.text(operating.frequency(lab), 0.98, f" {lab}", rotation=90, va="top", fontsize=7,
                    transform=ax.get_xaxis_transform())
        ax.axvspan(0.7 / case.tp, 1.6 / case.tp, color="tab:cyan", alpha=0.2, label=f"wave band of {case.name}")
        ax.axvline(3 * case.rotor_rpm / 60, color="tab:red", ls=":", lw=1.0, label="3P")
        ax.set_ylabel(f"|H| ({unit})")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, loc="lower left")
    axes[0].set_title(f"Tower-base fore-aft bending moment per unit load, linearised at {case.name}")
    axes[1].set_xlabel("frequency (Hz)")
    fig.tight_layout()
    frf_path = out / "02_frequency_response.png"
    fig.savefig(frf_path, dpi=110)
    plt.close(fig)
    print(f"wrote {shapes_path} and {frf_path}")
    return {
        "frequencies_hz": dict(zip(parked.labels, map(float, parked.frequencies_hz), strict=True)),
        "damping_ratios": dict(zip(parked.labels, map(float, parked.damping_ratios), strict=True)),
        "operating_frequencies_hz": dict(zip(operating.labels, map(float, operating.frequencies_hz), strict=True)),
        "operating_damping_ratios": dict(zip(operating.labels, map(float, operating.damping_ratios), strict=True)),
        "operating_no_aero_damping_ratios": {lab: zeta(operating_no_aero, lab) for lab in operating.labels},
        "below_rated_damping_ratios": {lab: zeta(below_rated, lab) for lab in below_rated.labels},
        "below_rated_no_aero_damping_ratios": {lab: zeta(below_rated_no_aero, lab) for lab in below_rated.labels},
        "below_rated_wind_speed": float(below.wind_speed),
        "reference_hz": dict(OC3_REFERENCE_HZ),
        "figures": [shapes_path, frf_path],
    }


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="coarser frequency grid")
    ap.add_argument("--out", default=".", help="folder for the figures")
    a = ap.parse_args()
    main(quick=a.quick, out=a.out)
