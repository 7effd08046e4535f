"""``fowt-env demo`` tells one story: what it prints, what it draws and the model it compares with agree (issue 19).

The identification step is checked on the record the demo makes (OLC 7, shorter): the SSI-COV table lists
exactly the modes whose poles the stabilisation diagram draws as stable, and no line printed as "structural"
(Hankel-DMD or SSI-COV) lies more than 10 % from a mode of the model linearised at the record's load case.
"""

import re

import numpy as np
import pytest

import surrogates
from fowt_env import cli, plots
from fowt_env.identification import KIND_MEANING, OVERDAMPED_LINE, label_against_model, rotor_bands

CASE = 7
_ROW = re.compile(r"^\s+(\d+\.\d{4})\s.*?\s(structural|harmonic|rotor_band|unmodelled|noise)\b(.*)$")


@pytest.fixture(scope="module")
def demo_record():
    model = surrogates.FOWTModel()
    case = surrogates.load_case(CASE)
    return model, case, surrogates.simulate(model, case, duration=300.0, dt=0.0125, seed=0)


@pytest.fixture
def drawn(monkeypatch):
    """The figures the plotting functions save, by file name, still open (their artists can be read)."""
    figures = {}
    save = plots._save

    def keep(fig, path):
        figures[path.name] = {"title": fig._suptitle.get_text() if fig._suptitle else "",
                              "axes": [_artists(ax) for ax in fig.axes]}
        return save(fig, path)

    monkeypatch.setattr(plots, "_save", keep)
    return figures


def _artists(ax) -> dict:
    return {"title": ax.get_title(),
            "scatter": {c.get_label(): np.asarray(c.get_offsets()) for c in ax.collections},
            "vlines": [float(line.get_xdata()[0]) for line in ax.lines if len(set(line.get_xdata())) == 1],
            "texts": [t.get_text().strip() for t in ax.texts]}


def _table(text: str, header: str) -> list[tuple[float, str, str]]:
    """(frequency, kind, rest) of the rows printed under the section starting with ``header``."""
    lines = text.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith(header))
    rows = []
    for line in lines[start + 1:]:
        if not line.startswith("  "):
            break
        m = _ROW.match(line)
        if m:
            rows.append((float(m.group(1)), m.group(2), m.group(3).strip()))
    return rows


def test_demo_identification_reports_the_stable_poles_it_draws_and_no_structural_line_the_model_lacks(
        demo_record, drawn, tmp_path, capsys):
    model, case, rec = demo_record
    res = cli._demo_identification(rec, model, case, tmp_path)
    out = capsys.readouterr().out

    # 1. the stabilisation diagram's stable poles are exactly the poles of the SSI modes the table reports
    diagram = drawn["stabilization.png"]["axes"][0]
    stable = next((xy for lab, xy in diagram["scatter"].items() if lab.startswith("stable pole of a reported")),
                  np.zeros((0, 2)))
    ssi_rows = _table(out, "SSI-COV:")
    structural_ssi = [r for r in ssi_rows if r[1] != "harmonic"]
    assert len(structural_ssi) >= 1, out  # 5 minutes of OLC 7 give SSI modes: the check is not vacuous
    assert len(structural_ssi) == len(res.ssi.frequencies_hz_)
    printed = np.array([r[0] for r in structural_ssi])
    # each reported mode is the median of the poles the estimator assigned to it, one per order, enough orders (by
    # the estimator's own assignment: two modes 0.01 Hz apart can have poles nearer the other's median), and the
    # table prints those medians
    freqs = np.asarray(res.ssi.frequencies_hz_)
    for k, f in enumerate(freqs):
        mine = np.array([(float(fp), float(r["order"])) for r in res.ssi.stabilization_
                         for fp, m in zip(np.asarray(r["frequencies_hz"]), np.asarray(r["mode"]), strict=True)
                         if m == k])
        assert len(mine) == res.ssi.n_stable_[k] >= res.ssi.min_stable_
        assert np.median(mine[:, 0]) == pytest.approx(f, rel=1e-9)
        assert len(set(mine[:, 1])) == len(mine)
    assert np.sort(printed) == pytest.approx(np.sort(freqs), abs=6e-5)
    # ... and every pole the estimator calls part of a mode is drawn as such, nothing else
    expected = sorted((float(f), float(r["order"])) for r in res.ssi.stabilization_
                      for f in np.asarray(r["frequencies_hz"])[np.asarray(r["mode"]) >= 0])
    drawn = np.array(sorted(map(tuple, stable.tolist())), dtype=float).reshape(-1, 2)
    np.testing.assert_allclose(drawn, np.array(expected, dtype=float).reshape(-1, 2), rtol=1e-6)
    assert f"{res.ssi.min_stable_} of {res.ssi.orders_.size} orders" in out
    # the lines the diagram draws for reported modes are at the printed frequencies
    assert sorted(diagram["vlines"]) and all(np.min(np.abs(np.array(diagram["vlines"]) - f)) < 6e-5 for f in printed)

    # 2. nothing printed "structural" is more than 10 % from a mode of the model at this load case
    modal = model.modal_analysis(case)  # the modes that can show as a line (not the overdamped blade flap)
    model_f = np.array(modal.frequencies_hz)[np.array(modal.damping_ratios) < OVERDAMPED_LINE]
    dmd_rows = _table(out, "Hankel-DMD:")
    assert dmd_rows, out
    for f, kind, rest in dmd_rows + ssi_rows:
        nearest = np.min(np.abs(f - model_f) / model_f)
        if kind == "structural":
            assert nearest <= 0.10, (f, rest)
            assert rest.strip("()") in model.modal_analysis(case).labels  # and it names that mode
        elif kind == "unmodelled":
            assert nearest > 0.10, (f, kind)
        elif kind == "rotor_band":  # far from every mode, or inside the 3P band that holds no mode of the model
            in_3p = 0.53 < f < 0.66 and not np.any((model_f > 0.53) & (model_f < 0.66))
            assert nearest > 0.10 or in_3p, (f, kind)
    # the 3P band of a turbulent rotor (0.55-0.65 Hz here) is no structural mode, and says what it is
    for f, kind, _ in dmd_rows:
        if 0.53 < f < 0.66:
            assert kind in ("rotor_band", "harmonic", "noise"), (f, kind)
    for kind in {r[1] for r in dmd_rows + ssi_rows} & {"rotor_band", "unmodelled"}:
        assert f"{kind}: " + KIND_MEANING[kind].format(tol="10") in out


