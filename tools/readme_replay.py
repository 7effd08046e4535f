"""Regenerate the README's replay-against-OpenFAST table and overlay figure from ``benchmarks/replay.py``.

Replays every shared OpenFAST operating run (``../shared/reference/openfast/runs``; the turbulent runs with the
polar rotor field of their inflow file, the steady run with ``Wind1VelX``), writes the R² table with its linear
bounds between the ``<!-- replay:begin -->`` and ``<!-- replay:end -->`` markers of README.md (nothing else in the
file changes) and saves the 12 m/s overlay as ``docs/figures/replay_openfast_12mps.png``.

Usage::

    python tools/readme_replay.py [--reference DIR] [--readme README.md] [--figure PNG]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from replay import DEFAULT_REFERENCE, plot_overlay, replay_run  # noqa: E402

BEGIN, END = "<!-- replay:begin -->", "<!-- replay:end -->"
CHANNELS = ("PtfmSurge", "PtfmHeave", "PtfmPitch", "TwrBsMyt", "TwHt9ALxt", "RotSpeed", "BldPitch1", "PtfmRoll",
            "PtfmYaw")
LABEL = {"c_op08": "8 m/s", "c_op12": "12 m/s", "c_op18": "18 m/s", "d_steady12": "steady 12 m/s"}
FIGURE_RUN = "c_op12_Hs2p5_Tp10"


def _label(run: str) -> str:
    return next((v for k, v in LABEL.items() if run.startswith(k)), run)


def table(results: list[dict]) -> str:
    rows = ["| run | channel | R² wave 0.05-0.25 Hz | bound | R² 0-1 Hz | bound |", "|---|---|---|---|---|---|"]
    for res in results:
        by = {(s.channel, s.band): s for s in res["scores"]}
        for ch in CHANNELS:
            cells = []
            for band in ("wave", "0-1 Hz"):
                s = by.get((ch, band))
                if s is None or not (s.bound == s.bound):  # missing or NaN: a constant channel
                    cells += ["—", "—"]
                    continue
                mark = " ✗" if s.r2 < 0.85 * s.bound else ""
                cells += [f"{s.r2:.2f}{mark}", f"{s.bound:.2f}"]
            if cells[0] == "—" and cells[2] == "—":
                continue
            rows.append(f"| {_label(res['run'])} | {ch} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reference", type=Path, default=DEFAULT_REFERENCE)
    ap.add_argument("--readme", type=Path, default=REPO / "README.md")
    ap.add_argument("--figure", type=Path, default=REPO / "docs" / "figures" / "replay_openfast_12mps.png")
    a = ap.parse_args(argv)
    if not a.reference.is_dir():
        print(f"no OpenFAST reference runs at {a.reference}", file=sys.stderr)
        return 1
    folders = sorted(p for p in a.reference.iterdir() if p.is_dir() and p.name.startswith(("c_op", "d_steady"))
                     and (p / f"{p.name}.outb").is_file())
    results = [replay_run(f, "field", 100.0, 0.025) for f in folders]
    text = a.readme.read_text(encoding="utf-8")
    i, j = text.find(BEGIN), text.find(END)
    if i < 0 or j < i:
        print(f"{a.readme}: no {BEGIN} ... {END} block", file=sys.stderr)
        return 1
    a.readme.write_text(text[:i] + BEGIN + "\n" + table(results) + "\n" + text[j:], encoding="utf-8")
    fig = next((r for r in results if r["run"] == FIGURE_RUN), None)
    if fig is not None:
        plot_overlay(fig, a.figure)
    print(f"updated {a.readme} and {a.figure}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
