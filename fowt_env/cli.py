"""The ``fowt-env`` command line.

Examples
--------
::

    fowt-env demo                                  # the main job, figures in ./fowt_demo
    fowt-env simulate --case 7 --duration 1200 --seed 3 --out olc7.npz
    fowt-env simulate --case 4 --effects none --no-noise --out linear.npz
    fowt-env simulate --replay run.outb --wind-file run.bts --out replay.npz   # measured waves and wind
    fowt-env modes --case 7 --json modes.json
    fowt-env episode --case 5 --plane FA --fault scenario:A --fault dropout:0.1:2 --duration 120 --out ep.npz
    fowt-env identify olc7.npz --plane FA --json modes.json --plot figs
    fowt-env discrepancy measured.npz --case 7 --model-effects aero_damping=0 --json report.json --plot figs
    fowt-env discrepancy measured.npz --case 7 --replay    # residuals under the record's own waves and wind
    fowt-env identify run.outb --json modes.json            # OpenFAST output (.out/.outb), CSV/Parquet too
    fowt-env sense olc7.npz --hide TwHt1ALxt,TwHt9MLyt --estimator dmd --out filled.npz --plot figs
    fowt-env compare --scenario A,B,C --estimators hold,kalman,dmd,koopman --json table.json --plot figs
    fowt-env compare --estimators dmd --update-interval sweep --plot figs   # where accuracy collapses
    fowt-env campaign --cases 1-12 --seeds 0-4 --scenario random --out camp --scheduler local:2
    fowt-env validate --seeds 4 --json fidelity.json --plot figs   # the surrogate against OpenFAST
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import json
import re
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["main", "build_parser"]


class _UsageError(Exception):
    """A bad command-line value found after parsing: reported like argparse's own errors (the subcommand's usage,
    then ``fowt-env CMD: error: ...``, exit status 2)."""


class _HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Keeps the examples' line breaks and shows every option's default (unless its help already states it)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if (action.option_strings and not action.required and "default" not in text
                and not any(action.default is v for v in (None, False, argparse.SUPPRESS))):
            text += " (default: %(default)s)"
        return text


class _Parser(argparse.ArgumentParser):
    """argparse with the defaults shown in every help and a "did you mean" on misspelt options and commands."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("formatter_class", _HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str):  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {message}{self._suggestion(message)}\n")

    def _suggestion(self, message: str) -> str:
        choice = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
        if choice:
            wrong, known = choice.group(1), [c.strip(" '") for c in choice.group(2).split(",")]
        elif message.startswith("unrecognized arguments:"):
            words = [w.split("=")[0] for w in message.split(":", 1)[1].split() if w.startswith("-")]
            if not words:
                return ""
            wrong, known = words[0], [o for o in self._option_string_actions if o.startswith("--")]
        else:
            return ""
        close = difflib.get_close_matches(wrong, known, n=1, cutoff=0.6)
        return f" (did you mean {close[0]}?)" if close else ""


def _plane(text: str) -> str:
    """``--plane`` in any case: FA, SS (or all where offered)."""
    t = text.strip()
    return t.upper() if t.upper() in ("FA", "SS") else t.lower()


def _parse_effects(spec: str | None) -> str | dict[str, float]:
    """``all``, ``none`` or ``name=strength,name=strength`` (others stay nominal)."""
    if spec is None or spec in ("all", "none"):
        return spec or "all"
    out: dict[str, float] = {}
    for item in spec.split(","):
        name, eq, value = item.partition("=")
        if not (eq and name.strip() and value.strip()):
            raise _UsageError(f"--effects: expected 'all', 'none' or NAME=STRENGTH,... (e.g. quadratic_drag=0.5), "
                              f"got {item!r}")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise _UsageError(f"--effects: strength of {name!r} is not a number: {value!r}") from None
    return out


def _case(arg: str | int):
    """The load case of ``--case`` (an OLC number); a usage error naming the valid numbers otherwise."""
    import surrogates

    known = sorted(surrogates.LOAD_CASES)
    try:
        n = int(arg)
    except (TypeError, ValueError):
        n = None
    if n not in surrogates.LOAD_CASES:
        raise _UsageError(f"--case: expected an OLC number from {known[0]} to {known[-1]}, got {arg!r}")
    return surrogates.load_case(n)


def _save_record(rec, path: str | Path) -> Path:
    """Save by extension (.npz, .out, .outb, .csv, .parquet; none = .npz) via :func:`fowt_env.io.save_record`."""
    from .io import save_record

    if str(path).endswith(("/", "\\")) or Path(path).is_dir():
        raise _UsageError(f"--out: {str(path)!r} names a directory; give a file name, e.g. {Path(path) / 'run.npz'}")
    path = Path(path)
    return save_record(rec, path if path.suffix else path.with_suffix(".npz"))


def _timed_simulation(model, case, **kwargs):
    """``surrogates.simulate(model, case, **kwargs)`` and its own wall time: the set-up that a first call in a
    process pays once (the model's matrices, loading the compiled kernel) is done by a two-sample run first, so
    that the "x real time" figure is the simulation's speed, not the cost of starting the program."""
    import surrogates

    warm = {k: v for k, v in kwargs.items() if k in ("dt", "seed", "noise")}
    surrogates.simulate(model, case, duration=2.0 * kwargs.get("dt", 0.0125), transient=0.0, **warm)
    t0 = time.perf_counter()
    rec = surrogates.simulate(model, case, **kwargs)
    return rec, time.perf_counter() - t0


def _cmd_replay(args: argparse.Namespace) -> int:
    """``simulate --replay RECORD``: the surrogate under a record's measured waves and wind."""
    import surrogates

    from .replay import REPLAY_CHANNELS, replay_record, replay_scores, scores_table

    src = Path(args.replay)
    if not src.is_file():
        raise _UsageError(f"--replay: no such record {str(src)!r}")
    if args.wind_file is not None and not Path(args.wind_file).is_file():
        raise _UsageError(f"--wind-file: no such file {str(args.wind_file)!r}")
    from .io import load_record

    measured = load_record(src, unknown_channels="keep")
    heights = getattr(surrogates, "OPENFAST_GAUGE_HEIGHTS", None)
    model = surrogates.FOWTModel(_parse_effects(args.effects), gauge_heights=heights)
    from .progress import simulation_bar

    with simulation_bar(measured.duration, "replay") as (bar, hook):  # the record's span: transient + output
        t0 = time.perf_counter()
        rec = replay_record(src, wind=args.wind_file, model=model, transient=args.transient, dt=args.dt,
                            seed=args.seed, on_progress=hook,
                            initial="fit" if args.start == "fit" and args.transient >= 10.0 else True)
        wall = time.perf_counter() - t0
        bar.update(bar.total - bar.n)  # the last samples' rounding
        bar.set_postfix_str(f"writing {Path(args.out).name}")
        path = _save_record(rec, args.out)
    wind = rec.meta.get("replay", {}).get("wind") or {}
    print(f"wrote {path}: replay of {src.name} ({rec.t[0]:.1f}-{rec.t[-1]:.1f} s; wind: "
          f"{wind.get('level', 'none')}), {rec.n_samples} samples x {rec.n_channels} channels in {wall:.2f} s")
    channels = [c for c in REPLAY_CHANNELS if c in measured.channels]
    if channels and "Wave1Elev" in measured.channels and "Wind1VelX" in measured.channels:
        print(scores_table(replay_scores(measured, rec, channels=channels), src.stem))
    return 0


