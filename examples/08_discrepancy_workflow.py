"""Lesson 8 -- the discrepancy workflow: what is my model missing?

The physics (and the method). Every model leaves something out. When a measurement disagrees with the model, the
useful question is not "how large is the error" but "which piece of physics explains it". The surrogate's named
effects (lesson 3) and its named parameters (``surrogates.parameters``: tower stiffness, platform mass and inertia,
added mass, drag, each mooring line, structural damping) give a vocabulary for the answer, and
``fowt_env.discrepancy.run`` uses it in three steps:

1. **Where** -- simulate the candidate model under the measured load case with several seeds and reduce the
   measurement and every simulation to *features*: log band powers of tower and platform channels (platform
   modes, waves, 1P, 1st tower mode, 3P, 2nd tower mode), the centroid frequency of the modal bands, mean offsets,
   skewness and kurtosis. Each disagreement is a z-score against the model's own seed-to-seed scatter: |z| = 3 is
   a real difference, |z| = 1 is what another storm with the same statistics would give. The gap is mean(z²)
   over the features.
2. **Is it real?** -- each of the model's own seeds is scored against the others the same way: these "null"
   gaps show how large a gap a correct model leaves. Their 99th percentile is the significance level: below it,
   the answer is "no significant discrepancy".
3. **Name** -- every candidate is screened with one probe simulation, the most promising are profiled over their
   strength, and one is named only if it brings the gap down to the level of the *updated* model's own null --
   with an **interval** (every strength the test accepts), a warning if the fit sits at the edge of its range,
   and the other candidates that explain the record equally well. If none does, the answer is "unexplained" and
   the findings are listed; the least-bad candidate is never named.
   ``report.updated_model`` is the candidate with the named effect at its fitted strength.

What this script does. The "real turbine" is the full surrogate; its measured record is a noisy OLC 7 record.
The candidate model is the same surrogate with one effect hidden (``--hide``, default ``mooring_nonlinear``,
the catenary mooring's hardening and set-down). The workflow gets the measurement, the candidate and the load
case -- nothing else -- and must name what is missing.

What to look for.

* The findings point at the physics: with the catenary hidden, the platform's mean heave is off by 22 sigma and
  the mean sway by 7 (the catenary pulls the platform down and sideways as it drifts), while spectra barely differ.
* The named effect is the hidden one, near 1, with its interval (``--quick``): ``mooring_nonlinear`` at 0.96 (0.36
  to 1.43), the gap from 6.6 to 0.76 against a level of 1.15 (significant above 2.42).
* In the candidate panel the right effect stands out; the others barely move the gap.
* Try ``--hide aero_damping``: the effect also carries the rotor's aerodynamic damping of the tower, so hiding it
  leaves a strong signature -- far less power in the 2nd tower band of the tower-base moment and tower-top
  acceleration than the candidate has (z about -25) and shifted tower-mode centroid frequencies (z -18 to +18).
  ``--quick`` names it at 0.99 (0.72 to 1.32; gap 41.8 -> 0.79). Or ``--hide quadratic_drag``: at this wind speed
  aerodynamic damping dominates the platform's damping, drag is not detectable from these channels, and "no significant
  discrepancy" is the honest answer -- a limit of the data, not of the method.

The measured record is twenty minutes long (at ten, the catenary's signature sits near the significance level on
some seeds). ``--quick`` tests three candidate effects on a coarser strength grid
instead of all 21 candidates (``discrepancy.CANDIDATES``: eleven effects, ten parameters) on the default grid.
Writes ``08_discrepancy.png`` (gaps, features, candidates) and ``08_discrepancy_report.png`` (``report.plot``:
spectra of measurement, candidate and updated model). This is the last lesson; ``fowt-env discrepancy FILE --case
N`` runs the same workflow on a record of your own.

Usage: python examples/08_discrepancy_workflow.py [--hide mooring_nonlinear] [--quick] [--out DIR]
"""

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import surrogates
from fowt_env import discrepancy

CASE = 7
QUICK_DECOYS = ("quadratic_drag", "rotor_3p", "p_delta")  # effects tested besides the hidden one in quick mode


