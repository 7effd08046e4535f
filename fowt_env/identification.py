"""Output-only identification of a record: Hankel-DMD and SSI-COV side by side, optionally against a linear model.

:func:`identify` takes a :class:`surrogates.Record` (simulated, OpenFAST or field data), band-passes and z-scores
the chosen channels as the seed paper does (4th-order Butterworth 0.25-5 Hz, zero phase), and runs

* :class:`estimators.HankelDMD` (mode table with structural / harmonic / noise labels), and
* :class:`estimators.SSICov` (stabilisation diagram, stable poles),

both on the same data (with a linear reference, a line labelled ``"structural"`` by either method that lies
more than ``max_freq_rel``, 10 %, from every mode of the model is relabelled by what it is: ``"rotor_band"``
inside the band a rotor harmonic sweeps, else ``"unmodelled"``), and, when the record carries the rotor speed
(``RotSpeed``), finds the rotor harmonics (1P, 3P, 6P) by Hankel-DMD in the order domain
(:func:`estimators.rotor_harmonics`): a 3P load on a rotor whose speed follows the turbulence is a band in time
but a line at order 3 in azimuth. Mode shapes are returned in the record's physical units (the z-scoring is
undone), so they compare directly with the output shapes ``C v`` of a linear model: :func:`linear_reference`
gives those for a ``control.StateSpace`` (e.g. ``FOWTModel.linearize(case, plane="FA")``) and :func:`identify`
pairs every method's modes with them (frequency and MAC) when a reference is given -- the seed paper's Table 3.

:meth:`IdentificationResult.plot` draws the figures people look at: the stabilisation diagram over the PSD,
the DMD eigenvalues on the unit circle, the singular-value spectrum with the chosen rank, and a spectrogram
with the rotor harmonics' tracks over it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import signal

from estimators.hankel_dmd import HankelDMD
from estimators.modal import mac, pair_modes
from estimators.order_tracking import rotor_azimuth, rotor_harmonics
from estimators.preprocess import Preprocessor
from estimators.ssi_cov import SSICov

from .progress import progress_bar

__all__ = [
    "KIND_MEANING",
    "ROTOR_ORDERS",
    "IdentificationResult",
    "LinearReference",
    "OVERDAMPED_LINE",
    "identify",
    "label_against_model",
    "linear_reference",
    "model_reference",
    "rotor_bands",
]

_TOWER_PREFIX = "TwHt"
OVERDAMPED_LINE = 0.45
"""Damping ratio (-) above which a model mode has no resonance peak to show as a spectral line (peak gain
``1 / (2 zeta sqrt(1 - zeta^2))`` below 1.25): such a mode is not offered as the meaning of a data line."""


@dataclass(frozen=True)
class LinearReference:
    """Modes of a linear state-space model seen at its outputs.

    Attributes
    ----------
    frequencies_hz : ndarray (n_modes,)
        Damped natural frequencies (Hz) of the oscillatory poles, ascending.
    damping_ratios : ndarray (n_modes,)
        Damping ratios (-).
    shapes : ndarray (n_outputs, n_modes) complex
        Output mode shapes ``C v`` (the free response of mode j is ``Re(C v e^(lambda t))``), output units.
    labels : list of str
        Mode names if known (else ``mode_1`` ...).
    channels : list of str
        Output names.
    model_modes : tuple of (str, float)
        Every mode of the model at its operating point as (label, frequency in Hz), whatever its plane or band
        (platform, both tower planes): the modes :func:`identify`'s labelling rule measures distances to. Empty:
        the reference's own modes.
    """

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    shapes: np.ndarray
    labels: list[str]
    channels: list[str]
    model_modes: tuple[tuple[str, float], ...] = ()

    def all_modes(self) -> list[tuple[str, float]]:
        """(label, frequency in Hz) of every model mode: :attr:`model_modes`, else the reference's own modes."""
        if self.model_modes:
            return [(str(lab), float(f)) for lab, f in self.model_modes]
        return [(lab, float(f)) for lab, f in zip(self.labels, self.frequencies_hz, strict=True)]