def _cmd_simulate(args: argparse.Namespace) -> int:
    import surrogates

    if args.replay is not None:
        return _cmd_replay(args)
    if args.wind_file is not None:
        raise _UsageError("--wind-file needs --replay RECORD")
    from .progress import simulation_bar

    case = _case(args.case)
    with simulation_bar(args.duration + 60.0, "simulate") as (bar, hook):  # 60 s: simulate's default transient
        model = surrogates.FOWTModel(_parse_effects(args.effects))
        rec, wall = _timed_simulation(model, case, duration=args.duration, dt=args.dt, seed=args.seed,
                                      noise=not args.no_noise, on_progress=hook)
        bar.update(bar.total - bar.n)  # the last samples' rounding
        bar.set_postfix_str(f"writing {Path(args.out).name}")
        path = _save_record(rec, args.out)
    print(f"wrote {path}: {rec.n_samples} samples x {rec.n_channels} channels, {rec.duration:.1f} s simulated "
          f"in {wall:.2f} s ({rec.duration / max(wall, 1e-9):.0f}x real time)")
    from .validation import DEL_CHANNELS, record_dels

    base = [c for c in DEL_CHANNELS if c in rec.channels]
    if base:
        dels = record_dels(rec, base)
        print("tower-base DELs (rainflow, m = 4, 1 Hz; fowt-env fatigue for more): "
              + ", ".join(f"{c} {v:,.0f} {rec.units[rec.channels.index(c)]}" for c, v in dels.items()))
    return 0


def _cmd_fatigue(args: argparse.Namespace) -> int:
    from .validation import record_dels

    rec = _load_record(args.record, args.channel_map)
    channels = args.channels.split(",") if args.channels else None
    if not (args.m > 0 and args.frequency > 0):
        raise _UsageError(f"--m and --frequency must be > 0, got {args.m} and {args.frequency}")
    dels = record_dels(rec, channels, m=args.m, frequency_hz=args.frequency)
    units = dict(zip(rec.channels, rec.units, strict=True))
    print(f"damage-equivalent loads of {args.record}: rainflow (ASTM E1049-85), Woehler m = {args.m:g}, "
          f"N_eq = {args.frequency:g} Hz x {rec.t[-1] - rec.t[0]:.1f} s")
    width = max(len(c) for c in dels)
    for c, v in dels.items():
        print(f"  {c:<{width}}  {v:14.6g} {units.get(c, '')}")
    if args.json:
        payload = {"record": str(args.record), "m": args.m, "frequency_hz": args.frequency,
                   "duration_s": float(rec.t[-1] - rec.t[0]),
                   "dels": {c: {"del": v, "unit": units.get(c, "")} for c, v in dels.items()}}
        Path(args.json).write_text(json.dumps(payload, indent=2))
        print(f"wrote {args.json}")
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    import surrogates

    from .progress import progress_bar

    with progress_bar(2, "modes", unit="steps") as bar:  # shown on a terminal once it has run ~2 s
        bar.set_postfix_str("model")
        model = surrogates.FOWTModel(_parse_effects(args.effects))
        bar.update(1)
        bar.set_postfix_str("linearisation and eigenvalues")
        res = model.modal_analysis(_case(args.case) if args.case is not None else None)
        bar.update(1)
    print(res)
    if args.json:
        Path(args.json).write_text(json.dumps(res.as_table(), indent=2))
        print(f"wrote {args.json}")
    return 0


_FAULT_FORMS = {  # kind: (form, example)
    "dropout": ("dropout:RATE:BURST_S", "dropout:0.1:2"),
    "scenario": ("scenario:A|B|C", "scenario:B"),
    "mask": ("mask:CH,CH", "mask:TwHt1ALxt,TwHt9MLyt"),
    "stuck": ("stuck:CH:START_S", "stuck:TwHt9ALxt:30 (frozen from t = 30 s on)"),
    "spike": ("spike:RATE:AMP", "spike:0.001:0.5"),
    "drift": ("drift:CH:RATE", "drift:TwHt9ALxt:0.001"),
    "noiseburst": ("noiseburst:CH:STD:START_S:DURATION_S", "noiseburst:TwHt9ALxt:0.1:30:5"),
}


def _parse_faults(specs: list[str]):
    """``dropout:RATE:BURST_S``, ``scenario:A``, ``mask:CH1,CH2``, ``stuck:CH:START_S``, ``spike:RATE:AMP``,
    ``drift:CH:RATE``, ``noiseburst:CH:STD:START_S:DURATION_S``; every field is required."""
    from . import faults as F

    out = []
    for spec in specs:
        kind, *args = spec.split(":")
        if kind not in _FAULT_FORMS:
            raise _UsageError(f"--fault {spec!r}: unknown kind {kind!r} (one of {', '.join(_FAULT_FORMS)})")
        form, example = _FAULT_FORMS[kind]
        if len(args) != form.count(":") or not all(a.strip() for a in args):
            raise _UsageError(f"--fault {spec!r}: expected {form}, e.g. {example}")
        try:
            if kind == "dropout":
                out.append(F.RandomDropout(float(args[0]), float(args[1])))
            elif kind == "scenario":
                out.append(F.Scenario(args[0]))
            elif kind == "mask":
                out.append(F.FixedMask(args[0].split(",")))
            elif kind == "stuck":
                out.append(F.Stuck(args[0].split(","), start=float(args[1])))
            elif kind == "spike":
                out.append(F.Spike(float(args[0]), float(args[1])))
            elif kind == "drift":
                out.append(F.Drift(args[0].split(","), rate=float(args[1])))
            elif kind == "noiseburst":
                out.append(F.NoiseBurst(args[0].split(","), std=float(args[1]), start=float(args[2]),
                                        duration=float(args[3])))
        except (IndexError, ValueError) as exc:
            raise _UsageError(f"--fault {spec!r}: {exc or 'missing arguments'} (expected {form})") from None
    return out


def _cmd_episode(args: argparse.Namespace) -> int:
    from .progress import progress_bar

    # one bar from the imports and the set-up (the warm-up simulates 60 s and the first forcing chunk) to the files
    with progress_bar(max(1, int(round(args.duration / args.dt)) - 1), "episode", unit="steps", progress=None) as bar:
        bar.set_postfix_str("set-up and warm-up", refresh=False)
        import surrogates

        from .env import SparEnv

        env = SparEnv(case=_case(args.case), dt=args.dt, plane=args.plane, faults=_parse_faults(args.fault or []),
                      model=surrogates.FOWTModel(_parse_effects(args.effects)))
        n = int(round(args.duration / env.control_dt))
        bar.total = max(1, n - 1)
        obs, info = env.reset(seed=args.seed)
        meas, truth, t = [], [], []

        def keep(o, inf):
            meas.append(np.where(o["mask"].astype(bool), o["sensors"], np.nan))
            truth.append(inf["truth"])
            t.append(inf["time"])

        keep(obs, info)
        zero = np.zeros(2, dtype=np.float32)
        bar.set_postfix_str("stepping", refresh=False)
        t0 = time.perf_counter()
        terminated = False
        for _ in range(n - 1):
            obs, _, term, _, info = env.step(zero)
            keep(obs, info)
            bar.update(1)
            if term:
                terminated = True
                break
        wall = time.perf_counter() - t0
        meta = {"source": "fowt-env episode", "case": env.case.to_dict(), "seed": args.seed,
                "faults": [repr(f) for f in env.faults], "plane": args.plane, "dt": env.dt}
        units = surrogates.FOWTModel.units(env.channels)
        measured = surrogates.Record(np.array(t), np.array(meas), env.channels, units, {**meta, "kind": "measured"})
        true_rec = surrogates.Record(np.array(t), np.array(truth), env.channels, units, {**meta, "kind": "truth"})
        out = Path(args.out)
        bar.set_postfix_str(f"writing {out.name}")
        p1 = _save_record(measured, out)
        p2 = _save_record(true_rec, out.with_name(out.stem + "_truth" + (out.suffix or ".npz")))
    if terminated:
        print("episode terminated (physical failure)")
    lost = np.isnan(measured.y).mean()
    print(f"{len(t)} steps ({t[-1]:.1f} s) in {wall:.2f} s; {100 * lost:.1f} % of samples lost")
    print(f"wrote {p1} (measured, NaN where lost)\nwrote {p2} (noise-free truth)")
    return 0


