"""Make the compact OpenFAST reference data that ``fowt-env validate`` uses by default.

Reads the OpenFAST OC3 Hywind runs of the shared reference folder (``<run>/<run>.outb`` + ``<run>.case.json``),
and writes to ``fowt_env/data/openfast_reference/``:

- ``<run>.npz``: a :class:`surrogates.Record` (fowt-env record format) of the channels the validation compares,
  anti-alias filtered (zero-phase polyphase FIR, ``scipy.signal.resample_poly``) and decimated from 80 Hz to
  10 Hz (operating runs and platform decays) or 20 Hz (the tower decay), values rounded to float32 precision;
- ``<run>.case.json``: a copy of the run's conditions;
- ``<run>.inflow.npz`` (turbulent runs that have one): the run's inflow beside its record -- hub u/v/w, disc
  mean and the streamwise wind on the polar grid over the rotor (5 radii x 16 azimuths) -- anti-alias filtered and
  decimated from 20 Hz to 5 Hz, the polar field stored as float16 (0.008 m/s resolution at 16 m/s), so that
  ``fowt-env validate --replay`` can replay the measured wind field without the shared folder;
- ``summary.json``: per run, the statistics at the **full** 80 Hz resolution (means, std in total and per band,
  DELs of the tower-base moments, free-decay periods and damping) computed by :mod:`fowt_env.validation`, so
  that the 1st tower band (0.4-0.6 Hz) and the DELs are not limited by the decimation; plus the inputs (paths,
  size and sha256 of every ``.outb``) and the method.

Usage::

    python tools/compact_openfast_reference.py [--source ../shared/reference/openfast/runs] [--out DIR]
    python tools/compact_openfast_reference.py --inflow-only      # (re)write only the compact inflow files

Rerun it whenever the reference runs or the statistics method (``fowt_env.validation.STATISTICS_METHOD``)
change; ``fowt_env.validation`` recomputes the statistics from the records when the method differs.
"""

from __future__ import annotations

import argparse
import fnmatch
import hashlib
import json
import shutil
import sys
from pathlib import Path

import numpy as np
from scipy import signal

from fowt_env import validation
from fowt_env.io import load_record
from surrogates import Record

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SOURCE = REPO.parent / "shared" / "reference" / "openfast" / "runs"
DEFAULT_OUT = REPO / "fowt_env" / "data" / validation.PACKAGE_DATA

GAUGES = [f"TwHt{i}{q}" for q in ("ALxt", "ALyt", "MLxt", "MLyt") for i in (1, 5, 9)]
"""Tower gauges kept: 1, 5 and 9 (11.94, 46.86, 85.66 m above MSL), all four quantities (keeps the data < 5 MB)."""
DECAY_GAUGES = ("TwHt9ALxt", "TwHt9ALyt", "TwHt9MLxt", "TwHt9MLyt", "TwHt1MLxt", "TwHt1MLyt")
"""Tower gauges kept in the free decays."""
CHANNELS: tuple[str, ...] = (
    "PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw",
    "RotSpeed", "BldPitch1", "GenPwr", "GenTq", "RotThrust", "LSShftTq",
    "TwrBsMyt", "TwrBsMxt", "YawBrTAxp", "YawBrTAyp", "TTDspFA", "TTDspSS",
    "Wave1Elev", "Wind1VelX", *GAUGES,
)
"""Channels kept in the compact records (those the run has)."""

DECAY_ROTOR_CHANNELS = ("RotSpeed", "BldPitch1", "GenPwr", "GenTq", "RotThrust", "LSShftTq", "Wind1VelX",
                        "Wave1Elev")
"""Channels dropped from the free decays (parked rotor, no wind, still water: constant)."""


def sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def compact(record: Record, channels: list[str], fs_out: float, name: str, source: str) -> Record:
    """Zero-phase anti-alias filter + decimation to ``fs_out`` (Hz), float32 precision."""
    q = int(round(record.fs / fs_out))
    if abs(record.fs / q - fs_out) > 1e-6 * fs_out:
        raise ValueError(f"{name}: {record.fs} Hz is not an integer multiple of {fs_out} Hz")
    y = np.column_stack([record[c] for c in channels])
    yd = signal.resample_poly(y, 1, q, axis=0, padtype="line")
    t = record.t[0] + np.arange(yd.shape[0]) * (q * record.dt)
    yd = yd.astype(np.float32).astype(np.float64)
    units = dict(zip(record.channels, record.units, strict=True))
    meta = {"source": "OpenFAST v5.0.0 OC3 Hywind reference run (compact copy)", "run": name,
            "original_file": source, "original_fs_hz": record.fs, "fs_hz": fs_out,
            "processing": f"scipy.signal.resample_poly(up=1, down={q}, padtype='line') (zero-phase FIR "
                          "anti-alias filter), float32 precision"}
    return Record(t, yd, channels, [units[c] for c in channels], meta)


INFLOW_FS = 5.0
"""Sample rate (Hz) of the compact inflow files (the shared ones are at 20 Hz)."""