def main(quick: bool = False, out: str = ".", hide: str = "mooring_nonlinear") -> dict:
    if hide not in surrogates.EFFECTS:
        raise ValueError(f"hide must be one of {sorted(surrogates.EFFECTS)}, got {hide!r}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    duration = 1200.0  # twenty minutes: the record length on which the workflow is verified (hidden-truth tests)
    real_turbine = surrogates.FOWTModel()  # every effect at nominal strength
    measured = surrogates.simulate(real_turbine, CASE, duration=duration, dt=0.0125, seed=0)  # noisy, as measured
    candidate = real_turbine.without(hide)
    if quick:
        candidates = [hide] + [e for e in QUICK_DECOYS if e != hide][:2]
        report = discrepancy.run(measured, candidate, CASE, candidates=candidates, max_effects=1,
                                 strengths=(0.5, 1.0, 2.0))
    else:
        candidates = list(discrepancy.CANDIDATES)
        report = discrepancy.run(measured, candidate, CASE)
    print(f"measured: {duration:.0f} s of {surrogates.load_case(CASE).name} from the full model; "
          f"candidate model: {candidate!r} ({hide} hidden)")
    print(report.summary())

    # the gap each candidate effect reaches at its best strength, in the first round of the search
    first_round = [c for c in report.candidates if c["round"] == 1 and c["gap"] is not None]  # not the diverged
    threshold = report.detect_gap  # the significance level: 99th percentile of the model's null gaps

    fig, axes = plt.subplots(1, 3, figsize=(15, 5.5), gridspec_kw={"width_ratios": [0.8, 1.6, 1.2]})
    ax = axes[0]
    named = ", ".join(f"{n} x{s:.2f}" for n, s in report.effects) or "nothing"
    ax.bar([0, 1], [report.gap_before, report.gap_after], color=["tab:blue", "tab:red"])
    ax.set_ylim(0.0, 1.3 * max(report.gap_before, threshold))
    ax.axhline(report.null_gap, color="0.3", ls=":", label=f"null level {report.null_gap:.2f} (model vs itself)")
    ax.axhline(threshold, color="tab:orange", ls="--", label=f"significance level {threshold:.1f} (99th pct of null)")
    ax.set_xticks([0, 1])
    ax.set_xticklabels(["candidate", "updated"])
    ax.set_ylabel("gap: mean z² over features (-)")
    ax.set_title("The gap before and after")
    ax.legend(fontsize=7)
    ax = axes[1]
    order = np.argsort(-np.abs(report.z_before))[:15][::-1]
    y = np.arange(order.size)
    z_floor = 0.05  # |z| below this is drawn at the floor of the log axis
    ax.barh(y + 0.2, np.maximum(np.abs(report.z_before[order]), z_floor), 0.4, color="tab:blue", label="candidate")
    ax.barh(y - 0.2, np.maximum(np.abs(report.z_after[order]), z_floor), 0.4, color="tab:red", label="updated")
    ax.axvline(3.0, color="0.3", ls=":", label="|z| = 3")
    ax.set_yticks(y)
    ax.set_yticklabels([report.feature_names[i] for i in order], fontsize=7)
    ax.set_xscale("log")
    ax.set_xlim(z_floor, 2.0 * max(np.abs(report.z_before).max(), 4.0))
    ax.set_xlabel("|z| (measurement - model mean, in units of the model's seed scatter)")
    ax.set_title("The 15 largest disagreements (feature = channel:band or statistic)")
    ax.legend(fontsize=7, loc="lower right")
    ax = axes[2]
    names = [c["effect"] for c in first_round]
    ax.barh(np.arange(len(names)), [c["gap"] for c in first_round],
            color=["tab:red" if c["accepted"] else "0.6" for c in first_round])
    ax.axvline(report.gap_before, color="tab:blue", ls="--", label="gap of the candidate")
    ax.axvline(report.null_gap, color="0.3", ls=":", label="null level")
    ax.set_yticks(np.arange(len(names)))
    ax.set_yticklabels([f"{c['effect']} (x{c['strength']:.2f})" for c in first_round], fontsize=8)
    if not first_round:
        ax.text(0.5, 0.5, "no search: the candidate's gap\nis below the significance threshold",
                transform=ax.transAxes, ha="center", va="center", fontsize=9)
    ax.set_xlabel("gap with the candidate at its best strength (-)")
    ax.set_title("Which effect or parameter closes the gap? (red: named)")
    ax.legend(fontsize=7)
    fig.suptitle(f"Discrepancy workflow, {report.case.name}: {hide} hidden from the model; named: {named}")
    fig.tight_layout()
    path = out / "08_discrepancy.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    report_path = report.plot(out / "08_discrepancy_report.png")
    print(f"wrote {path} and {report_path}")
    return {"hidden": hide, "candidates": candidates, "named": list(report.effects), "effect": report.effect,
            "strength": report.strength, "gap_before": report.gap_before, "gap_after": report.gap_after,
            "null_gap": report.null_gap, "report": report, "figures": [path, report_path]}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hide", default="mooring_nonlinear", choices=sorted(surrogates.EFFECTS),
                    help="the effect the candidate model lacks")
    ap.add_argument("--quick", action="store_true", help="three candidate effects, coarser strength grid")
    ap.add_argument("--out", default=".", help="folder for the figures")
    a = ap.parse_args()
    main(quick=a.quick, out=a.out, hide=a.hide)