def linear_reference(system: Any, *, labels: dict[str, float] | None = None, f_min: float = 0.0,
                     f_max: float = np.inf) -> LinearReference:
    """Modal frequencies, damping and output mode shapes of a continuous-time linear model.

    Parameters
    ----------
    system : control.StateSpace
        Continuous-time model with named outputs (``FOWTModel.linearize(case, plane=...)``).
    labels : dict of str to float, optional
        Known mode names and frequencies (Hz), e.g. from ``FOWTModel.modal_analysis``; each pole takes the label
        of the nearest frequency within 5 %, others are called ``mode_<k>``.
    f_min, f_max : float
        Keep poles with damped frequency in this range (Hz).

    Returns
    -------
    LinearReference
    """
    A = np.asarray(system.A, dtype=float)
    C = np.asarray(system.C, dtype=float)
    lam, vec = np.linalg.eig(A)
    keep = (lam.imag > 1e-9) & (lam.imag / (2 * np.pi) >= f_min) & (lam.imag / (2 * np.pi) <= f_max)
    lam, vec = lam[keep], vec[:, keep]
    order = np.argsort(lam.imag)
    lam, vec = lam[order], vec[:, order]
    shapes = C @ vec
    freqs = lam.imag / (2 * np.pi)
    zetas = -lam.real / np.abs(lam)
    names: list[str] = []
    known = dict(labels or {})
    for k, f in enumerate(freqs):
        near = [(abs(fk - f) / fk, lab) for lab, fk in known.items() if fk > 0 and abs(fk - f) <= 0.05 * fk]
        if near:
            lab = min(near)[1]
            names.append(lab)
            known.pop(lab)
        else:
            names.append(f"mode_{k + 1}")
    channels = list(getattr(system, "output_labels", [f"y{i}" for i in range(C.shape[0])]))
    return LinearReference(freqs, zetas, shapes, names, channels)


def model_reference(model: Any, case: Any = None, plane: str | None = None) -> LinearReference:
    """The linear reference of a :class:`surrogates.FOWTModel`: its tower modes seen at the tower channels.

    Parameters
    ----------
    model : surrogates.FOWTModel
    case : int or surrogates.LoadCase, optional
        Operating point (None: parked, still water).
    plane : {"FA", "SS"}, optional
        Keep the 18 channels of that plane and the tower modes of that plane (the other plane's modes are
        invisible, or nearly so, in its channels); None: all outputs and all tower modes.

    Returns
    -------
    LinearReference
        Tower modes labelled as :meth:`FOWTModel.modal_analysis` names them (the platform modes lie below the
        identification band); :attr:`~LinearReference.model_modes` lists every mode of the modal analysis at
        ``case`` (platform, both tower planes, the blades' flap) that can show as a spectral line (damping ratio
        below :data:`OVERDAMPED_LINE`).
    """
    modes = model.modal_analysis(case)
    wanted = {lab: f for lab, f in zip(modes.labels, modes.frequencies_hz, strict=True) if lab.startswith("tower_")}
    ref = linear_reference(model.linearize(case, plane=plane), labels=wanted, f_min=0.5 * min(wanted.values()))
    keep = [k for k, lab in enumerate(ref.labels) if lab in wanted
            and (plane is None or lab.startswith(f"tower_{plane.lower()}_"))]
    # a mode damped beyond OVERDAMPED_LINE (the operating rotor's blade flap, ~54 %) has no resonance peak (gain
    # at most 1 / (2 zeta sqrt(1 - zeta^2)) < 1.25): no spectral line of the data can be it
    every = tuple((str(lab), float(f)) for lab, f, z in zip(modes.labels, modes.frequencies_hz,
                                                           modes.damping_ratios, strict=True) if z < OVERDAMPED_LINE)
    return LinearReference(ref.frequencies_hz[keep], ref.damping_ratios[keep], ref.shapes[:, keep],
                           [ref.labels[k] for k in keep], ref.channels, model_modes=every)


