"""Regenerate the README's time-domain block (``fowt-env validate time-domain``) and its figure.

Replays the packaged OpenFAST runs that keep their start (:mod:`fowt_env.time_domain`) with the default surrogate and
with each named effect switched off in turn, writes the tables between ``<!-- timedomain:begin -->`` and
``<!-- timedomain:end -->`` of README.md (nothing else changes) and saves the steady-wind run's overlay as
``docs/figures/time_domain_steady12.png``.

Usage::

    python tools/readme_time_domain.py [--readme README.md] [--figure docs/figures/time_domain_steady12.png]

About 20 s.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

import surrogates
from fowt_env.time_domain import plot_time_domain, time_domain

REPO = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- timedomain:begin -->", "<!-- timedomain:end -->"
COLUMNS = ("PtfmSurge", "PtfmHeave", "PtfmPitch", "PtfmRoll", "PtfmYaw", "RotSpeed", "BldPitch1", "GenPwr", "RotThrust",
           "TwrBsMyt", "TwrBsMxt", "TwHt9ALxt", "TwHt9ALyt")
ABLATION = ("quadratic_drag", "mooring_nonlinear", "rotor_nonlinear", "blade_deflection", "cm_kinematics",
            "sampled_wind_curvature", "hydro_fixed_axes", "gyroscopic", "rotor_skew", "rotor_asymmetry")
ABLATION_COLUMNS = ("PtfmSurge", "PtfmHeave", "PtfmPitch", "PtfmYaw", "RotSpeed", "BldPitch1", "GenPwr", "TwrBsMyt")
STEADY = "t_steady12_Hs2p5_Tp10_from0"


def _model(**off: float):
    m = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS).with_effects(rotor_1p=0.0)
    return m.with_effects(**off) if off else m


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--readme", type=Path, default=REPO / "README.md")
    ap.add_argument("--figure", type=Path, default=REPO / "docs" / "figures" / "time_domain_steady12.png")
    args = ap.parse_args(argv)

    scores, records = time_domain(model=_model(), return_records=True)
    runs = list(dict.fromkeys(s.run for s in scores))
    by = {(s.run, s.channel): s for s in scores}
    cols = [c for c in COLUMNS if any((r, c) in by for r in runs)]
    lines = [BEGIN, "`fowt-env validate time-domain`: R² of the surrogate's series against OpenFAST's over 20-400 s "
                    "(std ratio in brackets); `-`: a channel the run holds still.", "",
             "| run | " + " | ".join(cols) + " |", "|---|" + "---|" * len(cols)]
    for r in runs:
        cells = [f"{by[(r, c)].r2:.2f} ({by[(r, c)].std_ratio:.2f})" if (r, c) in by else "-" for c in cols]
        lines.append(f"| {r} | " + " | ".join(cells) + " |")
    lines += ["", f"Each named effect switched off in turn, run `{STEADY}` (R²):", "",
              "| effect off | " + " | ".join(ABLATION_COLUMNS) + " |", "|---|" + "---|" * len(ABLATION_COLUMNS)]
    lines.append("| (none) | " + " | ".join(f"{by[(STEADY, c)].r2:.2f}" for c in ABLATION_COLUMNS) + " |")
    for effect in ABLATION:
        off = {s.channel: s for s in time_domain(model=_model(**{effect: 0.0}), runs=[STEADY])}
        lines.append(f"| `{effect}` | " + " | ".join(f"{off[c].r2:.2f}" for c in ABLATION_COLUMNS) + " |")
        print(f"{effect}: done", flush=True)
    lines.append(END)

    text = args.readme.read_text(encoding="utf-8")
    if text.count(BEGIN) != 1 or text.count(END) != 1:
        raise SystemExit(f"{args.readme}: expected one {BEGIN} ... {END} block")
    pre, rest = text.split(BEGIN)
    _, post = rest.split(END)
    args.readme.write_text(pre + "\n".join(lines) + post, encoding="utf-8")
    with tempfile.TemporaryDirectory() as tmp:
        paths = plot_time_domain({STEADY: records[STEADY]}, tmp)
        args.figure.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(paths[0], args.figure)
    print(f"updated {args.readme} and {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