def _cmd_discrepancy(args: argparse.Namespace) -> int:
    import surrogates

    from . import discrepancy

    measured = _load_record(args.measured, args.channel_map)
    # an OpenFAST record has its tower gauges at the OC3 deck's nodes and no sensor noise: the model measures
    # where and as it does
    openfast = "openfast" in str(measured.meta.get("source", "")).lower() or Path(args.measured).suffix.lower() in (
        ".out", ".outb")
    model = surrogates.FOWTModel(_parse_effects(args.model_effects),
                                 gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS if openfast else None)
    if openfast:
        model = model.with_noise(scale=0.0)
        print("OpenFAST record: the model has OpenFAST's gauge heights and no sensor noise")
    cands = args.candidates.split(",") if args.candidates else None
    case = _record_case(measured, args.case)
    sidecar = Path(args.measured).with_suffix(".case.json")  # an OpenFAST reference run's conditions beside it
    if case is None and sidecar.is_file():
        from .validation import surrogate_case

        case = surrogate_case(json.loads(sidecar.read_text(encoding="utf-8")))
        print(f"load case from {sidecar.name}: {case}")
    if case is None:
        raise _UsageError(f"{args.measured} does not state its load case: give --case (an OLC number)")
    t0 = time.perf_counter()
    rep = discrepancy.run(measured, model, case, seed=args.seed, candidates=cands, n_seeds=args.seeds,
                          progress=None, replay=args.replay)
    print(rep.summary())
    print(f"({time.perf_counter() - t0:.1f} s)")
    if args.json:
        Path(args.json).write_text(json.dumps(rep.to_dict(), indent=2))
        print(f"wrote {args.json}")
    if args.plot:
        print(f"wrote {_drawn(lambda: rep.plot(Path(args.plot) / 'discrepancy.png'))}")
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    from .validation import format_pooled, pooled_over_seas, validate

    if args.reference == "time-domain" or args.time_domain:
        return _cmd_time_domain(args)
    progress = None  # a bar on a terminal, once a step has run 2 s
    rep = validate(args.reference, seeds=args.seeds, duration=args.duration, runs=args.runs, plot_dir=args.plot,
                   progress=progress, replay=args.replay, wind="synthetic" if args.free_wind else args.wind)
    print(rep.summary(graded_only=not args.all_channels), end="")
    pooled = pooled_over_seas(rep)
    if pooled:
        print("\n" + format_pooled(pooled), end="")
    if args.json:
        rep.to_json(args.json)
        print(f"wrote {args.json}")
    if rep.figures:
        print(f"wrote {len(rep.figures)} figure(s) to {args.plot}")
    return 1 if args.strict and not rep.passed else 0


def _cmd_time_domain(args: argparse.Namespace) -> int:
    """``validate time-domain`` / ``validate DIR --time-domain``: replay runs from their start, R² per channel."""
    from .time_domain import format_time_domain, plot_time_domain, time_domain

    reference = None if args.reference in (None, "time-domain") else args.reference
    try:
        scores, records = time_domain(reference, runs=args.runs, return_records=True)
    except ValueError as exc:
        raise SystemExit(f"fowt-env: {exc}") from None
    print("Replayed from OpenFAST's initial state under its own wave elevation (and steady wind); "
          "R² = 1 - mean((surrogate - OpenFAST)²) / var(OpenFAST)")
    print(format_time_domain(scores), end="")
    if args.json:
        Path(args.json).write_text(json.dumps([s.to_dict() for s in scores], indent=1) + "\n", encoding="utf-8")
        print(f"wrote {args.json}")
    if args.plot:
        figs = plot_time_domain(records, args.plot)
        print(f"wrote {len(figs)} figure(s) to {args.plot}")
    return 0


def _load_record(path: str, channel_map: str | None = None):
    """Any record file fowt_env.io reads (.npz, .out, .outb, .csv, .parquet); one-line exit on any problem."""
    import zipfile

    from .io import load_channel_map, load_record

    p = Path(path)
    if p.suffix.lower() == ".npz" and p.is_file() and not zipfile.is_zipfile(p):
        # numpy reads a non-zip file as a pickle and answers with advice on unsafe loading: never relay that
        raise SystemExit(f"fowt-env: {path}: not an .npz record (an .npz file is a zip archive of arrays, as "
                         "written by fowt-env simulate/episode or Record.save)")
    try:
        mapping = load_channel_map(channel_map) if channel_map else None
        return load_record(path, channel_map=mapping, unknown_channels="keep")
    except ValueError as exc:
        message = str(exc)
        if "pickle" in message:
            message = f"{path}: not a record file this program can read safely"
        raise SystemExit(f"fowt-env: {message}") from None


def _record_case(rec, case_arg: str | None):
    """The load case of ``--case`` if given, else the record's own (its header's ``case``), else None."""
    import surrogates

    if case_arg is not None:
        return _case(case_arg)
    if isinstance(rec.meta.get("case"), dict):
        return surrogates.LoadCase.from_dict(rec.meta["case"])
    return None


def _identification_reference(rec, case_arg: str | None, plane: str | None, effects: str):
    """Linear reference for ``identify``: from --case, else from the record's own load case if it has one."""
    import surrogates

    from .identification import model_reference

    case = _record_case(rec, case_arg)
    if case is None:
        return None
    return model_reference(surrogates.FOWTModel(_parse_effects(effects)), case, plane=plane)


def _cmd_identify(args: argparse.Namespace) -> int:
    from .identification import identify

    rec = _load_record(args.record, args.channel_map)
    channels = args.channels.split(",") if args.channels else None
    ref = None if args.no_reference else _identification_reference(rec, args.case, args.plane, args.effects)
    rank: int | float | str = args.rank if args.rank == "auto" else (float(args.rank) if "." in args.rank
                                                                         else int(args.rank))
    delays: int | float = float(args.delays) if "." in args.delays else int(args.delays)
    t0 = time.perf_counter()
    rotor_speed = None if args.rotor_speed.lower() == "none" else args.rotor_speed
    res = identify(rec, channels=channels, plane=args.plane, delays=delays, rank=rank, ssi=not args.no_ssi,
                   reference=ref, rotor_speed=rotor_speed, progress=None)
    print(res.summary())
    print(f"({time.perf_counter() - t0:.1f} s)")
    if args.json:
        Path(args.json).write_text(json.dumps(res.to_dict(), indent=2))
        print(f"wrote {args.json}")
    if args.plot:
        for path in res.plot(args.plot, progress=None):
            print(f"wrote {path}")
    return 0


def _stats_table(rec, names: list[str]) -> str:
    rows = [f"{'channel':<12}{'unit':>8}{'mean':>12}{'std':>12}{'min':>12}{'max':>12}"]
    for n in names:
        v = rec[n]
        u = rec.units[rec.channels.index(n)]
        rows.append(f"{n:<12}{u:>8}{np.mean(v):>12.4g}{np.std(v):>12.4g}{np.min(v):>12.4g}{np.max(v):>12.4g}")
    return "\n".join(rows)