def test_demo_psd_marks_the_modes_of_the_load_case(demo_record, drawn, tmp_path):
    model, case, rec = demo_record
    modes = model.modal_analysis(case)
    cli._demo_psd(rec.select(["TwHt9ALxt", "TwHt9ALyt"]), modes, case, tmp_path)
    fig = drawn["psd_tower_top_acceleration.png"]
    assert "parked" not in fig["title"] and f"linear model at {case.name}" in fig["title"]
    shown = [(lab, f) for lab, f in zip(modes.labels, modes.frequencies_hz, strict=True) if f <= 3.0]
    for ax in fig["axes"]:
        for lab, f in shown:
            assert lab in ax["texts"]
            assert np.min(np.abs(np.array(ax["vlines"]) - f)) < 1e-9


def test_label_against_model_keeps_what_the_model_has_and_names_the_rest():
    model_modes = [("pitch", 0.03), ("tower_fa_1", 0.49), ("tower_fa_2", 2.55)]
    rows = [{"frequency_hz": f, "kind": k} for f, k in
            [(0.52, "structural"), (0.60, "structural"), (0.61, "harmonic"), (1.5, "structural"),
             (2.31, "structural"), (2.90, "structural"), (4.0, "noise")]]
    bands = rotor_bands(12.0 / 60.0 * np.linspace(0.95, 1.05, 1001))  # 12 rpm +- 5 %: 3P sweeps 0.57-0.63 Hz
    assert bands[1] == pytest.approx((0.19, 0.21), rel=2e-3) and bands[3] == pytest.approx((0.57, 0.63), rel=2e-3)
    label_against_model(rows, model_modes, 0.1, bands)
    assert [r["kind"] for r in rows] == ["structural", "rotor_band", "harmonic", "unmodelled", "structural",
                                         "unmodelled", "noise"]
    assert rows[0]["model_mode"] == "tower_fa_1" and rows[4]["model_mode"] == "tower_fa_2"
    assert rows[1]["rotor_order"] == 3 and "model_mode" not in rows[1]
    # without a rotor speed, the same line is only known not to be a model mode
    again = label_against_model([{"frequency_hz": 0.60, "kind": "structural"}], model_modes, 0.1, None)
    assert again[0]["kind"] == "unmodelled"
    # a mode within 10 % of the band's foot (0.53 Hz against 0.57-0.63 Hz): a line inside the band is the band's,
    # one between the mode and the band the mode's, and a mode inside the band keeps the lines near it
    near = [("tower_fa_1", 0.53)]
    rows = label_against_model([{"frequency_hz": f, "kind": "structural"} for f in (0.58, 0.55)], near, 0.1, bands)
    assert [r["kind"] for r in rows] == ["rotor_band", "structural"] and rows[0]["rotor_order"] == 3
    inside = label_against_model([{"frequency_hz": 0.59, "kind": "structural"}], [("blade", 0.60)], 0.1, bands)
    assert inside[0]["kind"] == "structural" and inside[0]["model_mode"] == "blade"
