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
FIGURE_RUN = "c_op12_Hs2p5_Tp10"


def block(report, seeds: int) -> str:
    cmd = "fowt-env validate" + ("" if seeds == 8 else f" --seeds {seeds}")
    n_g, n_f = len(report.graded), len(report.failures)
    head = f"`{cmd}`: {n_g - n_f} of {n_g} graded checks pass ({len(report.runs)} runs, {seeds} surrogate seeds)."
    notes = [f"- {s['run']} skipped: {s['reason']}" for s in report.skipped]
    notes += [f"- {n}" for n in dict.fromkeys(report.notes)]
    return "\n".join([BEGIN, head, "", report.as_table(), "", *notes, END])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=8, help="surrogate seeds per operating run (default 8)")
    ap.add_argument("--readme", type=Path, default=REPO / "README.md", help="file with the marked block")
    ap.add_argument("--figure", type=Path, default=REPO / "docs" / "figures" / "fidelity_psd_c_op12.png",
                    help="where the 12 m/s PSD overlay is written")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        rep = validate(seeds=args.seeds, plot_dir=tmp)
        shutil.copyfile(Path(tmp) / f"{FIGURE_RUN}.png", args.figure)
    text = args.readme.read_text(encoding="utf-8")
    if text.count(BEGIN) != 1 or text.count(END) != 1:
        raise SystemExit(f"{args.readme}: expected one {BEGIN} ... {END} block")
    pre, rest = text.split(BEGIN)
    _, post = rest.split(END)
    args.readme.write_text(pre + block(rep, args.seeds) + post, encoding="utf-8")
    print(f"updated {args.readme} and {args.figure} ({rep.elapsed_s:.0f} s validation)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