def _option_value(text: str):
    """The VALUE of an ``--option ...=VALUE``: parsed as JSON if it can be (numbers, true, lists), else the text."""
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def _cmd_sense(args: argparse.Namespace) -> int:
    from .compare import CompareSettings, parse_int_list
    from .io import save_record
    from .sensing import sense, write_json

    rec = _load_record(args.record, args.channel_map)
    train = [_load_record(p, args.channel_map) for p in args.train] if args.train else None
    truth = _load_record(args.truth, args.channel_map) if args.truth else None
    options: dict = {}
    for spec in args.option or []:
        key, eq, value = spec.partition("=")
        if not (eq and key):
            raise ValueError(f"--option: expected PARAM=VALUE, got {spec!r}")
        options[key] = _option_value(value)
    settings = None
    if not train:
        settings = CompareSettings(train_cases=tuple(parse_int_list(args.train_cases, "--train-cases")),
                                   train_duration=args.train_duration)
    res = sense(rec, args.estimator, plane=None if args.plane == "all" else args.plane,
                channels=args.channels.split(",") if args.channels else None,
                hide=[h.strip() for h in args.hide.split(",")] if args.hide else (), train=train,
                update_interval=args.update_interval, options=options or None, truth=truth, settings=settings,
                progress=None)
    print(res.summary())
    out = Path(args.out)
    out = out if out.suffix else out.with_suffix(".npz")
    print(f"wrote {save_record(res.record, out)}")
    if res.std is not None:
        print(f"wrote {save_record(res.std, out.with_name(out.stem + '_std' + out.suffix))}")
    if args.json:
        print(f"wrote {write_json(res, args.json)}")
    if args.plot:
        print(f"wrote {res.plot(args.plot, truth=truth)}")
    return 0


def _demo_sensing(rec, model, case, folder: Path) -> None:
    """Virtual sensing of the demo record: the paper's scenario B (tower base and top lost) filled in by the
    causal Hankel-DMD sensor trained on two other load cases."""
    import surrogates

    from .sensing import sense

    hidden = ["TwHt1ALxt", "TwHt9ALxt", "TwHt1MLyt", "TwHt9MLyt"]
    own = int(case.name[3:]) if case.name.startswith("OLC") and case.name[3:].isdigit() else None
    others = [c for c in (1, 6, 11) if c != own][:2]
    print(f"\nVirtual sensing: {', '.join(hidden)} lost (the paper's scenario B); causal Hankel-DMD sensor "
          f"(60 delays, rank 90, 1 s updates) trained on OLC {others[0]} and {others[1]} (120 s each):")
    from .progress import progress_bar

    t0 = time.perf_counter()
    with progress_bar(len(others) + 3, "sensing", progress=None) as bar:
        bar.set_postfix_str("training records")
        train = []
        for c in others:
            train.append(surrogates.simulate(model, c, duration=120.0, dt=rec.dt, seed=900 + c))
            bar.update(1)
        bar.set_postfix_str("noise-free truth")
        truth = surrogates.simulate(model, case, duration=rec.n_samples * rec.dt, dt=rec.dt,
                                    seed=rec.meta.get("seed", 0), noise=False)
        bar.update(1)
        bar.set_postfix_str("fit and reconstruct")
        res = sense(rec, "dmd", hide=hidden, train=train, truth=truth)
        bar.update(1)
        bar.set_postfix_str("figure")
        figure = res.plot(folder, truth=truth)
        bar.update(1)
    print(res.summary())
    print(f"wrote {figure} ({time.perf_counter() - t0:.1f} s)")


def _demo_psd(rec, modes, case, out: Path) -> Path:
    """The demo's PSD of the tower-top accelerations, marked with ``modes`` (the model linearised at ``case``,
    the same modes the modal table prints and the identification is checked against) and the rotor's 1P/3P/6P."""
    from .plots import psd_figure

    return psd_figure(rec, ["TwHt9ALxt", "TwHt9ALyt"], out / "psd_tower_top_acceleration.png",
                      modes=list(zip(modes.labels, modes.frequencies_hz, strict=True)), rotor_rpm=case.rotor_rpm,
                      title=f"Tower-top acceleration, {case.name} (modes: linear model at {case.name})")


def _demo_identification(rec, model, case, folder: Path):
    """Output-only identification of the demo record, side by side with the model's own linearisation; returns
    the :class:`~fowt_env.identification.IdentificationResult` it printed and drew."""
    from .identification import identify, model_reference

    print("\nIdentification from the 18 fore-aft tower channels alone (Hankel-DMD, 2.5 s of delays, rank 24; "
          f"SSI-COV), against the model linearised at {case.name} (a line more than 10 % from every model mode "
          "is not called structural):")
    ref = model_reference(model, case, plane="FA")
    t0 = time.perf_counter()
    res = identify(rec, plane="FA", reference=ref, progress=None)
    print(res.summary())
    paths = res.plot(folder, progress=None)
    print(f"wrote {len(paths)} figures to {folder} ({time.perf_counter() - t0:.1f} s)")
    return res


def _cmd_demo(args: argparse.Namespace) -> int:
    import surrogates

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    case = _case(args.case)
    model = surrogates.FOWTModel()
    print(f"fowt-env demo: NREL 5 MW on OC3 Hywind, {case.name}: Hs={case.hs} m, Tp={case.tp} s, "
          f"waves {case.wave_dir_deg} deg, wind {case.wind_speed} m/s (TI {case.turbulence_intensity:.3f})")
    print(f"effects: {model.effects}")
    modes = model.modal_analysis(case)
    print(f"\nModal analysis of the model linearised at {case.name} (the modes the PSD marks and the "
          "identification is checked against):")
    print(modes)
    from .progress import simulation_bar

    with simulation_bar(args.duration + 60.0, "simulate") as (_, hook):
        rec, wall = _timed_simulation(model, case, duration=args.duration, dt=0.0125, seed=args.seed, on_progress=hook)
    print(f"\nSimulated {rec.duration:.0f} s at 80 Hz in {wall:.2f} s ({rec.duration / max(wall, 1e-9):.0f}x real "
          "time)")
    print(_stats_table(rec, ["PtfmSurge", "PtfmPitch", "PtfmYaw", "RotSpeed", "TwHt1MLyt", "TwHt1MLxt",
                             "TwHt9ALxt", "TwHt9ALyt", "Wave1Elev", "Wind1VelX"]))
    path = rec.save(out / f"{case.name.lower()}_seed{args.seed}.npz")
    fig = _demo_psd(rec, modes, case, out)
    print(f"\nwrote {path}\nwrote {fig}")
    _demo_identification(rec, model, case, out / "identification")
    _demo_sensing(rec, model, case, out / "sensing")
    if args.skip_discrepancy or rec.duration < 300.0:
        if not args.skip_discrepancy:
            print("(discrepancy round trip skipped: it needs a record of at least 300 s)")
        return 0
    from . import discrepancy

    print("\nDiscrepancy round trip: the record above has catenary mooring; the candidate model has linear mooring.")
    t0 = time.perf_counter()
    rep = discrepancy.run(rec, model.without("mooring_nonlinear"), case, n_seeds=3, progress=None)
    print(rep.summary())
    print(f"wrote {_drawn(lambda: rep.plot(out / 'discrepancy.png'))} ({time.perf_counter() - t0:.0f} s)")
    return 0


def _cmd_compare(args: argparse.Namespace) -> int:
    from .compare import compare, grid_units

    scenarios, estimators, kwargs = _compare_request(args)
    total = len(grid_units(scenarios, estimators, **{k: kwargs[k] for k in ("cases", "seeds", "update_intervals",
                                                                            "settings")}))
    total += kwargs["lyapunov_time"] == "auto"  # the Lyapunov estimate runs as one more task
    with _scheduler(args.scheduler, "compare", total, args.scheduler_security, args.insecure) as executor:
        res = compare(scenarios, estimators, executor=executor, **kwargs)
    print(res.summary())
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(res.to_dict(wall_clock=args.timings), indent=1))
        print(f"wrote {args.json}")
    if args.plot:
        for path in _drawn(lambda: res.plot(args.plot)):
            print(f"wrote {path}")
    return 0