@dataclass
class IdentificationResult:
    """What :func:`identify` found. ``dmd`` and ``ssi`` are the fitted estimators themselves.

    Attributes
    ----------
    channels : list of str
        Channels used (in the order of the mode-shape rows).
    units : list of str
        Their units.
    dt : float
        Sample interval (s).
    band : tuple of float
        Band-pass corners (Hz).
    scale : ndarray (n_channels,)
        Standard deviation of each band-passed channel (channel units): the z-score that the shapes undo.
    dmd : estimators.HankelDMD
    ssi : estimators.SSICov or None
    dmd_modes : list of dict
        :meth:`HankelDMD.mode_table` rows (``frequency_hz``, ``damping_ratio``, ``energy``, ``phase_locking``,
        ``kind``, ``index``); with a reference, checked by :func:`label_against_model` (kinds
        ``"rotor_band"`` and ``"unmodelled"`` besides the table's own, ``model_mode`` / ``rotor_order``).
    ssi_modes : list of dict
        :meth:`SSICov.mode_table` rows, checked the same way: the modes made of the stabilisation diagram's
        filled poles (stable at ``ssi.min_stable_`` orders or more) and the harmonic lines.
    reference : LinearReference or None
    pairs : dict of str to list of dict
        For each method (``"dmd"``, ``"ssi"``), the reference modes paired with its modes: ``label``,
        ``f_ref``, ``zeta_ref``, ``f``, ``zeta``, ``freq_rel_error``, ``mac``.
    harmonics : list of dict or None
        Rotor harmonics found by Hankel-DMD in the order domain (:func:`estimators.rotor_harmonics` rows:
        ``order``, ``frequency_hz`` at the mean rotor speed, ``frequency_range_hz`` swept in time,
        ``damping_ratio``, ``phase_locking``, ``energy``, ``kind``); None when no order tracking was done.
    rotor_speed_source : str
        Where the rotor speed came from (a channel name, ``"array"``), or why there are no harmonics.
    max_freq_rel : float
        Tolerance of the pairing and of the check of structural lines against the model.
    """

    channels: list[str]
    units: list[str]
    dt: float
    band: tuple[float, float]
    scale: np.ndarray
    dmd: HankelDMD
    ssi: SSICov | None
    dmd_modes: list[dict]
    ssi_modes: list[dict]
    reference: LinearReference | None = None
    pairs: dict[str, list[dict]] = field(default_factory=dict)
    harmonics: list[dict] | None = None
    rotor_speed_source: str = "not requested"
    max_freq_rel: float = 0.1
    _spectrogram_channel: str | None = None
    _y: np.ndarray | None = None
    _rotor_hz: np.ndarray | None = None

    # ------------------------------------------------------------------------------------------ shapes
    def dmd_shape(self, index: int) -> np.ndarray:
        """Physical-unit mode shape (complex, n_channels) of DMD eigenvalue ``index``."""
        return self.dmd.modes_[:, index] * self.scale

    def ssi_shape(self, index: int) -> np.ndarray:
        """Physical-unit mode shape (complex, n_channels) of SSI mode ``index``."""
        if self.ssi is None:
            raise ValueError("SSI-COV was not run (identify(..., ssi=False))")
        return self.ssi.modes_[:, index] * self.scale

    # ------------------------------------------------------------------------------------------ output
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: settings, both mode tables and the pairing with the reference."""
        out: dict[str, Any] = {
            "channels": self.channels,
            "dt": self.dt,
            "band_hz": list(self.band),
            "dmd": {"delays": int(self.dmd.delays_), "rank": int(self.dmd.rank_), "method": self.dmd.method_,
                    "modes": self.dmd_modes},
        }
        if self.ssi is not None:
            out["ssi"] = {"modes": self.ssi_modes}
        out["rotor_harmonics"] = {"rotor_speed": self.rotor_speed_source, "lines": self.harmonics}
        if self.reference is not None:
            out["reference"] = [
                {"label": lab, "frequency_hz": float(f), "damping_ratio": float(z)}
                for lab, f, z in zip(self.reference.labels, self.reference.frequencies_hz,
                                     self.reference.damping_ratios, strict=True)
            ]
            out["pairs"] = self.pairs
        return out

    def summary(self, kinds: tuple[str, ...] = ("structural", "harmonic", "rotor_band", "unmodelled")) -> str:
        """A readable table: DMD modes of the given kinds, SSI-COV modes, and the reference pairing.

        Parameters
        ----------
        kinds : tuple of str
            DMD kinds to list (default all but ``"noise"``).

        Returns
        -------
        str
            The DMD lines with their kind (and, with a reference, the model mode each structural line is
            nearest to, or the rotor order of a rotor band), the SSI-COV modes -- exactly the clusters of the
            stabilisation diagram's filled poles, with the orders at which each is stable -- and the pairing.
        """
        d, h = self.dmd.delays_, self.dmd.dt_
        lines = [f"Hankel-DMD: delays {d} samples ({d * h:.2f} s at {1 / h:.0f} Hz), rank {self.dmd.rank_} "
                 f"({self.dmd.method_}), {len(self.channels)} channels"]
        lines.append(f"  {'f (Hz)':>8} {'zeta (%)':>9} {'energy':>7} {'locking':>8}  kind")
        shown: set[str] = set()
        for row in self.dmd_modes:
            if row["kind"] in kinds:
                shown.add(row["kind"])
                lines.append(f"  {row['frequency_hz']:8.4f} {100 * row['damping_ratio']:9.2f} {row['energy']:7.3f} "
                             f"{row['phase_locking']:8.2f}  {_kind_text(row)}")
        if self.harmonics is None:
            lines.append(f"Rotor harmonics: not tracked ({self.rotor_speed_source})")
        else:
            lines.append(f"Rotor harmonics (Hankel-DMD at equal azimuth steps, speed from {self.rotor_speed_source}):"
                         f" {len(self.harmonics)}")
            lines.append(f"  {'order':>6} {'f (Hz)':>8} {'sweeps (Hz)':>13} {'locking':>8}")
            for row in self.harmonics:
                lo, hi = row["frequency_range_hz"]
                lines.append(f"  {row['order']:6.2f} {row['frequency_hz']:8.4f} {lo:6.3f}-{hi:<6.3f} "
                             f"{row['phase_locking']:8.2f}")
        if self.ssi is not None:
            n_orders = int(self.ssi.orders_.size)
            loose = sum(int(np.count_nonzero(np.asarray(r["stable"]) & (np.asarray(r["mode"]) < 0)))
                        for r in self.ssi.stabilization_)
            lines.append(f"SSI-COV: {len(self.ssi_modes)} modes and lines (each from poles stable at >= "
                         f"{self.ssi.min_stable_} of {n_orders} orders: the filled poles of the stabilisation "
                         "diagram)")
            if not self.ssi_modes:
                lines.append("  (no pole stable over the model orders: a longer record usually helps)")
            else:
                lines.append(f"  {'f (Hz)':>8} {'zeta (%)':>9} {'orders':>7}  kind")
            for row in self.ssi_modes:
                shown.add(row["kind"])
                lines.append(f"  {row['frequency_hz']:8.4f} {100 * row['damping_ratio']:9.2f} {row['n_stable']:7d}"
                             f"  {_kind_text(row)}")
            if loose:
                lines.append(f"  ({loose} further poles passed the stability test against the next lower order "
                             "but form no mode: hollow in the diagram)")
        relabelled = sorted(shown & {"rotor_band", "unmodelled"})
        for kind in relabelled:
            lines.append(f"{kind}: " + KIND_MEANING[kind].format(tol=f"{100 * self.max_freq_rel:g}"))
        if self.reference is not None:
            lines.append("Against the linear reference (f in Hz, zeta in %, MAC of output shapes):")
            head = f"  {'mode':<12}{'f_lin':>8}{'z_lin':>7}"
            methods = [m for m in ("ssi", "dmd") if m in self.pairs]
            for m in methods:
                head += f"{'f_' + m:>9}{'z_' + m:>7}{'MAC':>6}"
            lines.append(head)
            for k, lab in enumerate(self.reference.labels):
                row = (f"  {lab:<12}{self.reference.frequencies_hz[k]:8.3f}"
                       f"{100 * self.reference.damping_ratios[k]:7.2f}")
                for m in methods:
                    hit = next((p for p in self.pairs[m] if p["label"] == lab), None)
                    row += (f"{hit['f']:9.3f}{100 * hit['zeta']:7.2f}{hit['mac']:6.2f}" if hit
                            else f"{'-':>9}{'-':>7}{'-':>6}")
                lines.append(row)
        return "\n".join(lines)

    def plot(self, folder: str | Path, *, progress: bool | None = False) -> list[Path]:
        """Write the identification figures (PNG) into ``folder``; returns their paths.

        Parameters
        ----------
        folder : str or Path
            Created if needed.
        progress : bool or None
            Progress bar of the figures on stderr (:func:`fowt_env.progress.progress_bar`): True, False
            (default), None = on a terminal, after 2 s.

        Returns
        -------
        list of Path
        """
        from .plots import (
            eigenvalue_figure,
            singular_value_figure,
            spectrogram_figure,
            stabilization_figure,
        )
        from .progress import progress_bar

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        jobs: list[tuple[str, Callable[[], Path]]] = [
            ("DMD eigenvalues", lambda: eigenvalue_figure(self.dmd, self.dmd_modes, folder / "dmd_eigenvalues.png")),
            ("singular values", lambda: singular_value_figure(self.dmd, folder / "singular_values.png"))]
        if self.ssi is not None and self._y is not None:
            jobs.append(("stabilisation diagram", lambda: stabilization_figure(
                self.ssi, self._y, self.dt, folder / "stabilization.png", reference=self.reference)))
        if self._y is not None and self._spectrogram_channel is not None:
            j = self.channels.index(self._spectrogram_channel)
            tracks = None
            if self.harmonics and self._rotor_hz is not None:
                tracks = {f"{row['order']:.0f}P": row["order"] * self._rotor_hz for row in self.harmonics}
            jobs.append(("spectrogram", lambda: spectrogram_figure(
                self._y[:, j], self.dt, self._spectrogram_channel, self.units[j], folder / "spectrogram.png",
                tracks=tracks)))
        paths = []
        with progress_bar(len(jobs), "figures", unit="figures", progress=progress) as bar:
            for name, job in jobs:
                bar.set_postfix_str(name, refresh=False)
                paths.append(job())
                bar.update(1)
        return paths


def _kind_text(row: dict) -> str:
    """A mode-table row's kind as the summary prints it: ``structural (tower_fa_1)``, ``rotor_band (3P)``."""
    if row.get("model_mode"):
        return f"{row['kind']} ({row['model_mode']})"
    if row.get("rotor_order"):
        return f"{row['kind']} ({row['rotor_order']}P)"
    return str(row["kind"])


