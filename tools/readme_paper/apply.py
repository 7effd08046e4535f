#!/usr/bin/env python3
"""Rewrite the README's paper-reproduction tables from a rerun.sh OUTDIR, and list the prose numbers to update.

    python apply.py OUTDIR README_IN README_OUT [--report FILE]

Tables rewritten in README_OUT (rows matched by their first cells; cells formatted as the README formats them;
rows whose outputs are missing are left as they are and listed):

* Identification: the tower-mode table (linearisation / SSI-COV / Hankel-DMD, seeds 1 / 2).
* Virtual sensing: Table 2 (``compare/table2.json``) and "the seed paper's Table 7, reproduced" (look-ahead column
  from ``compare/lookahead.json``, causal DMD and Kalman columns from ``table2.json``; the paper's column is kept).
* OpenFAST: the aggregate Table 7 rows present in ``openfast/table7.md`` (the Kalman rows, or all of them after
  ``--openfast-full``), the per-sensor 12 m/s cells of the sensors present in ``openfast/fold_c_op12_*.json``,
  and the model-error table (``model_error/model_error.md``).

The "before -> after the fix" table of the OpenFAST section is historical (measured at the Kalman fix, never
rerun since) and is not rewritten; its current "after" values are printed.

Prose: every number in those sections that derives from the outputs is printed with its old value (read from
README_IN), the value computed from OUTDIR the way the README states it, and the sentence it is in. Prose is not
changed: edit it by hand from this list. Numbers the outputs cannot give are listed as such.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Any

# ------------------------------------------------------------------------------------------- formatting


def f(v: float | None, spec: str) -> str:
    return "-" if v is None else format(v, spec)


def rng(values: list[float], spec: str, sep: str = "-") -> str:
    """'lo-hi' of the formatted extremes ('x' when they format alike)."""
    vals = [v for v in values if v is not None]
    if not vals:
        return "n/a"
    lo, hi = format(min(vals), spec), format(max(vals), spec)
    return lo if lo == hi else f"{lo}{sep}{hi}"


def sci(v: float, sign: bool = True) -> str:
    """README style of small differences: +8.6e-6 (no zero padding in the exponent)."""
    s = format(v, "+.1e" if sign else ".1e")
    mant, exp = s.split("e")
    return f"{mant}e{int(exp)}"


def lowhigh(rel: float | None) -> str:
    """A relative frequency error as the README words it: '7 % low' / '5 % high'."""
    if rel is None:
        return "-"
    return f"{abs(100 * rel):.0f} % {'low' if rel < 0 else 'high'}"


def readme_misses(misses: list[tuple[str, str, float]]) -> str:
    """'0.897 on `TwHt3MLyt` and 0.871 on `TwHt4MLyt` in A, 0.990 on `TwHt1ALxt` in C, ... under random dropouts'."""
    parts = []
    for sc in dict.fromkeys(m[0] for m in misses):
        items = [f"{c:.3f} on `{n}`" for s, n, c in misses if s == sc]
        where = "under random dropouts" if sc == "random" else f"in {sc}"
        parts.append((", ".join(items[:-1]) + " and " + items[-1] if len(items) > 1 else items[0]) + " " + where)
    return ", ".join(parts) if parts else "none"


def tool_fmt(v: float | None, spec: str = ".3f") -> str:
    """tools/openfast_table7.py's _fmt."""
    if v is None:
        return "-"
    return format(v, ".1e") if abs(v) >= 1e3 else format(v, spec)