def _drawn(draw):
    """``draw()`` (figures: 10-16 s for discrepancy's or compare's on a busy machine) under a one-step bar, so the
    wait shows its elapsed time on a terminal."""
    from .progress import progress_bar

    with progress_bar(1, "figures", progress=None) as bar:
        out = draw()
        bar.update(1)
    return out


@contextlib.contextmanager
def _scheduler(spec: str | None, desc: str, total: int | None = None, security: str | None = None,
               insecure: bool = False):
    """The executor of ``--scheduler`` (None: none, compare's in-process default), with a progress bar of
    ``total`` tasks on stderr when it is a terminal."""
    from .campaign import ProgressExecutor, SerialExecutor, parse_scheduler
    from .progress import on_terminal

    if spec is None and (security or insecure):
        raise _UsageError("--scheduler-security and --insecure apply to --scheduler tcp:// or tls:// only")
    if spec is None:
        if not on_terminal():
            yield None
            return
        wrapped = ProgressExecutor(SerialExecutor(), total=total, desc=desc)  # same results, a bar for people
        try:
            yield wrapped
        finally:
            wrapped.shutdown()
        return

    with parse_scheduler(spec, security=security, insecure=insecure) as executor:
        wrapped = ProgressExecutor(executor, total=total, desc=desc)
        try:
            yield wrapped
        finally:
            wrapped.shutdown()


def _compare_request(args: argparse.Namespace) -> tuple[list[str], list[str], dict]:
    """The grid and settings of the compare/campaign arguments: (scenarios, estimators, keyword arguments)."""
    from .compare import SCENARIO_NAMES, SWEEP_INTERVALS, CompareSettings, parse_int_list
    from .io import load_channel_map

    def floats(text: str, name: str) -> list[float]:
        try:
            return [float(v) for v in text.split(",")]
        except ValueError:
            raise ValueError(f"--{name}: expected comma-separated seconds, got {text!r}") from None

    scenarios = list(SCENARIO_NAMES) if args.scenario == "all" else [s.strip() for s in args.scenario.split(",")]
    intervals = list(SWEEP_INTERVALS) if args.update_interval == "sweep" else floats(args.update_interval,
                                                                                      "update-interval")
    options: dict[str, dict] = {}
    for spec in args.option or []:
        key, eq, value = spec.partition("=")
        est, dot, param = key.partition(".")
        if not (eq and dot and est and param):
            raise ValueError(f"--option: expected ESTIMATOR.PARAM=VALUE, got {spec!r}")
        options.setdefault(est, {})[param] = _option_value(value)
    lyap = args.lyapunov_time if args.lyapunov_time in ("auto", "none") else floats(args.lyapunov_time,
                                                                                    "lyapunov-time")[0]
    settings = CompareSettings(
        train_cases=tuple(parse_int_list(args.train_cases, "--train-cases")), train_duration=args.train_duration,
        train_seed=args.train_seed, duration=args.duration, plane=None if args.plane == "all" else args.plane,
        dropout_rate=args.dropout_rate, dropout_burst_s=args.dropout_burst, estimator_options=options,
        train_files=tuple(args.train or ()), test_files=tuple(args.test or ()),
        channel_map=load_channel_map(args.channel_map) if args.channel_map else {},
        band=tuple(floats(args.band, "band")),  # type: ignore[arg-type]
        truth_effects={k: _option_value(v) for k, _, v in (item.strip().partition("=") for item in
                                                          (args.truth_model or "").split(",") if item.strip())})
    return scenarios, [e.strip() for e in args.estimators.split(",")], {
        "cases": parse_int_list(args.cases, "--cases") if args.cases else None,
        "seeds": parse_int_list(args.seeds, "--seeds"), "update_intervals": intervals, "settings": settings,
        "lyapunov_time": None if lyap == "none" else lyap}