def _default_channels(record: Any, plane: str | None) -> list[str]:
    if plane is not None:
        return record.planar(plane).channels
    tower = [c for c in record.channels if c.startswith(_TOWER_PREFIX)]
    return tower or list(record.channels)


def _pair(reference: LinearReference, freqs: np.ndarray, zetas: np.ndarray, shapes: np.ndarray,
          max_freq_rel: float) -> list[dict]:
    if freqs.size == 0:
        return []
    found = pair_modes(reference.frequencies_hz, reference.shapes, freqs, shapes, max_freq_rel=max_freq_rel)
    out = []
    for p in found:
        a, b = p["index_a"], p["index_b"]
        out.append({"label": reference.labels[a], "f_ref": float(reference.frequencies_hz[a]),
                    "zeta_ref": float(reference.damping_ratios[a]), "f": float(freqs[b]), "zeta": float(zetas[b]),
                    "freq_rel_error": float(p["freq_rel_error"]),
                    "mac": float(mac(reference.shapes[:, a], shapes[:, b]))})
    return sorted(out, key=lambda p: p["f_ref"])


_SPEED_UNITS = {"rpm": np.pi / 30.0, "rad/s": 1.0}

#: Rotor orders whose swept band names a line that no model mode explains: 1P and blade passing (3P, 6P), the
#: lines the demo's PSD marks.
ROTOR_ORDERS: tuple[int, ...] = (1, 3, 6)