def split_row(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def join_row(cells: list[str]) -> str:
    return "| " + " | ".join(cells) + " |"


# ------------------------------------------------------------------------------------------- README model


class Readme:
    SECTIONS = {  # name: (first line starting with, first line of the next part)
        "Identification": ("## Identification: Hankel-DMD and SSI-COV", "## Virtual sensing"),
        "Virtual sensing": ("## Virtual sensing", "### On data this project did not make"),
        "OpenFAST / model error": ("### On data this project did not make", "## What is my model missing?"),
    }

    def __init__(self, text: str):
        self.lines = text.split("\n")
        self.bounds: dict[str, tuple[int, int]] = {}
        for name, (start, end) in self.SECTIONS.items():
            i = next((k for k, ln in enumerate(self.lines) if ln.startswith(start)), None)
            j = next((k for k, ln in enumerate(self.lines) if i is not None and k > i and ln.startswith(end)), None)
            if i is None or j is None:
                raise SystemExit(f"apply.py: README section {name!r} not found ({start!r} ... {end!r})")
            self.bounds[name] = (i, j)

    def table(self, section: str, header_start: str) -> tuple[int, int] | None:
        """(first data row, end) line indices of the table whose header line starts with header_start."""
        i0, i1 = self.bounds[section]
        for k in range(i0, i1):
            if self.lines[k].startswith(header_start):
                first = k + 2  # header, separator
                end = first
                while end < len(self.lines) and self.lines[end].lstrip().startswith("|"):
                    end += 1
                return first, end
        return None

    def paragraphs(self, section: str) -> list[str]:
        i0, i1 = self.bounds[section]
        paras, cur = [], []
        for ln in self.lines[i0:i1]:
            starts_block = re.match(r"\s*(\* |- |\d+\. |\||```)", ln) is not None
            if ln.strip() and not (starts_block and cur):
                cur.append(ln.strip())
            elif ln.strip():  # a bullet, list item, table row or fence starts a new paragraph
                paras.append(" ".join(cur))
                cur = [ln.strip()]
            elif cur:
                paras.append(" ".join(cur))
                cur = []
        if cur:
            paras.append(" ".join(cur))
        return paras

    def text(self) -> str:
        return "\n".join(self.lines)


class Changes:
    def __init__(self) -> None:
        self.rows: list[tuple[str, str, str]] = []  # (table, old, new)
        self.notes: list[str] = []

    def note(self, msg: str) -> None:
        self.notes.append(msg)


def rewrite_table(rd: Readme, ch: Changes, section: str, header: str, name: str, key_cells: int, make: Any) -> None:
    """For each data row: key = its first key_cells cells; make(key, cells) -> new cells or None (keep)."""
    span = rd.table(section, header)
    if span is None:
        ch.note(f"{name}: table not found in the README (header {header!r})")
        return
    for k in range(*span):
        old = rd.lines[k]
        cells = split_row(old)
        try:
            new_cells = make(tuple(cells[:key_cells]), list(cells))
        except (KeyError, IndexError, ValueError, TypeError, AttributeError) as exc:
            ch.note(
                f"{name}: row {' | '.join(cells[:key_cells])!r}: no output for it ({type(exc).__name__} {exc}); kept"
            )
            continue
        if new_cells is None:
            continue
        if len(new_cells) != len(cells):
            ch.note(f"{name}: row {cells[:key_cells]} would change its number of cells; kept")
            continue
        new = join_row(new_cells)
        if new != old:
            rd.lines[k] = new
        ch.rows.append((name, old, new))


# ------------------------------------------------------------------------------------------- outputs


def load(path: Path) -> Any:
    return json.loads(path.read_text()) if path.is_file() else None


class Compare:
    """A fowt-env compare --json result."""

    def __init__(self, data: dict[str, Any], name: str):
        self.d, self.name = data, name

    def runs(self, sc: str, est: str, interval: Any = "any") -> list[dict[str, Any]]:
        return [
            r
            for r in self.d["runs"]
            if r["scenario"] == sc and r["estimator"] == est and (interval == "any" or r["update_interval"] == interval)
        ]

    def row(self, sc: str, est: str, interval: Any = "any") -> dict[str, Any]:
        rows = [
            r
            for r in self.d["table"]
            if r["scenario"] == sc and r["estimator"] == est and (interval == "any" or r["update_interval"] == interval)
        ]
        if len(rows) != 1:
            raise KeyError(f"{self.name}: {len(rows)} table rows for {sc}/{est}/{interval}")
        return rows[0]

    def channels(self, sc: str, est: str, interval: Any = "any") -> list[dict[str, Any]]:
        return [c for r in self.runs(sc, est, interval) for c in r["channels"]]

    def channel(self, sc: str, est: str, name: str, interval: Any = "any") -> dict[str, Any]:
        hits = [c for c in self.channels(sc, est, interval) if c["channel"] == name]
        if not hits:
            raise KeyError(f"{self.name}: no {sc}/{est}/{name}")
        return hits[0]

    def scenarios(self) -> list[str]:
        return list(dict.fromkeys(r["scenario"] for r in self.d["runs"]))

    def covs(self, sc: str, est: str) -> list[tuple[str, float]]:
        return [(c["channel"], c["coverage95"]) for c in self.channels(sc, est) if c.get("coverage95") is not None]


SCEN = {"A": "A", "B": "B", "C": "C", "random": "random"}
T2_SENSORS = {
    "hold last value": ("hold", None),
    "Hankel-DMD (causal, 1 s)": ("dmd", 1.0),
    "Kalman (linearised model)": ("kalman", None),
    "Koopman-Kalman (DMD model)": ("koopman", None),
}


# ------------------------------------------------------------------------------------------- prose report


class Prose:
    def __init__(self, rd: Readme):
        self.rd = rd
        self.items: list[str] = []

    @staticmethod
    def _eval(v: Any) -> Any:
        """Values are given as lambdas, so that one that cannot be computed (a missing output, a mode not found)
        is reported as such instead of stopping the report."""
        if not callable(v):
            return v
        try:
            return v()
        except Exception as exc:  # noqa: BLE001 -- reported, not hidden
            return f"n/a (not computable from these outputs: {type(exc).__name__} {exc})"

    def add(self, section: str, what: str, pattern: str | None, new: Any, source: Any = "") -> None:
        """pattern: regex with groups for the old values, searched in the section's paragraphs (lines joined)."""
        new, source = self._eval(new), self._eval(source)
        old, sentence = "(no anchor)", ""
        if pattern:
            old, sentence = "(anchor not found: the README's wording changed?)", ""
            for para in self.rd.paragraphs(section):
                m = re.search(pattern, para)
                if m:
                    groups = [g for g in m.groups()] or [m.group(0)]
                    old = " | ".join(groups)
                    s0 = max(para.rfind(". ", 0, m.start()) + 2, 0) if para.rfind(". ", 0, m.start()) >= 0 else 0
                    s1 = para.find(". ", m.end())
                    s1 = len(para) if s1 < 0 else s1 + 1
                    sentence = para[s0:s1]
                    if len(sentence) > 700:
                        sentence = "..." + para[max(m.start() - 250, 0) : m.end() + 250] + "..."
                    break
        if isinstance(new, (list, tuple)):
            new = " | ".join(str(v) for v in new)
        flag = "" if str(new).replace(" ", "") == str(old).replace(" ", "") else "   <-- differs"
        text = f"[{section}] {what}\n    old: {old}\n    new: {new}{flag}"
        if source:
            text += f"\n    from: {source}"
        if sentence:
            text += f'\n    in:  "{sentence}"'
        self.items.append(text)

    def info(self, section: str, what: str, text: Any) -> None:
        text = str(self._eval(text))
        self.items.append(f"[{section}] {what}\n    " + text.replace("\n", "\n    "))


# ------------------------------------------------------------------------------------------- sections


def identification(rd: Readme, ch: Changes, pr: Prose, out: Path) -> None:
    S = "Identification"
    ids = {s: load(out / "identification" / f"seed{s}.json") for s in (1, 2)}
    if not all(ids.values()):
        ch.note("Identification: identification/seed1.json or seed2.json missing: table and prose not updated")
    else:

        def ref(label: str) -> float:
            plane = "FA" if "_fa_" in label else "SS"
            refs = {s: {r["label"]: r["frequency_hz"] for r in ids[s]["planes"][plane]["reference"]} for s in (1, 2)}
            if abs(refs[1][label] - refs[2][label]) > 1e-9:
                ch.note(f"Identification: {label}'s linearisation differs between the seeds' runs")
            return refs[1][label]

        def pair(seed: int, method: str, label: str) -> dict[str, Any] | None:
            plane = "FA" if "_fa_" in label else "SS"
            return next(
                (p for p in ids[seed]["planes"][plane].get("pairs", {}).get(method, []) if p["label"] == label), None
            )

        def both(method: str, label: str) -> str:
            hits = [pair(s, method, label) for s in (1, 2)]
            return " / ".join("-" if h is None else f"{h['f']:.3f}" for h in hits) + " Hz"

        def make(key: tuple[str, ...], cells: list[str]) -> list[str]:
            label = key[0]
            return [label, f"{ref(label):.4f} Hz", both("ssi", label), both("dmd", label), cells[4]]

        rewrite_table(rd, ch, S, "| mode | linearisation (OLC 4)", "Identification (Table 3)", 1, make)
        dur = {s: ids[s]["duration_s"] for s in (1, 2)}
        if any(d != 1800.0 for d in dur.values()):
            ch.note(f"Identification: records of {dur} s, not the README's 30 minutes (a --tiny run?)")

        labels = ["tower_fa_1", "tower_ss_1", "tower_fa_2", "tower_ss_2"]
        macs = {m: [p["mac"] for s in (1, 2) for lab in labels if (p := pair(s, m, lab))] for m in ("ssi", "dmd")}
        pr.add(
            S,
            "MAC against the linear output shapes (min over the 4 modes x 2 seeds; SSI-COV, Hankel-DMD)",
            r"with MAC (\d+(?:\.\d+)?) against the linear output shapes",
            lambda: f"{rng(macs['ssi'], '.2f')} (SSI-COV), {rng(macs['dmd'], '.2f')} (DMD); README says one number",
            "identification/seed*.json pairs[*].mac",
        )
        modes = {n: load(out / "modes" / f"{n}.json") for n in ("parked", "olc4")}
        if modes["parked"]:
            m = {r["label"]: r["frequency_hz"] for r in modes["parked"]}
            pr.add(
                S,
                "parked 1st tower modes, fore-aft and side-to-side (Hz)",
                r"parked, the surrogate's 1st tower modes are at (\d+(?:\.\d+)?) \(fore-aft.*?\) and (\d+(?:\.\d+)?) Hz",
                lambda: (f"{m['tower_fa_1']:.4f}", f"{m['tower_ss_1']:.4f}"),
                "modes/parked.json (fowt-env modes)",
            )
        pr.add(
            S,
            "operating (OLC 4) fore-aft and side-to-side 1st modes (Hz, linearisation)",
            r"sits at (\d+(?:\.\d+)?) Hz \(OpenFAST's.*?and the side-to-side one at (\d+(?:\.\d+)?) Hz",
            lambda: (f"{ref('tower_fa_1'):.3f}", f"{ref('tower_ss_1'):.3f}"),
            "identification reference",
        )
        ssi_err = [abs(p["freq_rel_error"]) for s in (1, 2) for lab in labels if (p := pair(s, "ssi", lab))]
        n_ssi = sum(1 for s in (1, 2) for lab in labels if pair(s, "ssi", lab))
        pr.add(
            S,
            "SSI-COV: largest frequency error against the linearisation (%), modes found (of 8)",
            r"SSI-COV finds all four within (\d+) % of the linearisation",
            lambda: f"{100 * max(ssi_err):.2f} % ({n_ssi} of 8 mode-seed pairs found)" if ssi_err else "none found",
            "pairs['ssi'].freq_rel_error",
        )
        # DMD's fore-aft lines around the operating mode
        f0 = ref("tower_fa_1")
        lines_txt, lower, upper, strongest = [], [], [], []
        for s in (1, 2):
            ms = [m for m in ids[s]["planes"]["FA"]["dmd"]["modes"] if 0.40 <= abs(m["frequency_hz"]) <= 0.70]
            lines_txt.append(
                f"seed {s}: "
                + ", ".join(f"{abs(m['frequency_hz']):.3f} Hz (energy {m['energy']:.3f}, {m['kind']})" for m in ms)
            )
            lo = [m for m in ms if 0.9 * f0 <= abs(m["frequency_hz"]) < f0]
            hi = [m for m in ms if f0 < abs(m["frequency_hz"]) <= 1.12 * f0]
            if lo:
                lower.append(max(lo, key=lambda m: m["energy"]))
            if hi:
                upper.append(max(hi, key=lambda m: m["energy"]))
            if ms:
                strongest.append(max(ms, key=lambda m: m["energy"]))
        pr.info(
            S,
            "Hankel-DMD lines of the FA plane in 0.40-0.70 Hz (to judge the fore-aft prose)",
            lambda: "\n".join(lines_txt),
        )
        ratio = [u["energy"] / l_["energy"] for u, l_ in zip(upper, lower, strict=False)] if lower and upper else []
        pr.add(
            S,
            "DMD fore-aft lines below / above the operating mode (strongest in 0.9-1x and 1-1.12x of it), "
            "energy ratio upper/lower",
            r"either side of the operating mode, (\d+(?:\.\d+)?-\d+(?:\.\d+)?) Hz and, with (\w+) times the energy, "
            r"(\d+(?:\.\d+)?-\d+(?:\.\d+)?) Hz",
            lambda: (
                rng([abs(m["frequency_hz"]) for m in lower], ".2f"),
                (rng(ratio, ".1f") + "x") if ratio else "n/a",
                rng([abs(m["frequency_hz"]) for m in upper], ".2f"),
            ),
            "identification FA dmd modes",
        )
        dp = {s: pair(s, "dmd", "tower_fa_1") for s in (1, 2)}
        pr.add(
            S,
            "DMD's paired tower_fa_1 line, seeds 1 and 2 (Hz) and its error (%); seed 2's two lines",
            r"\((\d+(?:\.\d+)?) and (\d+(?:\.\d+)?) Hz, (\d+) % and (\d+) % low; which of its two lines, (\d+(?:\.\d+)?) and "
            r"(\d+(?:\.\d+)?) Hz, seed 2 pairs",
            lambda: tuple(
                [f(dp[s]["f"] if dp[s] else None, ".3f") for s in (1, 2)]
                + [lowhigh(dp[s]["freq_rel_error"] if dp[s] else None) for s in (1, 2)]
                + [
                    f(abs(lower[-1]["frequency_hz"]) if len(lower) == 2 else None, ".3f"),
                    f(abs(upper[-1]["frequency_hz"]) if len(upper) == 2 else None, ".3f"),
                ]
            ),
            "pairs['dmd'] tower_fa_1; seed 2's lines as above",
        )
        pr.add(
            S,
            "DMD's strongest line in 0.40-0.70 Hz against the operating mode (% high)",
            r"its strongest line is (\d+-\d+) % high",
            lambda: (
                rng([100 * (abs(m["frequency_hz"]) / f0 - 1) for m in strongest], ".0f")
                + " %"
                + " at "
                + ", ".join(f"{abs(m['frequency_hz']):.3f} Hz" for m in strongest)
            ),
            "FA dmd modes",
        )
        dmd_other = [abs(p["freq_rel_error"]) for s in (1, 2) for lab in labels[1:] if (p := pair(s, "dmd", lab))]
        pr.add(
            S,
            "DMD: largest error of the side-to-side and 2nd modes (%)",
            r"The side-to-side and 2nd modes it finds within (\d+(?:\.\d+)?) %",
            lambda: f"{100 * max(dmd_other):.2f} %" if dmd_other else "none found",
            "pairs['dmd']",
        )
        pr.add(
            S,
            "the section's italic note on which physics the numbers were measured on",
            r"(as of commit \w+)",
            lambda: "update by hand: now rerun on " + provenance_head(out),
        )

    harm = load(out / "harmonics" / "harmonics.json")
    if harm is None:
        pr.info(
            S,
            "Rotor harmonics by order tracking",
            "not rerun (rerun.sh --with-harmonics makes harmonics/harmonics.json); its numbers stay as they are",
        )
        return
    olc4 = [r for r in harm["turbulent"] if r["case"] == 4]
    pr.add(
        S,
        "rotor speed std over 30 min of OLC 4, seeds 0, 3, 4 (rpm)",
        r"std (\d+(?:\.\d+)?-\d+(?:\.\d+)?) rpm over 30",
        lambda: rng([r["rotspeed_std_rpm"] for r in olc4], ".2f"),
        "harmonics.json turbulent[case 4]",
    )
    pr.add(
        S,
        "3P band: 1st-99th percentile of 3 x RotSpeed (Hz), OLC 4",
        r"sweeps a band \((\d+(?:\.\d+)?-\d+(?:\.\d+)?) Hz",
        lambda: (
            f"{min(r['f3p_p1_p99_hz'][0] for r in olc4):.2f}-{max(r['f3p_p1_p99_hz'][1] for r in olc4):.2f}"
            if olc4
            else "n/a"
        ),
        "harmonics.json",
    )
    ssi3 = [
        m
        for r in olc4
        for p in ("FA", "SS")
        for m in r["planes"][p]["ssi_rotor_band"]
        if 0.5 <= m["frequency_hz"] <= 0.7
    ]
    pr.add(
        S,
        "SSI-COV's 3P 'mode' on OLC 4 (Hz, damping %), both planes",
        r"as a (\d+(?:\.\d+)?-\d+(?:\.\d+)?) Hz \"mode\" with (\d+-\d+) % damping",
        lambda: (rng([m["frequency_hz"] for m in ssi3], ".2f"), rng([100 * m["damping_ratio"] for m in ssi3], ".0f")),
        "harmonics.json ssi_rotor_band (0.5-0.7 Hz)",
    )
    block = []
    for plane in ("FA", "SS"):
        lines = harm["steady"][plane]["lines"] or []
        block.append(
            f"{plane}: Rotor harmonics (Hankel-DMD at equal azimuth steps, speed from "
            f"{harm['steady'][plane]['rotor_speed']}): {len(lines)}"
        )
        block.append("   order   f (Hz)   sweeps (Hz)  locking")
        for h in lines:
            lo, hi = h["frequency_range_hz"]
            block.append(f"{h['order']:8.2f}{h['frequency_hz']:9.4f}  {lo:.3f}-{hi:.3f}{h['phase_locking']:9.2f}")
    pr.info(
        S,
        "steady-wind order-tracking table (the README's code block shows the FA plane; replace by hand)",
        lambda: "\n".join(block),
    )
    ss = harm["steady"]["SS"]["lines"] or []
    pr.add(
        S,
        "steady wind, side-to-side plane: order and frequency",
        r"order (\d+(?:\.\d+)?) at (\d+(?:\.\d+)?) Hz\)",
        lambda: "; ".join(f"{h['order']:.2f} at {h['frequency_hz']:.4f} Hz" for h in ss) or "none",
        "harmonics.json",
    )
    n = len(harm["turbulent"]) * 2
    empty = sum(1 for r in harm["turbulent"] for p in ("FA", "SS") if not r["planes"][p]["harmonics"])
    pr.add(
        S,
        "turbulent runs with an empty harmonics table",
        r"the table is empty in all (\d+) runs",
        lambda: f"{empty} of {n}",
        "harmonics.json",
    )


def lyapunov(rd: Readme, ch: Changes, pr: Prose, out: Path) -> None:
    S = "Identification"
    ly = load(out / "lyapunov" / "olc4.json")
    if ly is None:
        pr.info(S, "Lyapunov time", "lyapunov/olc4.json missing")
        return
    lam = [r["exponent_per_s"] for r in ly["seeds"]]
    pr.info(
        S,
        "Lyapunov: caveat",
        "the README's own procedure is unknown (README_pipeline.md): at HEAD 2c80b68 "
        "tools/readme_lyapunov.py's literal reading gives 0.749, 0.639, 0.705/s where the README says 0.540, 0.676, "
        "0.514/s; settings used: " + json.dumps(ly["settings"]),
    )
    pr.add(
        S,
        "Lyapunov: lambda range (1/s) and Lyapunov time range (s), seeds 0-2",
        r"it reports lambda = (\d+(?:\.\d+)?-\d+(?:\.\d+)?)/s, a Lyapunov time of (\d+(?:\.\d+)?-\d+(?:\.\d+)?) s",
        lambda: (rng(lam, ".2f"), rng([1 / v for v in lam if v > 0], ".1f")),
        "lyapunov/olc4.json",
    )
    pr.add(
        S,
        "Lyapunov: lambda per seed 0, 1, 2 (1/s)",
        r"\(seeds 0-2: (\d+(?:\.\d+)?), (\d+(?:\.\d+)?), (\d+(?:\.\d+)?)/s",
        lambda: tuple(f"{v:.3f}" for v in lam),
        "lyapunov/olc4.json",
    )
    pr.add(
        S,
        "Lyapunov: seed 0 and its phase-randomised copies (1/s)",
        r"\(seed 0: (\d+(?:\.\d+)?)/s, copies (\d+(?:\.\d+)?) and (\d+(?:\.\d+)?)/s",
        lambda: tuple([f"{lam[0]:.3f}"] + [f"{c['exponent_per_s']:.3f}" for c in ly["copies"]]),
        "lyapunov/olc4.json",
    )
    if ly["settings"]["duration"] != 300.0:
        ch.note(f"Lyapunov: records of {ly['settings']['duration']} s, not 300 s (a --tiny run?)")


def virtual_sensing(rd: Readme, ch: Changes, pr: Prose, out: Path) -> Compare | None:
    S = "Virtual sensing"
    t2d = load(out / "compare" / "table2.json")
    if t2d is None:
        ch.note("Virtual sensing: compare/table2.json missing: Table 2, Table 7 and prose not updated")
        return None
    t2 = Compare(t2d, "table2")
    s = t2d["settings"]
    if (s["duration"], s["train_duration"], tuple(s["train_cases"])) != (600.0, 300.0, (1, 3, 4, 6, 8, 9, 10, 11, 12)):
        ch.note(
            f"Virtual sensing: table2.json ran with duration {s['duration']}, training {s['train_duration']} s "
            f"of OLCs {s['train_cases']}: not the README's set-up (a --tiny run?)"
        )

    def scen_of(label: str) -> str:
        return label.split()[0]

    def make_t2(key: tuple[str, ...], cells: list[str]) -> list[str]:
        sc, (est, interval) = scen_of(key[0]), T2_SENSORS[key[1]]
        row = t2.row(sc, est, interval)
        case = t2.runs(sc, est, interval)[0]["case"]
        if f"(OLC {case})" not in key[0]:
            ch.note(f"Table 2: row {key[0]!r} but the run's test OLC is {case}")
        covs = [c for _, c in t2.covs(sc, est)]
        cov = (
            "-"
            if row["pooled_coverage95"] is None
            else (f"{row['pooled_coverage95']:.3f} ({min(covs):.2f}-{max(covs):.2f})")
        )
        return [
            cells[0],
            cells[1],
            f"{row['median_r2']:.4f} / {row['worst_r2']:.4f}",
            f"{100 * row['median_nrmse']:.2f}",
            f"{row['median_r2_band']:.3f} / {row['worst_r2_band']:.3f}",
            cov,
        ]

    rewrite_table(
        rd,
        ch,
        S,
        "| scenario | sensor | R² median / worst | NRMSE median (%) | R² band-passed median / worst | 95 % coverage",
        "Table 2 (surrogate)",
        2,
        make_t2,
    )

    lad = load(out / "compare" / "lookahead.json")
    la = Compare(lad, "lookahead") if lad else None
    if la is None:
        ch.note("Table 7 (surrogate): compare/lookahead.json missing: its look-ahead column kept")
    elif lad["settings"].get("estimator_options", {}).get("dmd", {}).get("causal") is not False:
        ch.note("Table 7 (surrogate): lookahead.json was not run with dmd.causal=false")

    def cell7(c: dict[str, Any]) -> str:
        return f"{c['r2_band']:.3f} / {100 * c['nrmse_band']:.2f}"

    def make_t7(key: tuple[str, ...], cells: list[str]) -> list[str]:
        sc = key[0]
        m = re.match(r"(\d+) `(\w+)`", key[1])
        idx, name = int(m.group(1)), m.group(2)
        if t2d["settings"]["channels"].index(name) != idx:
            ch.note(f"Table 7 (surrogate): {name} is FA index {t2d['settings']['channels'].index(name)}, not {idx}")
        new = list(cells)
        if la is not None:
            new[3] = cell7(la.channel(sc, "dmd", name))
        new[4] = cell7(t2.channel(sc, "dmd", name, 1.0))
        new[5] = cell7(t2.channel(sc, "kalman", name))
        return new

    rewrite_table(
        rd, ch, S, "| scenario | sensor (FA index) | paper: look-ahead DMD, OpenFAST", "Table 7 (surrogate)", 2, make_t7
    )

    # ---- prose: Table 7
    t7 = {(sc, c["channel"]): c for sc in ("A", "B", "C") for c in t2.channels(sc, "dmd", 1.0)}
    if la is not None:
        lav = {(sc, c["channel"]): c["r2_band"] for sc in ("A", "B", "C") for c in la.channels(sc, "dmd")}
        pr.add(
            S,
            "look-ahead DMD: band R² range over Table 7's sensors",
            r"passes the paper's numbers on surrogate "
            r"data \(band-passed R² (\d+(?:\.\d+)?-\d+(?:\.\d+)?) against",
            lambda: rng(list(lav.values()), ".3f"),
            "lookahead.json",
        )
        pr.add(
            S,
            "look-ahead: nacelle moment 17 in B and C; mid-tower accelerometer 5 in A",
            r"the nacelle moment 17 \((\d+(?:\.\d+)?-\d+(?:\.\d+)?)\) and, as in the paper, the mid-tower accelerometer 5 "
            r"\((\d+(?:\.\d+)?)\)",
            lambda: (
                rng([lav.get(("B", "TwHt9MLyt")), lav.get(("C", "TwHt9MLyt"))], ".3f"),
                f(lav.get(("A", "TwHt6ALxt")), ".3f"),
            ),
            "lookahead.json",
        )
        weakest = sorted(lav.items(), key=lambda kv: kv[1])[:4]
        pr.info(S, "look-ahead DMD's weakest sensors", lambda: ", ".join(f"{k[0]} {k[1]} {v:.3f}" for k, v in weakest))
        loss = [lav[k] - t7[k]["r2_band"] for k in lav if k in t7]
        pr.add(
            S,
            "causal DMD's loss of band R² against the look-ahead smoother, per sensor (min-max)",
            r"loses (\d+(?:\.\d+)?-\d+(?:\.\d+)?) in R² on the tower-mode band",
            lambda: rng(loss, ".2f"),
            "lookahead.json - table2.json",
        )
    pr.add(
        S,
        "causal DMD: nacelle moment 17 band R² in B and C",
        r"most on the nacelle moment 17 \((\d+(?:\.\d+)?-\d+(?:\.\d+)?) in"
        r" B and C\)",
        lambda: rng([t7[("B", "TwHt9MLyt")]["r2_band"], t7[("C", "TwHt9MLyt")]["r2_band"]], ".2f"),
        "table2.json dmd",
    )
    # ---- prose: what the numbers say
    sc4 = [sc for sc in ("A", "B", "C", "random") if t2.runs(sc, "dmd", 1.0)]
    worst = {sc: min(t2.channels(sc, "dmd", 1.0), key=lambda c: c["r2_band"]) for sc in sc4}  # sc4: with dmd runs
    pr.add(
        S,
        "causal DMD: band median range; worst-channel range; B/C worst; random worst; A worst (channel)",
        r"drops to (\d+(?:\.\d+)?-\d+(?:\.\d+)?) median and (\d+(?:\.\d+)?-\d+(?:\.\d+)?) on its worst channel \(the nacelle moment "
        r"`TwHt9MLyt` in scenarios B and C, (\d+(?:\.\d+)?-\d+(?:\.\d+)?); (\d+(?:\.\d+)?) under random dropouts; `TwHt6ALxt` in A, "
        r"(\d+(?:\.\d+)?)\)",
        lambda: (
            rng([t2.row(sc, "dmd", 1.0)["median_r2_band"] for sc in sc4], ".2f"),
            rng([w["r2_band"] for w in worst.values()], ".2f"),
            rng([worst[sc]["r2_band"] for sc in ("B", "C")], ".2f") + f" ({worst['B']['channel']}, "
            f"{worst['C']['channel']})",
            f"{worst['random']['r2_band']:.2f} ({worst['random']['channel']})",
            f"{worst['A']['r2_band']:.2f} ({worst['A']['channel']})",
        ),
        "table2.json dmd rows and channels",
    )
    kk = [t2.row(sc, e)["worst_r2_band"] for sc in t2.scenarios() for e in ("kalman", "koopman") if t2.runs(sc, e)]
    pr.add(
        S,
        "both Kalman filters: lowest worst-channel band R²",
        r"stay at (\d+(?:\.\d+)?) or above",
        lambda: f"{min(kk):.3f}",
        "table2.json kalman/koopman worst_r2_band",
    )
    # ---- coverage
    sck = [sc for sc in ("A", "B", "C", "random") if t2.runs(sc, "kalman")]
    sckp = [sc for sc in ("A", "B", "C", "random") if t2.runs(sc, "koopman")]
    kal = {sc: t2.row(sc, "kalman")["pooled_coverage95"] for sc in sck}
    kc = [(sc, n, c) for sc in sck for n, c in t2.covs(sc, "kalman")]
    inside = sum(0.90 <= c <= 0.98 for _, _, c in kc)
    misses = readme_misses([(sc, n, c) for sc, n, c in kc if not 0.90 <= c <= 0.98])
    pr.add(
        S,
        "Kalman pooled coverage range over the scenarios (%)",
        r"cover the truth (\d+(?:\.\d+)?-\d+(?:\.\d+)?) % of the hidden samples",
        lambda: rng([100 * v for v in kal.values()], ".1f"),
        lambda: (
            "table2.json kalman pooled_coverage95 (" + ", ".join(f"{k} {100 * v:.1f}" for k, v in kal.items()) + ")"
        ),
    )
    pr.add(
        S,
        "Kalman channels inside 90-98 %, and the misses",
        r"with (\d+) of (\d+) hidden channels inside 90-98 % \(the misses: (.*?); one 300 s",
        lambda: (str(inside), str(len(kc)), misses),
        "table2.json kalman channels coverage95",
    )
    kp = [t2.row(sc, "koopman")["pooled_coverage95"] for sc in sckp]
    kpc = [(sc, n, c) for sc in sckp for n, c in t2.covs(sc, "koopman")]
    mom = [min([c for s_, n, c in kpc if s_ == sc and "MLyt" in n] or [float("nan")]) for sc in sckp]
    pr.add(
        S,
        "Koopman-Kalman: pooled range (%), channels inside 90-98 %, lowest moment-gauge coverage per scenario",
        r"too narrow, (\d+(?:\.\d+)?-\d+(?:\.\d+)?) % pooled, (\d+) of (\d+) channels inside 90-98 %, the moment gauges down to "
        r"(\d+(?:\.\d+)?-\d+(?:\.\d+)?)",
        lambda: (
            rng([100 * v for v in kp], ".0f"),
            str(sum(0.90 <= c <= 0.98 for *_, c in kpc)),
            str(len(kpc)),
            rng(mom, ".2f") + " (" + ", ".join(f"{sc} {m:.2f}" for sc, m in zip(sckp, mom, strict=True)) + ")",
        ),
        "table2.json koopman",
    )
    s1d = load(out / "compare" / "seed1.json")
    if s1d is None:
        ch.note("Virtual sensing: compare/seed1.json missing: seed-1 line not computed")
    else:
        s1 = Compare(s1d, "seed1")
        if s1d["runs"] and {r["seed"] for r in s1d["runs"]} != {1}:
            ch.note("seed1.json does not hold test seed 1 only")
        s1sc = [sc for sc in ("A", "B", "C", "random") if s1.runs(sc, "kalman") and s1.runs(sc, "koopman")]
        kw = {e: [s1.row(sc, e)["worst_r2"] for sc in s1sc] for e in ("kalman", "koopman")}
        km = {e: [s1.row(sc, e)["median_r2"] for sc in s1sc] for e in ("kalman", "koopman")}
        pr.add(
            S,
            "test seed 1: Kalman pooled A / B / C / random (%), Koopman-Kalman pooled range (%), physical R² "
            "(ambiguous in the README: here the worst-channel range of both filters; medians below)",
            r"Kalman (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) % pooled in scenarios A / B / C / random, "
            r"Koopman-Kalman (\d+-\d+) %, physical R² (\d+(?:\.\d+)?-\d+(?:\.\d+)?)",
            lambda: (
                tuple(f"{100 * s1.row(sc, 'kalman')['pooled_coverage95']:.1f}" for sc in s1sc)
                + (
                    rng([100 * s1.row(sc, "koopman")["pooled_coverage95"] for sc in s1sc], ".0f"),
                    rng(kw["kalman"] + kw["koopman"], ".3f"),
                )
            ),
            lambda: (
                f"seed1.json; worst R² Kalman {rng(kw['kalman'], '.3f')}, Koopman {rng(kw['koopman'], '.3f')}; "
                f"median R² Kalman {rng(km['kalman'], '.4f')}, Koopman {rng(km['koopman'], '.4f')}"
            ),
        )
    # ---- sweep
    swd = load(out / "compare" / "sweep.json")
    if swd is None:
        ch.note("Virtual sensing: compare/sweep.json missing: sweep caption not computed")
    else:
        sw = Compare(swd, "sweep")
        ivs = (0.25, 1.0, 2.0, 4.0)
        scs = [sc for sc in ("A", "B", "C", "random") if sw.runs(sc, "dmd")]
        band = [rng([sw.row(sc, "dmd", iv)["median_r2_band"] for sc in scs], ".2f") for iv in ivs]
        phys = [rng([sw.row(sc, "dmd", iv)["median_r2"] for sc in scs], ".2f") for iv in ivs]
        pr.add(
            S,
            "sweep caption: DMD median band R² at 0.25 / 1 / 2 / 4 s, then physical (ranges over scenarios)",
            r"falls from (\d+(?:\.\d+)?-\d+(?:\.\d+)?) at 0.25 s to (\d+(?:\.\d+)?-\d+(?:\.\d+)?) at 1 s, (\d+(?:\.\d+)?-\d+(?:\.\d+)?) at 2 s and "
            r"(\d+(?:\.\d+)?-\d+(?:\.\d+)?) at 4 s \(physical signals: (\d+(?:\.\d+)?-\d+(?:\.\d+)?), (\d+(?:\.\d+)?-\d+(?:\.\d+)?), (\d+(?:\.\d+)?-\d+(?:\.\d+)?), "
            r"(\d+(?:\.\d+)?-\d+(?:\.\d+)?)\)",
            lambda: tuple(band + phys),
            "sweep.json table (dmd)",
        )
        longest = {r["scenario"]: r["longest_within_s"] for r in swd["sweep"] if r["estimator"] == "dmd"}
        others = [longest.get(sc) for sc in scs if sc != "A"]
        pr.add(
            S,
            "sweep: longest interval with every hidden channel within 5 % NRMSE, A and the others (s)",
            r"within 5 % NRMSE up to (\d+(?:\.\d+)?) s in scenario A and up to (\d+(?:\.\d+)?) s in the others",
            lambda: (
                f"{longest.get('A')}",
                ", ".join(f"{sc} {longest.get(sc)}" for sc in scs if sc != "A")
                + ("" if len(set(others)) <= 1 else "  (NOT the same in the others)"),
            ),
            "sweep.json sweep",
        )
        pr.info(
            S,
            "consistency: the sweep's DMD at 1 s against Table 2's DMD rows (same records: equal expected)",
            lambda: ", ".join(
                f"{sc} {sw.row(sc, 'dmd', 1.0)['median_r2_band']:.4f} vs {t2.row(sc, 'dmd', 1.0)['median_r2_band']:.4f}"
                for sc in scs
            ),
        )
        lam = swd.get("lyapunov") or {}
        pr.add(
            S,
            "sweep figure's Lyapunov time (s)",
            r"Lyapunov time, (\d+(?:\.\d+)?) s \(Rosenstein",
            lambda: f(lam.get("time_s"), ".2f"),
            lambda: f"sweep.json lyapunov ({lam.get('source')}; {lam.get('diagnostic')})",
        )
        pr.info(
            S,
            "sweep figure",
            lambda: (
                f"{out / 'compare' / 'sweep_figures' / 'update_interval_sweep.png'} "
                "-> docs/figures/compare_update_interval_sweep.png"
            ),
        )
    pr.add(
        S,
        "the section's italic note (which physics)",
        r"rerun on the physics of this\s+checkout \((.*?)\)",
        lambda: "update by hand if the physics' name changed: " + provenance_head(out),
    )
    pr.info(
        S, "not regenerated here", "the Cost bullet (python benchmarks/virtual_sensing.py) is outside this pipeline"
    )
    return t2


def openfast(rd: Readme, ch: Changes, pr: Prose, out: Path, t2: Compare | None) -> None:
    S = "OpenFAST / model error"
    of = out / "openfast"
    md = of / "table7.md"
    tj = load(of / "table7.json")
    folds = {p.stem[len("fold_") :]: json.loads(p.read_text()) for p in sorted(of.glob("fold_*.json"))}
    if not md.is_file() or tj is None:
        ch.note("OpenFAST: openfast/table7.md or table7.json missing: OpenFAST tables not updated")
    else:
        rows = {}
        for ln in md.read_text().split("\n"):
            if ln.startswith("| ") and not ln.startswith("| scenario") and not ln.startswith("|---"):
                cells = split_row(ln)
                if len(cells) == 7:
                    rows[(cells[0], cells[1])] = cells
        ests = sorted({r["estimator"] for fold in folds.values() for r in fold["runs"]})
        pr.info(
            S,
            "OpenFAST Table 7 sensors in this run",
            lambda: (
                ", ".join(ests)
                + ("" if len(ests) > 3 else "  (the other rows stay as measured at commit 2b32232, as the README says)")
            ),
        )

        def make(key: tuple[str, ...], cells: list[str]) -> list[str] | None:
            if key in rows:
                return rows.pop(key)
            return None

        rewrite_table(
            rd,
            ch,
            S,
            "| scenario | sensor | R² median / worst | NRMSE median (%) | R² band-passed median "
            "/ worst | NRMSE band-passed median (%)",
            "OpenFAST Table 7 (aggregate)",
            2,
            make,
        )
        for key in rows:
            ch.note(f"OpenFAST Table 7: the tool's row {key} has no README row (B and C no longer equal?)")

        rated = folds.get("c_op12_Hs2p5_Tp10")
        col = {3: "dmd_lookahead", 4: "dmd", 5: "kalman", 6: "koopman"}

        def make_ps(key: tuple[str, ...], cells: list[str]) -> list[str]:
            if rated is None:
                raise KeyError("no fold_c_op12_Hs2p5_Tp10.json")
            sc = "B" if key[0] == "B = C" else key[0]
            name = re.search(r"`(\w+)`", key[1]).group(1)
            new = list(cells)
            for k, est in col.items():
                hit = [
                    c
                    for r in rated["runs"]
                    if r["scenario"] == sc and r["estimator"] == est
                    for c in r["channels"]
                    if c["channel"] == name
                ]
                if hit and hit[0]["r2_band"] is not None:
                    new[k] = f"{tool_fmt(hit[0]['r2_band'])} / {tool_fmt(100 * hit[0]['nrmse_band'], '.2f')}"
            return new

        rewrite_table(
            rd,
            ch,
            S,
            "| scenario | sensor (FA index) | paper: look-ahead DMD | look-ahead DMD",
            "OpenFAST Table 7 per sensor at 12 m/s",
            2,
            make_ps,
        )

        # ---- prose
        table = {(r["scenario"], r["estimator"]): r for r in tj["table"]}
        have = {e for _, e in table}

        def rowv(sc: str, est: str, key: str) -> float | None:
            r = table.get((sc, est))
            return None if r is None else r[key]

        def fold_chan(fold: str, sc: str, est: str) -> list[dict[str, Any]]:
            return [
                c
                for r in folds.get(fold, {"runs": []})["runs"]
                if r["scenario"] == sc and r["estimator"] == est
                for c in r["channels"]
            ]

        def fold_run(fold: str, sc: str, est: str) -> dict[str, Any] | None:
            return next(
                (r for r in folds.get(fold, {"runs": []})["runs"] if r["scenario"] == sc and r["estimator"] == est),
                None,
            )

        scs = ("A", "B", "random")
        wall = timings(out)
        pr.add(
            S,
            "italic note: run times of the Kalman rows and of the model-error table (min)",
            r"`tools/openfast_table7.py --estimators kalman,kalman_nogate,kalman_nominal`, (\d+) min, and "
            r"`tools/model_error_table.py`, (\d+) min",
            lambda: (
                f"{wall.get('openfast', 0) / 60:.0f}" if "openfast" in wall else "n/a",
                f"{wall.get('modelerr', 0) / 60:.0f}" if "modelerr" in wall else "n/a",
            ),
            "timings.txt (wall, niced)",
        )
        if "dmd_lookahead" in have:
            ps = [c["r2_band"] for sc in ("A", "B") for c in fold_chan("c_op12_Hs2p5_Tp10", sc, "dmd_lookahead")]
            n17 = [
                c["r2_band"]
                for c in fold_chan("c_op12_Hs2p5_Tp10", "B", "dmd_lookahead")
                if c["channel"] == "TwHt9MLyt"
            ]
            pr.add(
                S,
                "look-ahead DMD per sensor at 12 m/s (range; nacelle moment 17); median over all runs",
                r"band-passed R² (\d+(?:\.\d+)?-\d+(?:\.\d+)?) per sensor at 12 m/s against the paper's 0.943-0.998, weakest at "
                r"the nacelle moment 17 \((\d+(?:\.\d+)?) vs 0.956\).*?over all three runs (\d+(?:\.\d+)?-\d+(?:\.\d+)?) median",
                lambda: (
                    rng(ps, ".3f"),
                    f(n17[0] if n17 else None, ".3f"),
                    rng([rowv(sc, "dmd_lookahead", "median_r2_band") for sc in scs], ".3f"),
                ),
                "table7.json, folds",
            )
        sur_med = (
            rng([t2.row(sc, "dmd", 1.0)["median_r2_band"] for sc in ("A", "B", "C", "random")], ".2f") if t2 else "n/a"
        )
        sur_17 = rng([t2.channel(sc, "dmd", "TwHt9MLyt", 1.0)["r2_band"] for sc in ("B", "C")], ".2f") if t2 else "n/a"
        if "dmd" in have:
            c17 = [c["r2_band"] for c in fold_chan("c_op12_Hs2p5_Tp10", "B", "dmd") if c["channel"] == "TwHt9MLyt"]
            of_med, of_17 = (
                rng([rowv(sc, "dmd", "median_r2_band") for sc in scs], ".2f"),
                f(c17[0] if c17 else None, ".2f"),
            )
        else:
            of_med = of_17 = "(causal DMD not rerun: keep)"
        pr.add(
            S,
            "causal DMD: OpenFAST band median range vs surrogate's; nacelle moment at 12 m/s vs surrogate B/C",
            r"\(band median (\d+(?:\.\d+)?-\d+(?:\.\d+)?) against (\d+(?:\.\d+)?-\d+(?:\.\d+)?); the nacelle moment `TwHt9MLyt` down to "
            r"(\d+(?:\.\d+)?) at 12 m/s, against (\d+(?:\.\d+)?-\d+(?:\.\d+)?) on surrogate data\)",
            lambda: (of_med, sur_med, of_17, sur_17),
            "table7.json / table2.json",
        )
        lm = tj.get("linear_map_check") or []
        fits = [c for c in lm if "scenario" in c]
        if fits:
            pr.add(
                S,
                "static least-squares map: worst hidden R² (physical, band) over A, B and the three runs",
                r"reconstructs the third's hidden channels with R² ≥ (\d+(?:\.\d+)?)",
                lambda: f"{min(c['min_r2'] for c in fits):.6f}, band {min(c['min_r2_band'] for c in fits):.6f}",
                "table7.json linear_map_check (data only: does not depend on the surrogate)",
            )
            sv = lm[-1]["singular_values_12mps"]
            pr.add(
                S,
                "singular values of the z-scored 12 m/s record (relative)",
                r"singular values of the z-scored 12 m/s record: (.*?)\)",
                lambda: ", ".join(f"{v:.2g}" for v in sv[:7]),
                "table7.json linear_map_check",
            )
        if "koopman" in have:
            kc = [c for sc in ("A", "B") for c in fold_chan("c_op12_Hs2p5_Tp10", sc, "koopman")]
            pr.add(
                S,
                "Koopman-Kalman per sensor at 12 m/s: lowest band R², band NRMSE range (%)",
                r"The Koopman-Kalman sensor learns that map \(R² (\d+(?:\.\d+)?), band NRMSE (\d+(?:\.\d+)?-\d+(?:\.\d+)?) %\)",
                lambda: (f"{min(c['r2_band'] for c in kc):.3f}", rng([100 * c["nrmse_band"] for c in kc], ".2f")),
                "fold_c_op12",
            )
            pr.add(
                S,
                "Koopman-Kalman coverage: pooled range (%), per-channel range in A, inside 90-98 % in A",
                r"cover (\d+-\d+) % pooled \((\d+(?:\.\d+)?-\d+(?:\.\d+)?) per channel, none of (\d+) channels",
                lambda: (
                    rng([100 * rowv(sc, "koopman", "pooled_coverage95") for sc in scs], ".0f"),
                    f"{rowv('A', 'koopman', 'coverage95_min'):.2f}-{rowv('A', 'koopman', 'coverage95_max'):.2f}",
                    f"{rowv('A', 'koopman', 'coverage95_inside_90_98')} of {rowv('A', 'koopman', 'coverage95_n')}",
                ),
                "table7.json",
            )
        if "kalman" in have:
            pr.add(
                S,
                "Kalman (default): band median range and band worst range over A, B = C, random",
                r"it reaches band-passed R² (\d+(?:\.\d+)?-\d+(?:\.\d+)?) median and (\d+(?:\.\d+)?-\d+(?:\.\d+)?) worst over the three runs",
                lambda: (
                    rng([rowv(sc, "kalman", "median_r2_band") for sc in scs], ".3f"),
                    rng([rowv(sc, "kalman", "worst_r2_band") for sc in scs], ".3f"),
                ),
                "table7.json kalman",
            )
            ps = [
                (c["channel"], c["r2_band"]) for sc in ("A", "B") for c in fold_chan("c_op12_Hs2p5_Tp10", sc, "kalman")
            ]
            if ps:
                weakest = min(ps, key=lambda p: p[1])
                pr.add(
                    S,
                    "Kalman (default) per sensor at 12 m/s: range, weakest channel",
                    r"per sensor at 12 m/s (\d+(?:\.\d+)?-\d+(?:\.\d+)?), the tower-top accelerometer weakest",
                    lambda: f"{rng([p[1] for p in ps], '.3f')} (weakest {weakest[0]} {weakest[1]:.3f})",
                    "fold_c_op12",
                )
            r8 = {e: fold_run("c_op08_Hs2p0_Tp9", "A", e) for e in ("kalman", "kalman_nominal")}
            if all(r8.values()):
                pr.add(
                    S,
                    "8 m/s fold, scenario A: pooled coverage, default vs nominal levels",
                    r"coverage (\d+(?:\.\d+)?) against the nominal (\d+(?:\.\d+)?)\)",
                    lambda: (
                        f"{r8['kalman']['pooled_coverage95']:.3f}",
                        f"{r8['kalman_nominal']['pooled_coverage95']:.3f}",
                    ),
                    "fold_c_op08 A",
                )
            r18 = {e: fold_run("c_op18_Hs4p0_Tp11", "random", e) for e in ("kalman", "kalman_nogate", "kalman_nominal")}
            if all(r18.values()):
                pr.add(
                    S,
                    "18 m/s random: worst channel R², default vs nominal-level filter (no gate)",
                    r"except 18 m/s under random dropouts \(worst channel (\d+(?:\.\d+)?) against (\d+(?:\.\d+)?)\)",
                    lambda: (f"{r18['kalman']['worst_r2']:.3f}", f"{r18['kalman_nominal']['worst_r2']:.3f}"),
                    lambda: (
                        f"fold_c_op18 random (kalman_nogate {r18['kalman_nogate']['worst_r2']:.3f}; band worst "
                        f"{r18['kalman']['worst_r2_band']:.3f} / {r18['kalman_nominal']['worst_r2_band']:.3f})"
                    ),
                )
            same = all(
                fold_run(fd, sc, "kalman")
                and fold_run(fd, sc, "kalman_nominal")
                and fold_run(fd, sc, "kalman")["worst_r2"] == fold_run(fd, sc, "kalman_nominal")["worst_r2"]
                for fd in folds
                for sc in ("A", "B", "random")
            )
            pr.info(
                S,
                "default Kalman vs nominal-level filter",
                lambda: (
                    "identical worst R² in every fold and scenario"
                    if same
                    else "they differ in some cells (see the before/after values below)"
                ),
            )
        if {"kalman", "kalman_nominal"} <= have:
            pr.add(
                S,
                "pooled coverage A / B / random: nominal levels, then the default (%)",
                r"nominal loads covers (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) % pooled \(A / B / random; the default, with "
                r"its learned levels, (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) %\)",
                lambda: tuple(
                    f"{100 * rowv(sc, e, 'pooled_coverage95'):.1f}" for e in ("kalman_nominal", "kalman") for sc in scs
                ),
                "table7.json",
            )
            lines = []
            for fd in folds:
                for sc in scs:
                    cs = fold_chan(fd, sc, "kalman_nominal")
                    outside = [
                        f"{c['channel']} {c['coverage95']:.2f}"
                        for c in cs
                        if c.get("coverage95") is not None and not 0.90 <= c["coverage95"] <= 0.98
                    ]
                    lines.append(f"{fd} {sc}: {len(outside)} of {len(cs)} outside 90-98 %: " + ", ".join(outside))
            pr.info(
                S,
                "nominal-level Kalman coverage per operating point (for the 'pattern by operating point' "
                "sentence, which the README says was measured with the quasi-static flap lag)",
                lambda: "\n".join(lines),
            )
            cells = []
            for fd, speed in (
                ("c_op08_Hs2p0_Tp9", "8 m/s"),
                ("c_op12_Hs2p5_Tp10", "12 m/s"),
                ("c_op18_Hs4p0_Tp11", "18 m/s"),
            ):
                rs = [fold_run(fd, sc, "kalman") for sc in scs]
                cells.append(
                    f"{speed}: "
                    + " | ".join("-" if r is None else f"{r['worst_r2']:.4f} ({r['worst_r2_band']:.3f})" for r in rs)
                )
            pr.info(
                S,
                "the historical before -> after table (not rewritten): current worst R² (band) of the "
                "default Kalman per run, A | B = C | random",
                lambda: "\n".join(cells),
            )
        log = out / "logs" / "openfast.log"
        if log.is_file():
            text = log.read_text(errors="replace")
            pr.info(
                S,
                "warnings in the OpenFAST run's log (load-level fallback, resets)",
                lambda: (
                    f"'nominal' in {sum('nominal' in ln and 'Warning' in ln for ln in text.splitlines())} warning "
                    f"lines, 'reset' in {sum('reset' in ln.lower() and 'Warning' in ln for ln in text.splitlines())}"
                    f" (see {log}); the README's 'falls back ... in the folds tested at 12 and 18 m/s' and '5 samples "
                    "down-weighted' are not in the JSON: check the log by hand"
                ),
            )

    # ---- model-error table
    me = load(out / "model_error" / "model_error.json")
    mmd = out / "model_error" / "model_error.md"
    if me is None or not mmd.is_file():
        ch.note("Model error: model_error/model_error.json or .md missing: table not updated")
        return
    rows = {
        split_row(ln)[0]: split_row(ln)
        for ln in mmd.read_text().split("\n")
        if ln.startswith("| ") and not ln.startswith("| truth") and not ln.startswith("|---")
    }

    def make_me(key: tuple[str, ...], cells: list[str]) -> list[str]:
        return rows.pop(key[0])

    rewrite_table(rd, ch, S, "| truth (records) | Kalman, nominal model", "Model-error table", 1, make_me)
    for key in rows:
        ch.note(f"Model-error table: the tool's row {key!r} has no README row")
    st = me["settings"]
    if (tuple(st["train_cases"]), st["train_duration"], st["duration"], tuple(st["seeds"])) != (
        (1, 4, 6, 10),
        300.0,
        300.0,
        (0, 1, 2),
    ):
        ch.note(f"Model error: settings {st} differ from the README's (a --tiny run?)")
    deltas = {}
    for r in me["rows"]:
        if "kalman_true" in r:
            deltas[r["perturbation"]] = [
                a - b
                for a, b in zip(
                    r["kalman_nominal"]["per_seed_median_r2_band"],
                    r["kalman_true"]["per_seed_median_r2_band"],
                    strict=True,
                )
            ]
    alld = [d for v in deltas.values() for d in v]
    if alld:
        pr.add(
            S,
            "model error: range of the per-seed differences (nominal - true)",
            r"the differences are ([-+.\de]+) to ([-+.\de]+) in band-passed R²",
            lambda: (sci(min(alld), min(alld) > 0), sci(max(alld))),
            "model_error.json",
        )
    tw = deltas.get("tower stiffness x0.95")
    if tw:
        pr.add(
            S,
            "tower stiffness x0.95: the three seeds' differences",
            r"and now ([-+.\de]+), ([-+.\de]+), "
            r"([-+.\de]+); it takes",
            lambda: tuple(sci(v) for v in tw),
            "model_error.json",
        )
    pm = deltas.get("platform mass +3 %")
    if pm:
        pr.add(
            S,
            "platform mass +3 %: range of the differences",
            r"The platform mass \+3 % moves it by ([-+.\de]+) to "
            r"([-+.\de]+) \(",
            lambda: (sci(min(pm)), sci(max(pm))),
            "model_error.json",
        )
    md_ = [abs(v) for k in ("mooring line stiffness -30 %", "drag x1.5") for v in deltas.get(k, [])]
    if md_:
        pr.add(
            S,
            "mooring stiffness and drag: largest |difference|",
            r"the drag by about ([\de.-]+) or less",
            lambda: sci(max(md_), False),
            "model_error.json",
        )
    covs = [r[k]["pooled_coverage95"] for r in me["rows"] for k in ("kalman_nominal", "kalman_true") if k in r]
    pr.add(
        S,
        "Kalman coverage range over every row, nominal and true model (%)",
        r"coverage stays (\d+(?:\.\d+)?-\d+(?:\.\d+)?) % throughout",
        lambda: rng([100 * c for c in covs], ".1f"),
        "model_error.json",
    )
    nom = next((r for r in me["rows"] if r["perturbation"].startswith("none")), None)
    imb = next((r for r in me["rows"] if r["perturbation"].startswith("rotor mass imbalance")), None)
    if nom and imb:
        keys = ("median_r2_band", "worst_r2_band", "median_r2", "worst_r2")
        diff = max(abs(nom[e][k] - imb[e][k]) for e in ("kalman_nominal", "koopman") for k in keys)
        pr.add(
            S,
            "2 % imbalance: largest change of any Kalman/Koopman R² against the nominal turbine",
            r"leaves every score unchanged to the (\w+) digit",
            lambda: (
                f"{diff:.1e} ("
                + ("unchanged to the fifth digit" if diff < 5e-6 else "CHANGES at the fifth digit")
                + ")"
            ),
            "model_error.json",
        )


def provenance_head(out: Path) -> str:
    p = out / "provenance.txt"
    if not p.is_file():
        return "(no provenance.txt)"
    head = next((ln.split()[1][:7] for ln in p.read_text().split("\n") if ln.startswith("HEAD ")), "?")
    dirty = any(ln.startswith("status  M") or ln.startswith("status M") for ln in p.read_text().split("\n"))
    return f"HEAD {head}" + (" plus uncommitted changes (provenance.diff)" if dirty else "")


def timings(out: Path) -> dict[str, float]:
    t = {}
    p = out / "timings.txt"
    if p.is_file():
        for ln in p.read_text().split("\n"):
            parts = ln.split()
            if len(parts) >= 2 and parts[1].isdigit():
                t[parts[0]] = float(parts[1])
    return t


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", type=Path)
    ap.add_argument("readme_in", type=Path)
    ap.add_argument("readme_out", type=Path)
    ap.add_argument("--report", type=Path, help="also write the printed report here")
    a = ap.parse_args()
    if a.readme_out.resolve() == a.readme_in.resolve():
        raise SystemExit("apply.py: README_OUT must differ from README_IN (work on a copy)")
    text = a.readme_in.read_text()
    rd, ch = Readme(text), Changes()
    pr = Prose(Readme(text))  # old values from the unchanged text
    identification(rd, ch, pr, a.outdir)
    lyapunov(rd, ch, pr, a.outdir)
    t2 = virtual_sensing(rd, ch, pr, a.outdir)
    openfast(rd, ch, pr, a.outdir, t2)
    a.readme_out.write_text(rd.text())

    rep = [
        f"apply.py: {a.outdir} -> {a.readme_out} (from {a.readme_in}); outputs made on {provenance_head(a.outdir)}",
        "",
    ]
    changed = [(t, o, n) for t, o, n in ch.rows if o != n]
    rep.append(f"TABLE ROWS: {len(ch.rows)} matched, {len(changed)} changed")
    for t, o, n in changed:
        rep += [f"  [{t}]", f"    - {o}", f"    + {n}"]
    rep += ["", "NOTES"] + [f"  * {m}" for m in ch.notes] + ["", "PROSE NUMBERS (edit by hand)", ""]
    for item in pr.items:
        rep += [item, ""]
    report = "\n".join(rep)
    print(report)
    if a.report:
        a.report.write_text(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