def compact_inflow(path: Path, out: Path, fs_out: float = INFLOW_FS) -> Path:
    """Write a compact copy of an OpenFAST reference ``*.inflow.npz`` (see the module docstring)."""
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    t = np.asarray(data["t"], float)
    fs = 1.0 / float(np.median(np.diff(t)))
    q = int(round(fs / fs_out))
    if q < 1 or abs(fs / q - fs_out) > 1e-6 * fs_out:
        raise ValueError(f"{path}: {fs} Hz is not an integer multiple of {fs_out} Hz")

    def dec(x: np.ndarray) -> np.ndarray:
        return signal.resample_poly(np.asarray(x, float), 1, q, axis=0)

    n = int(np.ceil(t.size / q))
    small = {
        "t": t[::q][:n],
        "hub_uvw": dec(data["hub_uvw"])[:n].astype(np.float32),
        "disc_mean_u": dec(data["disc_mean_u"])[:n].astype(np.float32),
        "polar_u": dec(data["polar_u"])[:n].astype(np.float16),
        "polar_radii": np.asarray(data["polar_radii"], float),
        "polar_azimuth_rad": np.asarray(data["polar_azimuth_rad"], float),
    }
    for key in ("zhub", "uhub", "source"):
        if key in data:
            small[key] = data[key]
    small["note"] = np.array(f"{data.get('note', '')} -- compact copy by tools/compact_openfast_reference.py: "
                             f"anti-alias filtered and decimated to {fs_out:g} Hz, polar_u float16")
    dest = out / path.name
    np.savez_compressed(dest, **small)
    return dest


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--source", type=Path, default=DEFAULT_SOURCE, help="folder of OpenFAST run folders")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder")
    ap.add_argument("--inflow-only", action="store_true", help="write only the compact inflow files")
    ap.add_argument("--no-inflow", action="store_true", help="write no compact inflow files (replays then use "
                    "Wind1VelX)")
    ap.add_argument("--runs", nargs="+", default=None, metavar="PATTERN",
                    help="only the run folders matching these glob patterns (default all)")
    ap.add_argument("--readme", default="shared/reference/openfast/README.md (OpenFAST v5.0.0, commit 2895884d, "
                    "OC3 Hywind deck)", help="where the runs are described (written into summary.json)")
    args = ap.parse_args(argv)
    src: Path = args.source.resolve()
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)

    def wanted(name: str) -> bool:
        return args.runs is None or any(fnmatch.fnmatch(name, p) for p in args.runs)

    inflows = [] if args.no_inflow else [p for p in sorted(src.glob("*/*.inflow.npz")) if wanted(p.parent.name)]
    for path in inflows:
        case_path = path.parent / (path.name[: -len(".inflow.npz")] + ".case.json")
        if not case_path.is_file():
            continue
        duration = float(json.loads(case_path.read_text(encoding="utf-8")).get("duration_s", 0.0))
        if duration >= validation.MIN_OPERATING_DURATION:  # the runs the package carries
            dest = compact_inflow(path, out)
            print(f"{dest.name}: {dest.stat().st_size / 1e6:.2f} MB")
    if args.inflow_only:
        return 0
    summary: dict = {
        "format": validation.SUMMARY_FORMAT, "version": 1,
        "created_by": "tools/compact_openfast_reference.py",
        "source_dir": str(src),
        "source_readme": args.readme,
        "method": validation._clean(validation.STATISTICS_METHOD),
        "runs": {}, "skipped": [],
    }
    for case_path in sorted(src.glob("*/*.case.json")):
        name = case_path.name[: -len(".case.json")]
        if not wanted(case_path.parent.name):
            continue
        outb = case_path.with_name(name + ".outb")
        case = json.loads(case_path.read_text(encoding="utf-8"))
        kind = "decay" if case.get("initial") else "operating"
        if not outb.is_file():
            summary["skipped"].append({"run": name, "reason": "no .outb"})
            continue
        if kind == "operating" and float(case.get("duration_s", 0.0)) < validation.MIN_OPERATING_DURATION:
            summary["skipped"].append({"run": name, "reason": f"output window {case.get('duration_s')} s is shorter "
                                       f"than {validation.MIN_OPERATING_DURATION:g} s: too short for band statistics"})
            print(f"skip {name} (too short)")
            continue
        rec = load_record(outb, unknown_channels="keep")
        chans = [c for c in CHANNELS if c in rec]
        if kind == "decay":
            chans = [c for c in chans if c not in DECAY_ROTOR_CHANNELS and (c in DECAY_GAUGES or c not in GAUGES)]
        key = next(iter(case["initial"])) if kind == "decay" else None
        fs_out = 20.0 if key in ("TTDspFA", "TTDspSS") else 10.0
        small = compact(rec, chans, fs_out, name, f"{name}/{outb.name}")
        npz = out / f"{name}.npz"
        small.save(npz)
        start = validation._elastodyn_start(case_path, name) if kind == "operating" else None
        if start and "start" not in case:  # where OpenFAST started: its deck's ElastoDyn initial conditions
            (out / f"{name}.case.json").write_text(json.dumps({**case, "start": start}, indent=1) + "\n",
                                                   encoding="utf-8")
        else:
            shutil.copyfile(case_path, out / f"{name}.case.json")
        info: dict = {
            "kind": kind,
            "source": {"path": str(outb), "bytes": outb.stat().st_size, "sha256": sha256(outb),
                       "n_samples": rec.n_samples, "fs_hz": rec.fs, "t0_s": float(rec.t[0]),
                       "t1_s": float(rec.t[-1])},
            "compact": {"file": npz.name, "fs_hz": fs_out, "n_samples": small.n_samples, "channels": chans,
                        "bytes": npz.stat().st_size},
        }
        if kind == "operating":
            info["statistics"] = validation._clean(validation.record_statistics(rec, chans))
        else:
            decay = {}
            for ch in (key, *validation.DECAY_FALLBACKS.get(key, ())):
                if ch in rec:
                    decay[ch] = validation.decay_analysis(rec.t, rec[ch]).to_dict()
            info["decay"] = decay
        summary["runs"][name] = info
        print(f"{name}: {kind}, {len(chans)} channels, {small.n_samples} samples at {fs_out:g} Hz, "
              f"{npz.stat().st_size / 1e6:.2f} MB")
    (out / "summary.json").write_text(json.dumps(summary, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    total = sum(p.stat().st_size for p in out.iterdir())
    print(f"wrote {out} ({total / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