def _cmd_campaign(args: argparse.Namespace) -> int:
    from .campaign import parse_scheduler, run_campaign

    scenarios, estimators, kwargs = _compare_request(args)
    if args.retries < 0:
        raise ValueError(f"--retries must be >= 0, got {args.retries}")
    with parse_scheduler(args.scheduler, security=args.scheduler_security, insecure=args.insecure) as executor:
        try:
            done = run_campaign(args.out, scenarios, estimators, executor=executor, retries=args.retries,
                                progress=args.progress, keep_traces=bool(args.plot), fresh=args.fresh, **kwargs)
        except KeyboardInterrupt:
            print(f"fowt-env campaign: interrupted; finished tasks are in {Path(args.out) / 'results.jsonl'}: "
                  f"run the same command again to resume", file=sys.stderr)
            return 130
    print(done.summary())
    print(f"wrote {done.summary_path}")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(done.to_dict(), indent=1))
        print(f"wrote {args.json}")
    if args.plot and done.result.runs:
        for path in _drawn(lambda: done.result.plot(args.plot)):
            print(f"wrote {path}")
    if not done.ok:
        print(f"fowt-env campaign: {len(done.failed)} task(s) failed (listed above and in {done.summary_path}); "
              f"run the same command again to retry them", file=sys.stderr)
        return 1
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (exposed for tests and docs)."""
    from . import __version__

    p = _Parser(prog="fowt-env", description=__doc__.split("Examples")[0].strip().replace("``", ""),
                epilog="Examples:\n" + __doc__.split("::")[1])
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    p.add_argument("--debug", action="store_true", help="show the full traceback of a failure")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)
    p.subcommands = sub.choices  # type: ignore[attr-defined]
    seed_help = "seed of waves, wind, rotor azimuth and sensor noise (same seed, same record)"
    effects_help = "model effects: 'all', 'none' or name=strength,... (others nominal)"
    dt_help = "sample time in s (0.0125 = 80 Hz)"

    d = sub.add_parser("demo", help="simulate an OLC, print modal frequencies and statistics, plot PSDs")
    d.add_argument("--out", default="fowt_demo", help="output folder (default: ./fowt_demo)")
    d.add_argument("--case", default="7", help="OLC number 1-12 (default 7: Hs 3 m, Tp 10 s, rated wind)")
    d.add_argument("--duration", type=float, default=600.0, help="simulated seconds (default 600)")
    d.add_argument("--seed", type=int, default=0, help=seed_help)
    d.add_argument("--skip-discrepancy", action="store_true", help="skip the discrepancy round trip")
    d.set_defaults(func=_cmd_demo)

    s = sub.add_parser("simulate", help="simulate a load case and save the record (.npz + JSON header)")
    s.add_argument("--case", default="7", help="OLC number 1-12")
    s.add_argument("--duration", type=float, default=600.0, help="seconds (default 600)")
    s.add_argument("--dt", type=float, default=0.0125, help="sample time in s (default 0.0125 = 80 Hz)")
    s.add_argument("--seed", type=int, default=0, help=seed_help)
    s.add_argument("--effects", default="all", help=effects_help)
    s.add_argument("--no-noise", action="store_true", help="noise-free sensors")
    s.add_argument("--out", required=True, help="output file: .npz (lossless), .out/.outb (OpenFAST), .csv or .parquet")
    s.add_argument("--replay", metavar="RECORD",
                   help="replay a measured record's Wave1Elev and Wind1VelX (OpenFAST .outb/.out, .npz, CSV) under "
                        "its conditions (<run>.case.json beside it, else estimated), from its first sample; "
                        "--case/--duration/--no-noise are then ignored (a replay is noise-free), the output starts "
                        "--transient s after the record")
    s.add_argument("--wind-file", metavar="FILE",
                   help="with --replay: a richer wind than Wind1VelX, a TurbSim .bts full field or an OpenFAST "
                        "reference *.inflow.npz (default: <run>.inflow.npz beside the record, if any)")
    s.add_argument("--transient", type=float, default=100.0,
                   help="with --replay: start-up discarded, s (default 100)")
    s.add_argument("--start", choices=["fit", "first-sample"], default="fit",
                   help="with --replay: the platform's initial positions and rates fitted to the record over the "
                        "discarded start-up (default; the sea before the record is unknown, so its wave loads start "
                        "cold), or taken from the record's first sample and its slopes")
    s.set_defaults(func=_cmd_simulate)

    e = sub.add_parser("episode", help="run an environment episode under sensor faults and save the records")
    e.add_argument("--case", default="7", help="OLC number 1-12")
    e.add_argument("--duration", type=float, default=600.0, help="seconds (default 600)")
    e.add_argument("--dt", type=float, default=0.0125, help=dt_help)
    e.add_argument("--plane", type=_plane, choices=["FA", "SS"], default=None,
                   help="18 channels of one plane, FA or SS in any case (default all 36)")
    e.add_argument("--fault", action="append", metavar="SPEC",
                   help="repeatable: " + " | ".join(form for form, _ in _FAULT_FORMS.values())
                        + " (times and durations in s, every field required)")
    e.add_argument("--effects", default="all", help=effects_help)
    e.add_argument("--seed", type=int, default=0, help="seed of the episode (physics and faults)")
    e.add_argument("--out", required=True, help="output .npz (the truth goes to *_truth.npz)")
    e.set_defaults(func=_cmd_episode)

    q = sub.add_parser("discrepancy", help="find and name the physical effect a model misses in a measured record")
    q.add_argument("measured",
                   help="measured record: .npz (fowt-env), OpenFAST .out/.outb, or .csv/.parquet field data")
    q.add_argument("--channel-map", default=None, metavar="FILE.json",
                   help='JSON object renaming file columns to channel names, e.g. {"acc_top_x": "TwHt9ALxt"}')
    q.add_argument("--case", default=None,
                   help="OLC number of the measured conditions (default: the record's own case, if it states one)")
    q.add_argument("--model-effects", default="all", help="candidate model: 'all', 'none' or name=strength,...")
    q.add_argument("--candidates", default=None,
                   help="comma-separated effects (surrogates.EFFECTS) and parameter multipliers "
                        "(surrogates.parameters.PARAMETERS, e.g. tower_fa_stiffness, mooring_line_1) to consider "
                        "(default all)")
    q.add_argument("--seeds", type=int, default=3, help="model simulations per setting (default 3)")
    q.add_argument("--seed", type=int, default=None,
                   help="first seed of the model simulations (default 1000; the next --seeds - 1 follow)")
    q.add_argument("--replay", action="store_true",
                   help="compare residual time series under the record's own waves and wind (its Wave1Elev, and the "
                        "rotor-effective wind estimated from RotThrust, RotSpeed and BldPitch1 if it has them, else "
                        "Wind1VelX) instead of statistics against the model's seed scatter")
    q.add_argument("--json", default=None, help="write the report as JSON")
    q.add_argument("--plot", default=None, help="folder for the figure")
    q.set_defaults(func=_cmd_discrepancy)

    i = sub.add_parser("identify", help="identify modes of a record with Hankel-DMD and SSI-COV (Table-3 style)")
    i.add_argument("record", help="record file: .npz (fowt-env), OpenFAST .out/.outb, or .csv/.parquet field data")
    i.add_argument("--channel-map", default=None, metavar="FILE.json",
                   help='JSON object renaming file columns to channel names, e.g. {"acc_top_x": "TwHt9ALxt"}')
    i.add_argument("--plane", type=_plane, choices=["FA", "SS"], default=None,
                   help="use the 18 channels of one plane, FA or SS in any case (default: all tower channels)")
    i.add_argument("--channels", default=None, help="comma-separated channels (overrides --plane)")
    i.add_argument("--delays", default="2.5", help="Hankel delay: seconds (e.g. 2.5, default) or samples (60)")
    i.add_argument("--rank", default="24", help="DMD rank: int, energy fraction (0.99) or 'auto'")
    i.add_argument("--case", default=None,
                   help="OLC of the linear reference (default: the record's own case, if it has one)")
    i.add_argument("--effects", default="all", help="effects of the reference model: " + effects_help)
    i.add_argument("--no-reference", action="store_true", help="do not compare with the linearised model")
    i.add_argument("--no-ssi", action="store_true", help="skip SSI-COV")
    i.add_argument("--rotor-speed", default="auto", metavar="CHANNEL",
                   help="rotor-speed channel (rpm or rad/s) for the order-tracked rotor harmonics; 'auto' "
                        "(default): RotSpeed if the record has it and the rotor turns; 'none': skip")
    i.add_argument("--json", default=None, help="write modes and pairing as JSON")
    i.add_argument("--plot", default=None, help="folder for the figures")
    i.set_defaults(func=_cmd_identify)

    v = sub.add_parser(
        "sense", help="virtual sensing of one record: fill its lost tower channels with a trained estimator",
        formatter_class=_HelpFormatter,
        description="Reconstruct the lost (NaN) or --hide'n tower channels of a record with a virtual sensor "
                    "(dmd, kalman, koopman, hold), trained on your own complete records (--train) or on the "
                    "surrogate's training set (the paper's OLCs). Writes the reconstruction (and its std for "
                    "uncertainty-aware sensors) in any record format.",
        epilog="Examples:\n"
               "  fowt-env simulate --case 7 --duration 120 --out run.npz\n"
               "  fowt-env sense run.npz --hide TwHt1ALxt,TwHt9MLyt --estimator dmd --out filled.npz --plot figs\n"
               "  fowt-env sense field.csv --channel-map map.json --train healthy.csv --estimator koopman \\\n"
               "      --out filled.csv --json scores.json")
    v.add_argument("record", help="record file: .npz, OpenFAST .out/.outb, .csv/.parquet (NaN = lost)")
    v.add_argument("--estimator", default="dmd", help="dmd (default), kalman, koopman or hold")
    v.add_argument("--hide", default=None, help="comma-separated channels to lose on purpose")
    v.add_argument("--plane", type=_plane, choices=["FA", "SS", "all"], default="FA",
                   help="channels to sense: FA, SS (any case) or all (default FA)")
    v.add_argument("--channels", default=None, help="comma-separated channels instead of a plane (needs --train)")
    v.add_argument("--train", nargs="+", default=None, metavar="FILE",
                   help="complete training records of the same channels (default: the surrogate training set)")
    v.add_argument("--train-cases", default="1,3,4,6,8-12",
                   help="surrogate training OLCs when no --train is given (default the paper's)")
    v.add_argument("--train-duration", type=float, default=300.0, help="seconds per surrogate training record")
    v.add_argument("--update-interval", type=float, default=1.0, help="recalibration interval (s) of dmd")
    v.add_argument("--option", action="append", metavar="PARAM=VALUE",
                   help="estimator option (VALUE parsed as JSON if it can be), e.g. rank=40; repeatable")
    v.add_argument("--truth", default=None, help="noise-free truth record: score the lost channels (R2, NRMSE)")
    v.add_argument("--channel-map", default=None, metavar="FILE.json", help="rename file columns to channel names")
    v.add_argument("--out", required=True, help="reconstruction file (.npz, .out, .outb, .csv, .parquet)")
    v.add_argument("--json", default=None, help="write the scores as JSON")
    v.add_argument("--plot", default=None, help="folder for the figure")
    v.set_defaults(func=_cmd_sense)

    c = sub.add_parser(
        "compare", help="virtual sensing: score estimators on hidden channels of unseen load cases (R2, NRMSE)",
        formatter_class=_HelpFormatter,
        description="Train virtual sensors on some OLCs, hide channels of unseen OLCs/seeds (the seed paper's "
                    "scenarios A, B, C or random dropouts), and report R2 and NRMSE per hidden channel (physical and "
                    "band-passed), the 95 % interval coverage and the cost per sample.",
        epilog="Examples:\n"
               "  fowt-env compare --duration 60                      # paper scenarios A, B, C; hold, kalman, dmd\n"
               "  fowt-env compare --scenario B,random --estimators hold,kalman --seeds 0-2 --json cmp.json\n"
               "  fowt-env compare --scenario A --estimators dmd,kalman --update-interval sweep --plot figs\n"
               "  fowt-env compare --cases 2,5,7 --option dmd.rank=24 --option kalman.gate_sigma=null\n"
               "  fowt-env compare --cases 2,5 --seeds 0-3 --scenario B --scheduler local:2 --json cmp.json")
    c.add_argument("--scenario", default="A,B,C", help="comma-separated A, B, C, random, or 'all' (default A,B,C)")
    c.add_argument("--cases", default=None,
                   help="test OLCs, e.g. 2,5,7 or 1-12, each under every scenario (default: the paper's pairing "
                        "A->5, B->7, C->2; random->7)")
    c.add_argument("--seeds", default="0", help="test seeds, e.g. 0,1,2 or 0-4 (default 0)")
    c.add_argument("--duration", type=float, default=600.0, help="seconds per test record (default 600)")
    c.add_argument("--estimators", default="hold,kalman,dmd",
                   help="comma-separated names: hold, kalman, dmd, koopman (default hold,kalman,dmd)")
    c.add_argument("--update-interval", default="1",
                   help="recalibration interval(s) in s for sensors that use one (dmd): e.g. 1 or 0.5,1,2, or "
                        "'sweep' = 0.25,0.5,1,2,4 (default 1, the paper's)")
    c.add_argument("--train-cases", default="1,3,4,6,8-12", help="training OLCs (default the paper's 1,3,4,6,8-12)")
    c.add_argument("--train-duration", type=float, default=300.0, help="seconds per training record (default 300)")
    c.add_argument("--train-seed", type=int, default=1000,
                   help="the training record of OLC c uses seed TRAIN_SEED + c (default 1000)")
    c.add_argument("--plane", type=_plane, choices=["FA", "SS", "all"], default="FA",
                   help="the 18 channels of one plane, or all 36 tower channels (default FA)")
    c.add_argument("--dropout-rate", type=float, default=0.2, help="random scenario: lost fraction (default 0.2)")
    c.add_argument("--dropout-burst", type=float, default=2.0, help="random scenario: mean burst in s (default 2)")
    c.add_argument("--lyapunov-time", default="auto",
                   help="seconds, 'auto' (Rosenstein on band-passed tower-top acceleration) or 'none'")
    c.add_argument("--option", action="append", metavar="EST.PARAM=VALUE",
                   help="repeatable estimator option (VALUE parsed as JSON if it can be), e.g. dmd.rank=24")
    c.add_argument("--train", nargs="+", default=None, metavar="FILE",
                   help="train on these records (OpenFAST .out/.outb, .csv, .parquet, .npz) instead of simulated OLCs; "
                        "with --test (then --cases are test-file indices; kalman is linearised at each test record's "
                        "operating point: its .case.json sidecar, metadata or mean Wind1VelX)")
    c.add_argument("--test", nargs="+", default=None, metavar="FILE", help="test on these records (with --train)")
    c.add_argument("--channel-map", default=None, metavar="FILE.json",
                   help="with --train/--test: rename file columns to channel names ({\"column\": \"TwHt1ALxt\", ...})")
    c.add_argument("--band", default="0.25,5", metavar="LO,HI",
                   help="band (Hz) of the band-passed scores, below the records' Nyquist frequency (default 0.25,5)")
    c.add_argument("--truth-model", default=None, metavar="NAME=VALUE,...",
                   help="simulated records from a perturbed truth model, e.g. tower_stiffness=0.95, "
                        "platform_mass=1.03, quadratic_drag=1.5, mooring_stiffness=0.7, rotor_mass_imbalance=0.02; "
                        "kalman keeps the nominal model")
    c.add_argument("--json", default=None, help="write the result as JSON (reproducible; --timings adds timings)")
    c.add_argument("--timings", action="store_true",
                   help="include the wall-clock timings in the JSON (machine-dependent; without them the JSON is "
                        "reproducible: the same whatever --scheduler)")
    c.add_argument("--plot", default=None, help="folder for the figures")
    c.add_argument("--scheduler", default=None, metavar="SPEC",
                   help="run the grid on: serial, threads:N, processes:N, local:N (a Dask LocalCluster of N worker "
                        "processes) or tcp://HOST:PORT / tls://HOST:PORT (an existing Dask cluster); the numbers do "
                        "not depend on it (default: in this process). Trust: Dask sends results pickled and this "
                        "program unpickles them, so whoever controls that address can run code here; tcp:// beyond "
                        "this machine is refused without --insecure: use tls:// with --scheduler-security")
    c.add_argument("--scheduler-security", default=None, metavar="FILE",
                   help="TLS credentials for a tls:// scheduler: YAML/JSON in Dask's layout (distributed: comm: "
                        "tls: ca-file, client: cert/key) or distributed.Security keywords (default: Dask's own "
                        "configuration)")
    c.add_argument("--insecure", action="store_true",
                   help="accept a plain tcp:// scheduler on another machine (only on a network you trust)")
    c.set_defaults(func=_cmd_compare)

    g = sub.add_parser(
        "campaign", parents=[c], add_help=False, formatter_class=_HelpFormatter,
        help="compare's grid as a resumable campaign: results written as tasks finish, retries, Dask clusters",
        description="Run compare's grid (scenarios x test OLCs x seeds x estimators x update intervals) task by "
                    "task on any scheduler, appending one JSON line per finished task to OUT/results.jsonl. Run the "
                    "same command again after an interruption (Ctrl-C, a killed process, a lost cluster) and only "
                    "the missing tasks run; a task that raises is retried --retries times, then reported as failed "
                    "(exit code 1), never dropped. The summary, the same JSON as compare --json, goes to "
                    "OUT/summary.json. Takes every option of compare.",
        epilog="Examples:\n"
               "  fowt-env campaign --out camp --cases 2,5 --seeds 0-3 --scenario B --estimators hold,dmd\n"
               "  fowt-env campaign --out camp --cases 1-12 --seeds 0-9 --scenario all --scheduler local:8\n"
               "  fowt-env campaign --out camp --cases 1-12 --scheduler tcp://scheduler-host:8786 --retries 2\n"
               "  fowt-env campaign --out camp --cases 2,5 --seeds 0-5 --scenario B   # rerun: only the new seeds run\n"
               "  fowt-env campaign --out camp --cases 2,5 --scenario B --fresh       # forget earlier results")
    g.add_argument("--out", required=True, metavar="DIR",
                   help="campaign directory: results.jsonl (one line per finished task), summary.json, campaign.json")
    g.add_argument("--retries", type=int, default=1, help="extra attempts for a task that raises (default 1)")
    g.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: when stderr is a terminal)")
    g.add_argument("--fresh", action="store_true", help="forget the results already in --out and start again")
    g.set_defaults(func=_cmd_campaign)

    vd = sub.add_parser(
        "validate", help="fidelity against OpenFAST: free decays, means, std per band, DELs, PSD overlays",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Simulate the surrogate under the conditions of each OpenFAST reference run (its case.json) with "
                    "several seeds and compare: free-decay periods and damping, means, standard deviations in total "
                    "and per band (<0.05, 0.05-0.25, 0.4-0.6 Hz), tower-base DELs (rainflow, m = 4), with the "
                    "tolerances of issue 15. Informational: exit status 0 unless --strict.",
        epilog="Examples:\n"
               "  fowt-env validate                                  # the packaged OC3 Hywind runs, 8 seeds\n"
               "  fowt-env validate --seeds 2 --duration 200 --runs c_op12 b_decay   # quick look\n"
               "  fowt-env validate ../shared/reference/openfast/runs --json fidelity.json --plot figs\n"
               "  fowt-env validate --replay --seeds 1              # same waves and wind as OpenFAST: R² per channel\n"
               "  fowt-env validate heldout                          # runs nothing was calibrated on\n"
               "  fowt-env validate steady-seas                      # steady 12 m/s in five seas, pooled too\n"
               "  fowt-env validate time-domain --plot figs          # from OpenFAST's start: R² of its series")
    vd.add_argument("reference", nargs="?", default=None,
                    help="folder of OpenFAST outputs (.outb/.out/.npz/.csv/.parquet) with <run>.case.json sidecars "
                         "(default: the compact OC3 Hywind runs shipped with fowt-env; 'heldout': the shipped "
                         "held-out runs at 10/12/14/18 m/s with seeds nothing was calibrated on; 'steady-seas': "
                         "the shipped steady 12 m/s run in five seas (also pooled over the seas); 'time-domain': "
                         "the shipped runs that start at t = 0, replayed from OpenFAST's initial state and scored by "
                         "R² of their time series)")
    vd.add_argument("--seeds", type=int, default=8, help="surrogate seeds per operating run (default 8)")
    vd.add_argument("--duration", type=float, default=None,
                    help="simulated seconds per operating run (default: the reference's, 600 s)")
    vd.add_argument("--runs", nargs="+", default=None, metavar="NAME",
                    help="only these runs (names, prefixes or glob patterns; default all)")
    vd.add_argument("--json", default=None, metavar="OUT", help="write the full report as JSON")
    vd.add_argument("--plot", default=None, metavar="DIR", help="folder for one figure per run (PSD overlays)")
    vd.add_argument("--all-channels", action="store_true", help="list every compared channel, not only graded ones")
    vd.add_argument("--strict", action="store_true", help="exit with status 1 if a graded check fails")
    vd.add_argument("--replay", action="store_true",
                    help="drive the operating runs with their own measured wave elevation and wind (the inflow field "
                         "beside each record, else Wind1VelX) instead of random seeds; adds R² per channel and band "
                         "against OpenFAST with its linear bound (seeds then vary only the initial rotor azimuth; "
                         "--duration is ignored)")
    vd.add_argument("--wind", choices=("inflow", "hub", "synthetic"), default="inflow",
                    help="what drives each turbulent run's surrogate: 'inflow' (default) the run's own wind field, "
                         "<run>.inflow.npz beside the record, as OpenFAST saw it (the seeds vary the waves), else "
                         "'hub'; 'hub' a synthesised field conditioned on the record's Wind1VelX (repeats the run's "
                         "slow gusts, grades the turbulence model too); 'synthetic' unconditioned, at the nominal "
                         "intensity")
    vd.add_argument("--free-wind", action="store_true", help="the same as --wind synthetic")
    vd.add_argument("--time-domain", action="store_true",
                    help="replay each run of REFERENCE from its first sample (records that start at the run's t = 0) "
                         "and print R² of the surrogate's series against OpenFAST's per channel (as 'validate "
                         "time-domain' does for the shipped runs)")
    vd.set_defaults(func=_cmd_validate)

    f = sub.add_parser("fatigue", help="damage-equivalent loads (rainflow) of a record's tower moments")
    f.add_argument("record", help="record file: .npz (fowt-env), OpenFAST .out/.outb, or .csv/.parquet field data")
    f.add_argument("--channels", default=None,
                   help="comma-separated channels (default: the tower moments, TwrBsMyt/TwrBsMxt and TwHt*MLyt/MLxt)")
    f.add_argument("--m", type=float, default=4.0, help="Woehler exponent of the S-N curve (default 4)")
    f.add_argument("--frequency", type=float, default=1.0,
                   help="frequency of the equivalent load in Hz: N_eq = frequency x record length (default 1)")
    f.add_argument("--channel-map", default=None, metavar="FILE.json",
                   help='JSON object renaming file columns to channel names, e.g. {"mb_fa": "TwrBsMyt"}')
    f.add_argument("--json", default=None, help="write the DELs as JSON")
    f.set_defaults(func=_cmd_fatigue)

    m = sub.add_parser("modes", help="modal frequencies and damping of the linearised model")
    m.add_argument("--case", default=None, help="OLC number (default: parked, still water)")
    m.add_argument("--effects", default="all", help=effects_help)
    m.add_argument("--json", default=None, help="write the table as JSON")
    m.set_defaults(func=_cmd_modes)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``fowt-env`` console script.

    Usage errors (unknown or misspelt options, bad values) exit with status 2 after the subcommand's usage.
    """
    parser = build_parser()
    args, extra = parser.parse_known_args(argv)
    command = parser.subcommands[args.command]
    if extra:  # argparse would blame the top-level parser; the misspelt option belongs to the subcommand
        command.error(f"unrecognized arguments: {' '.join(extra)}")
    try:
        _check_output_folders(args)
        return int(args.func(args))
    except _UsageError as exc:
        command.error(str(exc))
    except ValueError as exc:
        if args.debug:
            raise
        print(f"fowt-env {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except (OSError, MemoryError, ArithmeticError) as exc:  # failures, not usage errors: one line, status 1
        if args.debug:
            raise
        print(f"fowt-env {args.command}: error: {_failure_text(exc, args)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # Ctrl-C: one line, the shell's status for SIGINT
        if args.debug:
            raise
        print(f"\nfowt-env {args.command}: interrupted", file=sys.stderr)
        return 130


def _check_output_folders(args: argparse.Namespace) -> None:
    """An output file (``--json``; ``--out`` of simulate, episode, sense) must go to an existing, writable folder:
    found before the work, not after it (compare and campaign create the folders they write to)."""
    import os

    names = ["out"] if args.command in ("simulate", "episode", "sense") else []
    names += ["json"] if args.command not in ("compare", "campaign") else []
    for name in names:
        value = getattr(args, name, None)
        if value is None:
            continue
        folder = Path(value).parent
        if not folder.is_dir():
            raise _UsageError(f"--{name}: the folder {str(folder)!r} of {str(value)!r} does not exist")
        if not os.access(folder, os.W_OK):
            raise _UsageError(f"--{name}: the folder {str(folder)!r} of {str(value)!r} is not writable")


def _failure_text(exc: BaseException, args: argparse.Namespace) -> str:
    """One line for a failure of the machine or the numbers (a file that cannot be written, too little memory,
    a diverged simulation)."""
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        return f"{exc.filename}: {exc.strerror or exc}"
    if isinstance(exc, MemoryError):
        return ("not enough memory for this request (a shorter --duration or a larger --dt needs less)"
                f"{': ' + str(exc).splitlines()[0] if str(exc) else ''}")
    text = (str(exc).splitlines() or [type(exc).__name__])[0]
    if isinstance(exc, ArithmeticError) and getattr(args, "effects", "all") not in ("all", "none", None):
        text += f" (with --effects {args.effects}: strengths far from 1 can make the model unstable)"
    return text


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
