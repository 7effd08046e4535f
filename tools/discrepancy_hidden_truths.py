"""Run the discrepancy workflow's hidden-truth tests and print the README's table from their answers.

The slow tests of ``tests/test_discrepancy.py`` (every parameter hidden at two strengths, twenty null records)
assert; with ``FOWT_HIDDEN_TRUTH_LOG`` set they also write each answer (verdict, named candidate with its value
and 99 % interval, equally consistent alternatives, gaps) as a JSON line. This script runs them with that
variable set and turns the log into the table, so the README's figures are the tests' own runs.

Usage::

    python tools/discrepancy_hidden_truths.py [-k EXPR] [--log FILE]    # runs pytest, then prints the table
    python tools/discrepancy_hidden_truths.py --log FILE --no-run        # only formats an existing log

About 25 minutes of CPU for the parameter matrix and 3 for the twenty null records.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_K = "hidden_parameter or nothing_hidden"


def _answer(r: dict) -> str:
    if r["verdict"] != "explained":
        return f"**{r['verdict']}**"
    parts = []
    for f in r["fits"]:
        lo, hi = f["interval"]
        lo_s = f"<={lo:.2f}" if f["interval_at_bound"][0] else f"{lo:.2f}"
        hi_s = f">={hi:.2f}" if f["interval_at_bound"][1] else f"{hi:.2f}"
        if f.get("excludes_start") is not None:  # the interval ends at the rejected starting value
            lo_s, hi_s = (f"{lo:.2f} excl.", hi_s) if lo == f["excludes_start"] else (lo_s, f"{hi:.2f} excl.")
        parts.append(f"`{f['name']}` {f['value']:.2f} ({lo_s}-{hi_s})")
    for a in r["alternatives"]:
        lo, hi = a["interval"]
        at = a.get("interval_at_bound", (False, False))
        lo_s = f"<={lo:.2f}" if at[0] else f"{lo:.2f}"
        hi_s = f">={hi:.2f}" if at[1] else f"{hi:.2f}"
        parts.append(f"or equally `{a['name']}` {a['value']:.2f} ({lo_s}-{hi_s})")
    return "; ".join(parts)


def table(rows: list[dict]) -> str:
    """Markdown table of the parameter rows and a line on the null rows."""
    out = ["| truth in the 20-minute record | load case, seed | answer: value (99 % interval) | gap before -> "
           "after (level) |", "|---|---|---|---|"]
    params = [r for r in rows if r["kind"] == "parameter"]
    order = list(dict.fromkeys(r["name"] for r in params))
    for r in sorted(params, key=lambda r: order.index(r["name"])):
        out.append(f"| `{r['name']}` x{r['truth']:.2f} | {r['case']}, {r['seed']} | {_answer(r)} | "
                   f"{r['gap_before']:.1f} -> {r['gap_after']:.1f} ({r['accept']:.1f}) |")
    nulls = [r for r in rows if r["kind"] == "null"]
    if nulls:
        named = sum(bool(r["fits"]) for r in nulls)
        none = sum(r["verdict"] == "none" for r in nulls)
        worst = max(nulls, key=lambda r: r["gap_before"] / r["detect"])
        out.append(f"\nNull records: verdict none in {none} of {len(nulls)}, something named in {named}; gaps "
                   f"{min(r['gap_before'] for r in nulls):.2f}-{max(r['gap_before'] for r in nulls):.2f} against "
                   f"levels {min(r['detect'] for r in nulls):.2f}-{max(r['detect'] for r in nulls):.2f} (closest: "
                   f"{worst['case']} seed {worst['seed']}, {worst['gap_before']:.2f} against {worst['detect']:.2f})")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-k", default=DEFAULT_K, help=f"pytest -k expression (default {DEFAULT_K!r})")
    ap.add_argument("--log", type=Path, default=Path("hidden_truths.jsonl"), help="JSON-lines log (appended)")
    ap.add_argument("--no-run", action="store_true", help="only format an existing log")
    a = ap.parse_args(argv)
    rc = 0
    if not a.no_run:
        env = {**os.environ, "FOWT_HIDDEN_TRUTH_LOG": str(a.log.resolve())}
        rc = subprocess.call([sys.executable, "-m", "pytest", "-q", "-m", "slow", "-k", a.k, "-p", "no:cacheprovider",
                              str(ROOT / "tests" / "test_discrepancy.py")], env=env, cwd=ROOT)
    rows = [json.loads(line) for line in a.log.read_text(encoding="utf-8").splitlines() if line.strip()]
    print(table(rows))
    return rc


if __name__ == "__main__":
    raise SystemExit(main())