#: What each kind of an identified line means (the summary's legend; ``{tol}``: the tolerance in per cent).
KIND_MEANING: dict[str, str] = {
    "structural": "a damped mode of the response (with a reference: within {tol} % of the model mode named)",
    "harmonic": "an undamped, phase-locked forced line",
    "rotor_band": "no model mode within {tol} %; inside the band that rotor harmonic (1P, 3P, 6P) sweeps as the "
                  "rotor speed varies",
    "unmodelled": "no model mode within {tol} % and no rotor band: wave band, band-pass edge or a response the "
                  "linear model lacks",
}


def rotor_bands(rotor_hz: np.ndarray, orders: tuple[int, ...] = ROTOR_ORDERS,
                percentiles: tuple[float, float] = (1.0, 99.0)) -> dict[int, tuple[float, float]]:
    """The frequency bands that rotor harmonics sweep as the rotor speed varies.

    Parameters
    ----------
    rotor_hz : ndarray (n_samples,)
        Rotor speed in revolutions per second (Hz).
    orders : tuple of int
        Harmonic orders (1 = 1P, 3 = blade passing 3P, ...).
    percentiles : (float, float)
        Percentiles of the speed that bound each band (default 1 and 99: a few outlying samples do not widen it).

    Returns
    -------
    dict of int to (float, float)
        ``{order: (f_low, f_high)}`` in Hz.
    """
    lo, hi = np.percentile(np.asarray(rotor_hz, dtype=float), percentiles)
    return {int(k): (float(k * lo), float(k * hi)) for k in orders}


