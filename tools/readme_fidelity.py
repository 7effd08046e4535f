"""Regenerate the README's "Fidelity against OpenFAST" table and figure from ``fowt-env validate``.

Runs :func:`fowt_env.validation.validate` on the packaged OpenFAST reference data (8 seeds, the defaults of
``fowt-env validate``), writes its tables between the ``<!-- fidelity:begin -->`` and ``<!-- fidelity:end -->``
markers of README.md (nothing else in the file changes) and saves the 12 m/s PSD overlay as
``docs/figures/fidelity_psd_c_op12.png``.

Usage::

    python tools/readme_fidelity.py [--seeds 8] [--readme README.md] [--figure docs/figures/fidelity_psd_c_op12.png]

``--seeds`` is the surrogate seeds per operating run, ``--readme`` the file whose marked block is rewritten and
``--figure`` where the 12 m/s PSD overlay is saved. Every run validates, rewrites
the block and overwrites the figure.

``python tools/readme_fidelity.py --heldout`` instead validates the packaged held-out runs (``fowt-env validate
heldout``: new seeds and wind speeds, ``tools/openfast_heldout_runs.py``) and rewrites the summary between
``<!-- heldout:begin -->`` and ``<!-- heldout:end -->``: per run the graded checks passed, the operating means'
ratios and the failing checks.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

from fowt_env.validation import validate

REPO = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- fidelity:begin -->", "<!-- fidelity:end -->"
HELDOUT_BEGIN, HELDOUT_END = "<!-- heldout:begin -->", "<!-- heldout:end -->"
MEANS = ("RotSpeed", "BldPitch1", "GenPwr", "RotThrust", "PtfmSurge", "PtfmPitch", "TwrBsMyt")
FIGURE_RUN = "c_op12_Hs2p5_Tp10"


def block(report, seeds: int) -> str:
    cmd = "fowt-env validate" + ("" if seeds == 8 else f" --seeds {seeds}")
    n_g, n_f = len(report.graded), len(report.failures)
    head = f"`{cmd}`: {n_g - n_f} of {n_g} graded checks pass ({len(report.runs)} runs, {seeds} surrogate seeds)."
    notes = [f"- {s['run']} skipped: {s['reason']}" for s in report.skipped]
    notes += [f"- {n}" for n in dict.fromkeys(report.notes)]
    return "\n".join([BEGIN, head, "", report.as_table(), "", *notes, END])


def heldout_block(report, seeds: int) -> str:
    """Per held-out run: graded checks passed, the graded means (surrogate / OpenFAST) and the failures."""
    cmd = "fowt-env validate heldout" + ("" if seeds == 8 else f" --seeds {seeds}")
    n_g, n_f = len(report.graded), len(report.failures)
    lines = [HELDOUT_BEGIN, f"`{cmd}`: {n_g - n_f} of {n_g} graded checks pass ({len(report.runs)} runs, "
             f"{seeds} surrogate seeds).", "",
             "| run | graded checks passed | means, surrogate / OpenFAST: " + ", ".join(MEANS) + " | failing |",
             "|---|---|---|---|"]
    for info in report.runs:
        run = info["name"]
        graded = [c for c in report.graded if c.run == run]
        if not graded:
            continue
        means = []
        for ch in MEANS:
            c = report.get(run, ch, "mean")
            if c is None or c.passed is None:
                means.append("-")
            elif abs(c.openfast) < 0.5:  # fine pitch: the ratio of two near-zero angles says nothing
                means.append(f"{c.surrogate:.2f} vs {c.openfast:.2f} {'✓' if c.passed else '✗'}")
            else:
                means.append(f"{c.surrogate / c.openfast:.3f} {'✓' if c.passed else '✗'}")
        fails = [f"{c.channel} {c.statistic} {c.ratio:.2f}" for c in graded if c.passed is False]
        lines.append(f"| {run} | {sum(bool(c.passed) for c in graded)} of {len(graded)} | {', '.join(means)} | "
                     f"{'; '.join(fails) or '-'} |")
    return "\n".join([*lines, HELDOUT_END])


def _rewrite(path: Path, begin: str, end: str, new_block: str) -> None:
    text = path.read_text(encoding="utf-8")
    if text.count(begin) != 1 or text.count(end) != 1:
        raise SystemExit(f"{path}: expected one {begin} ... {end} block")
    pre, rest = text.split(begin)
    _, post = rest.split(end)
    path.write_text(pre + new_block + post, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=8, help="surrogate seeds per operating run (default 8)")
    ap.add_argument("--readme", type=Path, default=REPO / "README.md", help="file with the marked block")
    ap.add_argument("--figure", type=Path, default=REPO / "docs" / "figures" / "fidelity_psd_c_op12.png",
                    help="where the 12 m/s PSD overlay is written")
    ap.add_argument("--heldout", action="store_true", help="the held-out runs' summary block instead")
    args = ap.parse_args(argv)
    if args.heldout:
        rep = validate("heldout", seeds=args.seeds)
        _rewrite(args.readme, HELDOUT_BEGIN, HELDOUT_END, heldout_block(rep, args.seeds))
        print(f"updated {args.readme} ({rep.elapsed_s:.0f} s validation)")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        rep = validate(seeds=args.seeds, plot_dir=tmp)
        shutil.copyfile(Path(tmp) / f"{FIGURE_RUN}.png", args.figure)
    _rewrite(args.readme, BEGIN, END, block(rep, args.seeds))
    print(f"updated {args.readme} and {args.figure} ({rep.elapsed_s:.0f} s validation)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