def label_against_model(rows: list[dict], model_modes: list[tuple[str, float]], max_freq_rel: float = 0.1,
                        bands: dict[int, tuple[float, float]] | None = None) -> list[dict]:
    """Check the ``"structural"`` rows of a mode table against a model's modes and relabel the ones it lacks.

    A data-driven method calls a line ``"structural"`` when it is damped and carries energy; that is also true of a
    forcing band (the rotor's 3P swept by a turbulent rotor speed, the wave spectrum let through by the band-pass
    edge). With a model at hand the label means what a reader takes it to mean, a mode of the structure, only if
    the model has a mode near it: the same tolerance that pairs identified modes with the reference
    (``max_freq_rel``, 10 % by default) decides.

    Parameters
    ----------
    rows : list of dict
        Mode-table rows with ``frequency_hz`` and ``kind`` (:meth:`HankelDMD.mode_table`,
        :meth:`SSICov.mode_table`); changed in place.
    model_modes : list of (str, float)
        Every mode of the model as (label, frequency in Hz) (:meth:`LinearReference.all_modes`).
    max_freq_rel : float
        Largest relative distance ``|f - f_model| / f_model`` of a line still called structural.
    bands : dict of int to (float, float), optional
        Rotor-harmonic bands (:func:`rotor_bands`); None: no rotor speed known.

    Returns
    -------
    list of dict
        ``rows``: each ``"structural"`` row within ``max_freq_rel`` of a model mode gains ``model_mode`` (the
        nearest mode's label; :func:`identify` then names the reference mode a line is paired with, by frequency
        and shape, instead); the others become ``"rotor_band"`` (with ``rotor_order``, the lowest order whose
        band, widened by ``max_freq_rel``, holds the line) or ``"unmodelled"``. A line inside a rotor band (not
        widened) whose nearest model mode lies outside that band is the band's.
    """
    known = [(lab, f) for lab, f in model_modes if f > 0]
    for row in rows:
        if row["kind"] != "structural":
            continue
        f = float(row["frequency_hz"])
        near = min(known, key=lambda m: abs(f - m[1]) / m[1], default=None)
        # a line inside a rotor band whose nearest model mode lies outside it is the band's (the 3P band of a
        # turbulent rotor sits within 10 % of the operating tower mode)
        inside = next((k for k, (lo, hi) in sorted((bands or {}).items()) if lo <= f <= hi), None)
        if (inside is not None and near is not None
                and not bands[inside][0] <= near[1] <= bands[inside][1]):
            row["kind"] = "rotor_band"
            row["rotor_order"] = int(inside)
            continue
        if near is not None and abs(f - near[1]) <= max_freq_rel * near[1]:
            row["model_mode"] = near[0]
            continue
        order = next((k for k, (lo, hi) in sorted((bands or {}).items())
                      if (1 - max_freq_rel) * lo <= f <= (1 + max_freq_rel) * hi), None)
        if order is None:
            row["kind"] = "unmodelled"
        else:
            row["kind"] = "rotor_band"
            row["rotor_order"] = int(order)
    return rows


def _rotor_speed(record: Any, rotor_speed: Any) -> tuple[np.ndarray | None, np.ndarray | None, str]:
    """Rotor speed (rad/s) and azimuth (rad) for order tracking, and where they came from (or why there are none)."""
    if rotor_speed is None:
        return None, None, "not requested"
    auto = isinstance(rotor_speed, str) and rotor_speed == "auto"
    if isinstance(rotor_speed, str):
        name = "RotSpeed" if auto else rotor_speed
        if name not in record.channels:
            if auto:
                return None, None, "the record has no RotSpeed channel"
            raise ValueError(f"rotor_speed: no channel {name!r} in the record; it has {record.channels}")
        unit = record.units[record.channels.index(name)].strip().lower()
        if unit not in _SPEED_UNITS:
            raise ValueError(f"rotor_speed: channel {name!r} is in {unit!r}; expected one of {list(_SPEED_UNITS)}")
        w = np.asarray(record.select([name]).y[:, 0], dtype=float) * _SPEED_UNITS[unit]
        source = name
    else:
        w = np.asarray(rotor_speed, dtype=float)
        if w.shape != (record.n_samples,):
            raise ValueError(f"rotor_speed must be a channel name or an array of shape ({record.n_samples},) in "
                             f"rad/s, got shape {w.shape}")
        source = "array"
    try:
        psi = rotor_azimuth(w, float(record.dt))  # a clear error if not finite or not turning
    except ValueError:
        if not auto:
            raise
        return None, None, f"{source} is not finite and > 0 throughout (rotor parked, idling or stopping)"
    return w, psi, source


def identify(
    record: Any,
    *,
    channels: list[str] | None = None,
    plane: str | None = None,
    band: tuple[float, float] = (0.25, 5.0),
    delays: int | float = 2.5,
    rank: int | float | str = 24,
    decimate: bool = True,
    ssi: bool = True,
    ssi_block_rows: int | None = None,
    ssi_orders: Any = None,
    reference: LinearReference | None = None,
    max_freq_rel: float = 0.1,
    rotor_speed: str | np.ndarray | None = "auto",
    progress: bool | None = False,
) -> IdentificationResult:
    """Identify modes of a record with Hankel-DMD and SSI-COV, optionally paired with a linear reference.

    Parameters
    ----------
    record : surrogates.Record
        The measured or simulated record (any sample rate; channels in physical units).
    channels : list of str, optional
        Channels to use. Default: the tower channels of ``plane`` if given, else all tower channels (``TwHt*``),
        else all channels.
    plane : {"FA", "SS"}, optional
        Use the seed paper's 18 channels of that plane (accelerations then moments, gauges 1-9).
    band : (float, float)
        Band-pass corners (Hz) of the zero-phase 4th-order Butterworth filter; the upper corner is capped below
        Nyquist.
    delays : int or float
        Hankel-DMD delay depth: samples at the (decimated) analysis rate (int) or seconds (float; default 2.5 s,
        more than one period of the 1st tower modes). The seed paper's 60 samples at 80 Hz span 0.75 s, less
        than one period of a 0.48 Hz mode; on surrogate data they split the 1st fore-aft mode in two lines
        5-7 % either side of it, while 2.5 s finds it within 0.5 %.
    rank : int, float or "auto"
        Hankel-DMD rank (the seed paper identifies with 24).
    decimate : bool
        Decimate the band-passed data to about four times the upper band corner before both methods (default
        True; 80 Hz -> 20 Hz for the 5 Hz band). Same modes, a fraction of the cost.
    ssi : bool
        Also run SSI-COV.
    ssi_block_rows : int, optional
        SSI-COV block rows at the analysis rate. Default: ``fs / (2 f_low)``, the usual rule, capped so that
        ``block_rows * n_channels <= 1200``.
    ssi_orders : iterable of int, optional
        SSI-COV model orders (default 2, 4, ..., 80).
    reference : LinearReference, optional
        Linear modes to pair with (:func:`linear_reference`); its output names must cover ``channels``. With a
        reference, both mode tables are checked against the model (:func:`label_against_model`): a
        ``"structural"`` line more than ``max_freq_rel`` from every model mode
        (:meth:`LinearReference.all_modes`) becomes ``"rotor_band"`` or ``"unmodelled"``, the others name
        their ``model_mode``; only lines still ``"structural"`` are paired.
    max_freq_rel : float
        Largest relative frequency difference accepted when pairing with the reference, and between a line
        called structural and its nearest model mode (default 10 %).
    rotor_speed : "auto", str, ndarray or None
        Rotor speed for the order-tracked harmonics: a channel name (units rpm or rad/s), an array
        ``(n_samples,)`` in rad/s, ``None`` (skip), or ``"auto"`` (default): the ``RotSpeed`` channel if the
        record has one and the rotor turns throughout (a parked or idling record is skipped, with the reason
        in :attr:`IdentificationResult.rotor_speed_source`).
    progress : bool or None
        Progress of the steps (band-pass, Hankel-DMD, SSI-COV, order tracking) with an ETA on standard error
        (:func:`fowt_env.progress.progress_bar`): True, False (default) or None (when it is a terminal).

    Returns
    -------
    IdentificationResult

    Raises
    ------
    ValueError
        Unknown channels, a band above Nyquist, NaN in the data, too short a record, a reference without
        the channels, or an explicit rotor speed that is unknown, of the wrong length or unit, or not turning.
    """
    names = list(channels) if channels is not None else _default_channels(record, plane)
    missing = [c for c in names if c not in record.channels]
    if missing:
        raise ValueError(f"channels: not in the record: {missing}; it has {record.channels}")
    if reference is not None:
        absent = [c for c in names if c not in reference.channels]
        if absent:
            raise ValueError(f"reference: the linear model has no outputs {absent}")
    sub = record.select(names)
    dt = float(record.dt)
    speed, azimuth, speed_source = _rotor_speed(record, rotor_speed)
    nyq = 0.5 / dt
    lo, hi = (float(b) for b in band)
    if not 0 < lo < nyq:
        raise ValueError(f"band: lower corner {lo} Hz must be in (0, Nyquist = {nyq} Hz)")
    hi = min(hi, 0.9 * nyq)
    Y = np.asarray(sub.y, dtype=float)
    stages = ["band-pass", "Hankel-DMD"] + ["SSI-COV"] * bool(ssi) + ["order tracking"] * (azimuth is not None)
    with progress_bar(len(stages), "identify", progress=progress) as bar:
        bar.set_postfix_str(stages[0])
        res = _identify_steps(Y, sub, names, dt, lo, hi, delays, rank, decimate, ssi, ssi_block_rows, ssi_orders,
                              speed, azimuth, speed_source, max_freq_rel, stages, bar)
    if reference is not None:
        _check_against(res, reference, speed, max_freq_rel)
    return res


def _identify_steps(Y: np.ndarray, sub: Any, names: list[str], dt: float, lo: float, hi: float, delays: int | float,
                    rank: int | float | str, decimate: bool, ssi: bool, ssi_block_rows: int | None, ssi_orders: Any,
                    speed: np.ndarray | None, azimuth: np.ndarray | None, speed_source: str, max_freq_rel: float,
                    stages: list[str], bar: Any) -> IdentificationResult:
    """:func:`identify`'s computation, advancing ``bar`` after each of ``stages``."""

    def done(k: int) -> None:
        bar.update(1)
        if k + 1 < len(stages):
            bar.set_postfix_str(stages[k + 1])

    nyq = 0.5 / dt
    pre = Preprocessor(fs=1.0 / dt, band=(lo, hi))
    Z = pre.fit_transform(Y)
    filtered_std = pre.std_
    # the band-passed data carry nothing above `hi`: decimate to ~4x `hi` (cheaper SVDs, longer delays per row)
    q = max(1, int(np.floor(nyq / (2.0 * hi) + 1e-6))) if decimate else 1
    Zd = signal.decimate(Z, q, ftype="fir", axis=0, zero_phase=True) if q > 1 else Z
    dt_d = dt * q
    if isinstance(delays, float):
        delays = max(1, int(round(delays / dt_d)))
    done(0)
    dmd = HankelDMD(delays=delays, rank=rank, dt=dt_d).fit(Zd)
    dmd_modes = dmd.mode_table()
    done(1)
    ssi_est = None
    ssi_modes: list[dict] = []
    if ssi:
        if ssi_block_rows is None:
            ssi_block_rows = int(np.clip(np.ceil(1.0 / (2.0 * lo * dt_d)), 10, max(10, 1200 // Z.shape[1])))
        kwargs: dict[str, Any] = {"block_rows": ssi_block_rows, "freq_range_hz": (lo, hi)}
        kwargs["orders"] = (range(2, min(80, (ssi_block_rows - 1) * Z.shape[1]) + 1, 2) if ssi_orders is None
                            else ssi_orders)
        ssi_est = SSICov(dt_d, **kwargs).fit(Zd)
        ssi_modes = ssi_est.mode_table()
        done(2)
    harmonics = None
    if azimuth is not None:
        depths = tuple(sorted({max(2, int(round(f * delays))) for f in (0.8, 1.0, 1.2)}))
        harmonics = rotor_harmonics(Zd, dt_d, azimuth=azimuth[::q], delays=depths, rank=rank)
        done(len(stages) - 1)
    return IdentificationResult(names, [sub.units[i] for i in range(len(names))], dt, (lo, hi), filtered_std, dmd,
                               ssi_est, dmd_modes, ssi_modes, harmonics=harmonics, rotor_speed_source=speed_source,
                               max_freq_rel=float(max_freq_rel),
                               _rotor_hz=None if speed is None else speed / (2.0 * np.pi), _y=Y,
                               _spectrogram_channel=next((c for c in reversed(names) if c.endswith("ALxt") or
                                                          c.endswith("ALyt")), names[0]))


def _check_against(res: IdentificationResult, reference: LinearReference, speed: np.ndarray | None,
                   max_freq_rel: float) -> None:
    """Label ``res``'s mode tables against the model and pair them with ``reference`` (in place)."""
    names, dmd, ssi_est = res.channels, res.dmd, res.ssi
    dmd_modes, ssi_modes, filtered_std = res.dmd_modes, res.ssi_modes, res.scale
    rows = [reference.channels.index(c) for c in names]
    ref = LinearReference(reference.frequencies_hz, reference.damping_ratios, reference.shapes[rows],
                          reference.labels, names, model_modes=reference.model_modes)
    res.reference = ref
    bands = None if speed is None else rotor_bands(speed / (2.0 * np.pi))
    label_against_model(dmd_modes, ref.all_modes(), max_freq_rel, bands)
    label_against_model(ssi_modes, ref.all_modes(), max_freq_rel, bands)
    structural = [r["index"] for r in dmd_modes if r["kind"] == "structural"]
    res.pairs["dmd"] = _pair(ref, np.abs(dmd.frequencies_hz_[structural]), dmd.damping_ratios_[structural],
                             dmd.modes_[:, structural] * filtered_std[:, None], max_freq_rel)
    if ssi_est is not None:
        kept = [r["index"] for r in ssi_modes if r["kind"] == "structural"]
        res.pairs["ssi"] = _pair(ref, np.asarray(ssi_est.frequencies_hz_)[kept],
                                 np.asarray(ssi_est.damping_ratios_)[kept],
                                 np.asarray(ssi_est.modes_)[:, kept] * filtered_std[:, None], max_freq_rel)
    for method, table in (("dmd", dmd_modes), ("ssi", ssi_modes)):  # a paired line names its reference mode
        for pair in res.pairs.get(method, []):
            for row in table:
                if row["kind"] == "structural" and np.isclose(row["frequency_hz"], pair["f"], rtol=1e-12):
                    row["model_mode"] = pair["label"]
