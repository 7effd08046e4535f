"""Virtual-sensing comparison harness: train estimators on some load cases, test them on unseen ones.

The seed paper's virtual-sensing experiment (Abaei et al., Section 4, Tables 6-7) as a reusable grid:

1. **Train**: the surrogate is simulated for the training OLCs (default the paper's 1, 3, 4, 6, 8-12; one
   record per OLC, seed ``train_seed + OLC``); the *noisy* records -- what the sensors measure -- are given to
   each estimator's ``fit``.
2. **Test**: for every (scenario, test OLC, seed) the surrogate is simulated again (unseen OLC and/or seed);
   the sensors see the noisy record with the scenario's channels hidden (NaN, mask False), the scores compare
   the reconstruction with the noise-free truth.
3. **Score** (:mod:`estimators.metrics`): R² and NRMSE (the paper's definitions: ``1 - SSE/SST``, RMSE over the
   range of the truth) per hidden channel, on the physical full-band signals and on the paper's band-passed
   (0.25-5 Hz, zero phase), z-scored form; plus the 95 % interval coverage for sensors that report an
   uncertainty (``reconstruct(..., return_std=True)``) and the wall-clock cost per sample.

Scenarios (:data:`fowt_env.faults.SCENARIOS`): ``"A"`` hides FA sensors 2, 3, 5, 7, 11, 12, 14, 16 (paper OLC 5),
``"B"`` and ``"C"`` hide 0, 8, 9, 17 (OLC 7 and OLC 2); ``"random"`` drops every channel at random with the
two-state Markov semantics of :class:`fowt_env.faults.RandomDropout` (long-run rate and mean burst length), and
its scores are taken over the samples at which each channel was hidden (errors there, normalised by the variance
and range of the channel's whole record, so that a short burst is not judged against its own tiny variance).

The unit of work, :func:`run_unit`, is a pure function of (case, seed, scenario, estimator, update interval,
settings) returning plain JSON-able data, so any :class:`concurrent.futures.Executor` (threads, processes, Dask's
``client.get_executor()``) can run the grid and give the same numbers. Wall-clock timings live in a separate
``"wall_clock"`` part of every result; everything else is deterministic. Simulated records and fitted sensors are
memoised per process (:func:`clear_cache`); a unit works on its own deep copy of a fitted sensor.

Estimators are looked up by name in :data:`ESTIMATORS` (extensible, see :func:`register_estimator`).

Data this project did not make (issue 17): ``CompareSettings(train_files=..., test_files=...)`` (``fowt-env compare
--train FILE... --test FILE...``) trains and tests on records from files -- OpenFAST ``.out``/``.outb``, CSV/Parquet
(with ``channel_map``), ``.npz`` -- and ``kalman`` is then linearised at each test record's operating point (its
``case.json`` sidecar, metadata, or mean ``Wind1VelX``): a mismatched model, as on a real turbine.
``CompareSettings(truth_effects=...)`` (``--truth-model``) makes the simulated records come from a perturbed
surrogate (:func:`surrogates.model_error.perturbed_model`) while ``kalman`` keeps the nominal model.

Examples
--------
>>> from fowt_env.compare import CompareSettings, compare
>>> settings = CompareSettings(train_cases=(1, 6), train_duration=30.0, duration=10.0)
>>> res = compare(scenarios=["B"], estimators=["hold"], settings=settings, lyapunov_time=None)
>>> [row["hidden"] for row in res.runs][0]
['TwHt1ALxt', 'TwHt9ALxt', 'TwHt1MLyt', 'TwHt9MLyt']
>>> text = res.summary()
"""

from __future__ import annotations

import copy
import inspect
import json
import math
import threading
import time
import warnings
from collections import OrderedDict
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor
from contextlib import ContextDecorator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from estimators.metrics import reconstruction_scores

from .faults import SCENARIOS, RandomDropout

__all__ = [
    "DEFAULT_TEST_CASES",
    "ESTIMATORS",
    "PAPER_TRAIN_CASES",
    "SCENARIO_NAMES",
    "CompareResult",
    "CompareSettings",
    "clear_cache",
    "compare",
    "fit_sensor",
    "grid_units",
    "hidden_channels",
    "lyapunov_estimate",
    "parse_int_list",
    "register_estimator",
    "run_unit",
    "scenario_mask",
    "held_out_data",
    "training_data",
]

PAPER_TRAIN_CASES: tuple[int, ...] = (1, 3, 4, 6, 8, 9, 10, 11, 12)
"""The seed paper's training OLCs."""

SCENARIO_NAMES: tuple[str, ...] = ("A", "B", "C", "random")

DEFAULT_TEST_CASES: dict[str, int] = {"A": 5, "B": 7, "C": 2, "random": 7}
"""Test OLC of each scenario when no cases are given (the paper's pairing; ``random`` at rated conditions)."""

SWEEP_INTERVALS: tuple[float, ...] = (0.25, 0.5, 1.0, 2.0, 4.0)
"""Update intervals (s) of the standard sweep."""

_KALMAN_LINEARIZATION_CASE = 7  # every OLC runs at 12 m/s and 12.1 rpm: one operating point serves all


# ------------------------------------------------------------------------------------------------ registry
def _hold(dt: float, update_interval: float | None, *, channels: Sequence[str] | None = None,
          fill: str = "mean") -> Any:
    """:class:`estimators.baseline.HoldLastValue` (``fill="mean"``): the floor every estimator must beat."""
    from estimators.baseline import HoldLastValue

    return HoldLastValue(fill=fill)


_hold.uses_update_interval = False  # type: ignore[attr-defined]


def _kalman(dt: float, update_interval: float | None, *, channels: Sequence[str] | None = None,
            linearization_case: Any = _KALMAN_LINEARIZATION_CASE, gauge_heights: Sequence[float] | None = None,
            model_perturbation: dict[str, float] | None = None, **options: Any) -> Any:
    """:class:`estimators.kalman.KalmanSensor` on ``FOWTModel().linearize(load_case(7))``, rows = the channels.

    Assimilates every sample, so ``update_interval`` is ignored. ``linearization_case`` is an OLC number, a
    :class:`surrogates.LoadCase` or its ``to_dict()`` (with records from files, :func:`compare` passes the test
    record's operating point); ``gauge_heights`` (9 heights above SWL, m) places the model's gauges where the
    records' are (e.g. :data:`surrogates.OPENFAST_GAUGE_HEIGHTS` for the shared OpenFAST runs);
    ``model_perturbation`` makes the filter's model a :func:`surrogates.model_error.perturbed_model` (e.g. the
    true model of a ``truth_effects`` study). Other ``options`` go to ``KalmanSensor``.
    """
    import control

    import surrogates
    from estimators.kalman import KalmanSensor
    from surrogates.channels import tower_channels
    from surrogates.model_error import perturbed_model

    if isinstance(linearization_case, dict):
        case = surrogates.LoadCase.from_dict(linearization_case)
    elif isinstance(linearization_case, surrogates.LoadCase):
        case = linearization_case
    else:
        case = surrogates.load_case(int(linearization_case))
    names = list(channels) if channels is not None else tower_channels("FA")

    def linearize(plane: str | None) -> Any:
        def compute() -> Any:
            model = perturbed_model(model_perturbation, surrogates.FOWTModel(gauge_heights=gauge_heights))
            return _without_inert_states(model.linearize(case, plane=plane))

        key = json.dumps([case.to_dict(), plane, gauge_heights, model_perturbation], sort_keys=True, default=str)
        return _LINEARIZED.get(key, compute)

    for plane in ("FA", "SS"):
        if names == tower_channels(plane):
            return KalmanSensor(linearize(plane), dt=dt, **options)
    full = linearize(None)  # all channels: keep the rows of the observed ones
    outputs = list(full.output_labels)
    missing = [c for c in names if c not in outputs]
    if missing:
        raise ValueError(f"kalman: the linearised model has no outputs {missing}")
    rows = [outputs.index(c) for c in names]
    sys = control.ss(full.A, full.B, full.C[rows], full.D[rows], inputs=list(full.input_labels), outputs=names,
                     states=list(full.state_labels))
    return KalmanSensor(sys, dt=dt, **options)


def _without_inert_states(sys: Any) -> Any:
    """``sys`` without the states that act on nothing (zero columns of A and C), e.g. the pitch controller's
    integrator below rated wind, a pure integrator (eigenvalue 0) a Kalman filter's stationary analysis refuses.
    Exact: such a state changes no other state and no output."""
    import control

    a, c = np.asarray(sys.A), np.asarray(sys.C)
    keep = [i for i in range(a.shape[0]) if np.any(a[:, i]) or np.any(c[:, i])]
    if len(keep) == a.shape[0]:
        return sys
    labels = list(sys.state_labels)
    return control.ss(a[np.ix_(keep, keep)], np.asarray(sys.B)[keep], c[:, keep], sys.D, inputs=list(sys.input_labels),
                      outputs=list(sys.output_labels), states=[labels[i] for i in keep])


_kalman.uses_update_interval = False  # type: ignore[attr-defined]
_kalman.needs_operating_point = True  # type: ignore[attr-defined]  # records from files: at each test record's


def _dmd(dt: float, update_interval: float | None, *, channels: Sequence[str] | None = None,
         delays: int | float = 60, rank: int | float | str = 90, **options: Any) -> Any:
    """:class:`estimators.dmd_sensor.HankelDMDSensor` (rolling horizon, causal), recalibrated every
    ``update_interval`` seconds; default the paper's 60 delay samples and rank 90."""
    from estimators.dmd_sensor import HankelDMDSensor

    return HankelDMDSensor(delays=delays, rank=rank, update_interval=update_interval, dt=dt, **options)


_dmd.refit_per_interval = False  # type: ignore[attr-defined]  # the interval is set after fit, one fit serves all


def _koopman(dt: float, update_interval: float | None, *, channels: Sequence[str] | None = None,
             **options: Any) -> Any:
    """:class:`estimators.koopman_kalman.KoopmanKalmanSensor` (a Kalman filter on the Hankel-DMD model, its
    own defaults: 60 delay samples, rank 40); assimilates every sample, so ``update_interval`` is ignored."""
    from estimators.koopman_kalman import KoopmanKalmanSensor

    return KoopmanKalmanSensor(dt=dt, **options)


_koopman.uses_update_interval = False  # type: ignore[attr-defined]

ESTIMATORS: dict[str, Callable[..., Any]] = {"hold": _hold, "kalman": _kalman, "dmd": _dmd, "koopman": _koopman}
"""Virtual sensors by name: ``factory(dt, update_interval, *, channels, **options) -> unfitted sensor``.

``dt`` is the sample time (s), ``update_interval`` the time between recalibrations (s; None for sensors that
ignore it), ``channels`` the names of the channels the sensor will see (in order), ``options`` the user's
per-estimator options (:attr:`CompareSettings.estimator_options`). The sensor follows the protocol of
:mod:`estimators.baseline` in physical units.

Optional attributes of a factory:

* ``uses_update_interval`` (default True): False if the sensor ignores it; it is then run once per
  (scenario, case, seed) and reported with ``update_interval`` None;
* ``refit_per_interval`` (default True): False if the fitted sensor's ``update_interval`` attribute may be
  changed after ``fit`` (taking effect at ``reset()``), so one fit serves every interval of a sweep;
* ``concatenate_training`` (default False): True if the sensor's ``fit`` takes one array rather than a list of
  records (the training records are then stacked).

Built in: ``"hold"`` (HoldLastValue, training mean until a channel is seen), ``"kalman"`` (KalmanSensor on the
linearised surrogate), ``"dmd"`` (HankelDMDSensor), ``"koopman"`` (KoopmanKalmanSensor). Add your own with
:func:`register_estimator` or by assigning to this dict. With a process-based executor, register them in an
importable module so that the worker processes see them too.
"""


def register_estimator(name: str, factory: Callable[..., Any], *, uses_update_interval: bool = True,
                       concatenate_training: bool = False, replace: bool = False) -> None:
    """Add a virtual sensor to :data:`ESTIMATORS`.

    Parameters
    ----------
    name : str
        Name used by :func:`compare` and ``fowt-env compare --estimators``.
    factory : callable
        ``factory(dt, update_interval, *, channels, **options)`` returning an unfitted sensor.
    uses_update_interval : bool
        False if the sensor assimilates every sample (then it is run once per scenario, case and seed).
    concatenate_training : bool
        True if its ``fit`` accepts one array only.
    replace : bool
        Allow replacing an existing entry.
    """
    if not isinstance(name, str) or not name or "," in name:
        raise ValueError(f"name must be a non-empty string without commas, got {name!r}")
    if not callable(factory):
        raise ValueError(f"factory must be callable, got {type(factory).__name__}")
    if name in ESTIMATORS and not replace:
        raise ValueError(f"estimator {name!r} is already registered (pass replace=True)")
    factory.uses_update_interval = bool(uses_update_interval)  # type: ignore[attr-defined]
    factory.concatenate_training = bool(concatenate_training)  # type: ignore[attr-defined]
    ESTIMATORS[name] = factory


def _factory(name: str) -> Callable[..., Any]:
    try:
        return ESTIMATORS[name]
    except KeyError:
        raise ValueError(f"unknown estimator {name!r}; available: {', '.join(ESTIMATORS)}") from None


def _uses_interval(name: str) -> bool:
    return bool(getattr(_factory(name), "uses_update_interval", True))


# ------------------------------------------------------------------------------------------------ settings
@dataclass(frozen=True)
class CompareSettings:
    """Everything about a comparison that is not a grid axis (case, seed, scenario, estimator, interval).

    Parameters
    ----------
    train_cases : tuple of int
        Training OLCs (default the paper's 1, 3, 4, 6, 8-12).
    train_duration : float
        Length of each training record (s).
    train_seed : int
        The training record of OLC ``c`` uses seed ``train_seed + c``; test seeds must differ from it.
    duration : float
        Length of each test record (s).
    dt : float
        Sample time (s), 0.0125 = 80 Hz as the paper's data.
    plane : {"FA", "SS"} or None
        The paper's 18 channels of one plane, or None for all 36 tower channels. The scenarios' hidden indices
        refer to the 18-channel planar order (for None: the FA channels).
    band : (float, float)
        Band (Hz) of the paper's band-passed scores.
    dropout_rate, dropout_burst_s : float
        Long-run lost fraction per channel and mean burst length (s) of the ``"random"`` scenario.
    estimator_options : dict
        Per-estimator keyword options for the factories, e.g. ``{"dmd": {"rank": 24}}``.
    trace_seconds : float
        Length (s) of the end of each test record kept in memory for :meth:`CompareResult.plot` (0: none).
    train_files, test_files : tuple of str
        Records from files instead of simulations (both or neither): anything :func:`fowt_env.io.load_record`
        reads (OpenFAST ``.out``/``.outb``, ``.csv``/``.parquet``, ``.npz``). The sensors see the plane's tower
        channels present in every one of them; the test OLCs of the grid become indices into ``test_files``,
        the seeds only seed the ``"random"`` masks, and the scores compare with the record itself (it is the
        truth: no noise-free copy exists). ``dt`` is replaced by the records' sample time (they must share one),
        ``train_cases``/``train_seed``/``duration`` are unused. Model-based sensors (``kalman``) are linearised at
        each test record's operating point: its ``<name>.case.json`` sidecar, else its metadata's ``case``, else
        the mean of ``Wind1VelX`` (and 4 std / the spectral peak of ``Wave1Elev``).
    channel_map : dict
        Records from files: file column name -> fowt-env channel name, for every format
        (:func:`fowt_env.io.load_record`'s ``channel_map``), e.g. a CSV whose columns are not OpenFAST's names.
    truth_effects : dict
        Surrogate records only: the training and test records come from
        :func:`surrogates.model_error.perturbed_model` with these perturbations (e.g. ``{"tower_stiffness":
        0.95}``) while ``kalman`` keeps the nominal model -- the model-error axis. Empty: the nominal model.
    """

    train_cases: tuple[int, ...] = PAPER_TRAIN_CASES
    train_duration: float = 300.0
    train_seed: int = 1000
    duration: float = 600.0
    dt: float = 0.0125
    plane: str | None = "FA"
    band: tuple[float, float] = (0.25, 5.0)
    dropout_rate: float = 0.2
    dropout_burst_s: float = 2.0
    estimator_options: dict[str, dict[str, Any]] = field(default_factory=dict)
    trace_seconds: float = 20.0
    train_files: tuple[str, ...] = ()
    test_files: tuple[str, ...] = ()
    truth_effects: dict[str, float] = field(default_factory=dict)
    channel_map: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        import surrogates
        from surrogates.model_error import check_perturbations

        for name in ("train_files", "test_files"):
            files = getattr(self, name)
            files = (files,) if isinstance(files, (str, Path)) else tuple(files or ())
            object.__setattr__(self, name, tuple(str(f) for f in files))
        if bool(self.train_files) != bool(self.test_files):
            raise ValueError("train_files and test_files must be given together (records from files), or neither")
        object.__setattr__(self, "truth_effects", check_perturbations(self.truth_effects))
        cmap = self.channel_map or {}
        if not (isinstance(cmap, dict) and all(isinstance(k, str) and isinstance(v, str) for k, v in cmap.items())):
            raise ValueError(f"channel_map must map file column names to channel names (str -> str), got {cmap!r}")
        object.__setattr__(self, "channel_map", dict(cmap))
        if self.files and self.truth_effects:
            raise ValueError("truth_effects perturbs simulated records; records from files are their own truth")
        if self.files:
            self._init_files()

        cases = tuple(int(c) for c in np.atleast_1d(self.train_cases))
        if not cases:
            raise ValueError("train_cases must name at least one OLC")
        for c in cases:
            try:
                surrogates.load_case(c)
            except ValueError as exc:
                raise ValueError(f"train_cases: {exc}") from None
        object.__setattr__(self, "train_cases", cases)
        for name in ("train_duration", "duration", "dt", "dropout_burst_s"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float, np.number)) and math.isfinite(float(v)) and float(v) > 0):
                raise ValueError(f"{name} must be a positive finite number of seconds, got {v!r}")
            object.__setattr__(self, name, float(v))
        if not (isinstance(self.train_seed, (int, np.integer)) and self.train_seed >= 0):
            raise ValueError(f"train_seed must be a non-negative integer, got {self.train_seed!r}")
        if self.plane not in ("FA", "SS", None):
            raise ValueError(f"plane must be 'FA', 'SS' or None, got {self.plane!r}")
        lo, hi = (float(b) for b in self.band)
        if not (0 < lo < hi < 0.5 / self.dt):
            raise ValueError(f"band must be (low, high) Hz with 0 < low < high < Nyquist = {0.5 / self.dt} Hz, "
                             f"got {self.band!r}")
        object.__setattr__(self, "band", (lo, hi))
        if not 0.0 <= float(self.dropout_rate) < 1.0:
            raise ValueError(f"dropout_rate must be in [0, 1), got {self.dropout_rate!r}")
        object.__setattr__(self, "dropout_rate", float(self.dropout_rate))
        if not (math.isfinite(float(self.trace_seconds)) and self.trace_seconds >= 0):
            raise ValueError(f"trace_seconds must be >= 0, got {self.trace_seconds!r}")
        opts = self.estimator_options or {}
        if not isinstance(opts, dict) or not all(isinstance(v, dict) for v in opts.values()):
            raise ValueError("estimator_options must map estimator names to dicts of keyword options")
        object.__setattr__(self, "estimator_options", {str(k): dict(v) for k, v in opts.items()})
        if round(self.duration / self.dt) < 10:
            raise ValueError(f"duration={self.duration} s is shorter than 10 samples")

    def _init_files(self) -> None:
        """Read the records (memoised), take their common sample time and channels; check the test records."""
        from surrogates.channels import ALL_CHANNELS, tower_channels

        wanted = tower_channels(self.plane) if self.plane is not None else list(ALL_CHANNELS[:36])
        recs = [_file_record(f, self.channel_map) for f in self.train_files + self.test_files]
        dts = sorted({r.dt for r in recs})
        if dts[-1] - dts[0] > 1e-9 * dts[0]:
            listing = ", ".join(f"{r.name}: {r.dt:g} s" for r in recs)
            raise ValueError(f"the records must share one sample time; got {listing}")
        object.__setattr__(self, "dt", dts[0])
        common = [c for c in wanted if all(c in r.channels for r in recs)]
        if not common:
            raise ValueError(f"the records have no {self.plane or 'tower'} channel in common (looked for "
                             f"{wanted[0]} ... {wanted[-1]})")
        object.__setattr__(self, "_file_channels", common)
        train = {str(Path(f).resolve()) for f in self.train_files}
        both = [f for f in self.test_files if str(Path(f).resolve()) in train]
        if both:
            raise ValueError(f"test file(s) {both} are also training files: test on records the sensors did not "
                             f"see")

    @property
    def files(self) -> bool:
        """True if the records come from files (:attr:`train_files`, :attr:`test_files`)."""
        return bool(self.test_files)

    @property
    def channels(self) -> list[str]:
        """Names of the channels the sensors see, in order."""
        from surrogates.channels import ALL_CHANNELS, tower_channels

        if self.files:
            return list(self.__dict__["_file_channels"])
        return tower_channels(self.plane) if self.plane is not None else list(ALL_CHANNELS[:36])

    def test_name(self, case: int) -> str:
        """Label of test record ``case``: its file name (records from files) or ``OLC <case>``."""
        return Path(self.test_files[int(case)]).name if self.files else f"OLC {int(case)}"

    def train_seed_of(self, case: int) -> int:
        """Seed of the training record of OLC ``case``."""
        return int(self.train_seed) + int(case)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready settings."""
        d = asdict(self)
        d["train_cases"] = list(self.train_cases)
        d["band"] = list(self.band)
        d["train_files"], d["test_files"] = list(self.train_files), list(self.test_files)
        for name in ("train_files", "test_files", "truth_effects", "channel_map"):
            if not d[name]:  # unused: left out, so that results and campaigns of earlier versions still match
                del d[name]
        d["channels"] = self.channels
        return d

    def _key(self, *names: str) -> str:
        d = self.to_dict()
        d.update({n: getattr(self, n) for n in names if n not in d})  # the unused ones to_dict leaves out
        return json.dumps({n: d[n] for n in names} if names else d, sort_keys=True, default=str)


# ------------------------------------------------------------------------------------------------ caching
class _Memo:
    """A small thread-safe LRU memo: one computation per key even when threads ask at once."""

    def __init__(self, size: int) -> None:
        self.size = size
        self._lock = threading.Lock()
        self._items: OrderedDict[str, list] = OrderedDict()  # key -> [lock, done, value]

    def get(self, key: str, compute: Callable[[], Any]) -> Any:
        with self._lock:
            item = self._items.get(key)
            if item is None:
                item = self._items[key] = [threading.Lock(), False, None]
                while len(self._items) > self.size:
                    self._items.popitem(last=False)
            else:
                self._items.move_to_end(key)
        with item[0]:
            if not item[1]:
                item[2] = compute()
                item[1] = True
        return item[2]

    def clear(self) -> None:
        with self._lock:
            self._items.clear()


class _OneBlasThread(ContextDecorator):
    """One BLAS thread while the harness computes, so that results do not depend on the executor.

    OpenBLAS splits its reductions between threads, so the last digits of a result depend on how many it uses; Dask
    workers run with one (``OMP_NUM_THREADS=1``), a plain process with one per core. Reference-counted: units
    running in several threads at once share one limit, restored when the last one ends. The drivers
    (:func:`compare`, :func:`fowt_env.campaign.run_campaign`) hold it in the caller's thread while their units run
    in pool threads: OpenBLAS may ignore a limit set from another thread once its thread count was raised again.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._users = 0
        self._limiter: Any = None

    def __enter__(self) -> _OneBlasThread:
        from threadpoolctl import threadpool_info, threadpool_limits

        with self._lock:
            if self._users == 0:
                self._limiter = threadpool_limits(limits=1, user_api="blas")
                if any(lib["num_threads"] != 1 for lib in threadpool_info() if lib["user_api"] == "blas"):
                    warnings.warn("could not limit BLAS to one thread here: results may differ from those of "
                                  "other executors in the last digits", RuntimeWarning, stacklevel=3)
            self._users += 1
        return self

    def __exit__(self, *exc: object) -> None:
        with self._lock:
            self._users -= 1
            if self._users == 0:
                self._limiter.restore_original_limits()
                self._limiter = None


_one_blas_thread = _OneBlasThread()

_TRAIN_DATA = _Memo(2)
_LINEARIZED = _Memo(8)
_TEST_DATA = _Memo(8)
_SENSORS = _Memo(16)


def clear_cache() -> None:
    """Forget the memoised simulations and fitted sensors of this process."""
    for memo in (_TRAIN_DATA, _TEST_DATA, _SENSORS, _LINEARIZED, _FILES):
        memo.clear()


def _model(settings: CompareSettings | None = None):
    """The model that makes the records: nominal, or perturbed by ``settings.truth_effects``."""
    import surrogates
    from surrogates.model_error import perturbed_model

    return perturbed_model(settings.truth_effects if settings is not None else None, surrogates.FOWTModel())


# ------------------------------------------------------------------------------------------------ files
@dataclass(frozen=True)
class _FileRecord:
    """The part of a record file the harness uses: tower channels, sample time, operating point."""

    name: str
    dt: float
    channels: tuple[str, ...]
    y: np.ndarray  # (n_samples, n_channels), the tower channels present
    operating: dict[str, Any] | None  # LoadCase.to_dict() of the operating point, or None
    operating_source: str


_FILES = _Memo(16)
_OPERATING_KEYS = ("wind_speed", "hs", "tp", "gamma", "wave_dir_deg", "turbulence_intensity")


def _file_record(path: str, channel_map: dict[str, str] | None = None) -> _FileRecord:
    """Read a record file once per process (keyed by path, size, modification time and channel map)."""
    p = Path(path)
    cmap = dict(channel_map or {})
    try:
        st = p.stat()
        key = json.dumps([str(p.resolve()), st.st_size, st.st_mtime_ns, cmap], sort_keys=True)
    except OSError:
        key = json.dumps([str(p), None, None, cmap], sort_keys=True)  # load_record says what is wrong
    return _FILES.get(key, lambda: _read_file_record(p, cmap))


def _read_file_record(p: Path, channel_map: dict[str, str]) -> _FileRecord:
    from surrogates.channels import ALL_CHANNELS

    from .io import load_record

    table = p.suffix.lower() in (".csv", ".parquet")
    rec = load_record(p, channel_map=channel_map or None, **({"unknown_channels": "keep"} if table else {}))
    if rec.y.shape[0] < 10:
        raise ValueError(f"{p}: a record of {rec.y.shape[0]} samples is too short to test on")
    tower = [c for c in ALL_CHANNELS[:36] if c in rec.channels]
    y = np.ascontiguousarray(rec.select(tower).y, dtype=float) if tower else np.zeros((rec.y.shape[0], 0))
    dt = float(f"{float(rec.dt):.9g}")  # 0.0999999999999 (a float time axis) -> 0.1
    operating, source = _operating_point(p, rec)
    return _FileRecord(p.name, dt, tuple(tower), y, operating, source)


def _operating_point(p: Path, rec: Any) -> tuple[dict[str, Any] | None, str]:
    """Operating point of a record: sidecar ``<stem>.case.json``, else ``meta["case"]``, else the channels."""
    import surrogates

    def from_mapping(d: dict[str, Any]) -> dict[str, Any] | None:
        if not isinstance(d, dict) or not isinstance(d.get("wind_speed"), (int, float)) or d["wind_speed"] <= 0:
            return None
        kw = {k: float(d[k]) for k in _OPERATING_KEYS[1:] if isinstance(d.get(k), (int, float))}
        lc = surrogates.operating_case(float(d["wind_speed"]), **kw)
        if isinstance(d.get("rotor_rpm"), (int, float)) and d["rotor_rpm"] > 0:
            lc = lc.replace(rotor_rpm=float(d["rotor_rpm"]))
        return lc.to_dict()

    stem = p.name[: -len(p.suffix)] if p.suffix else p.name
    sidecar = p.with_name(stem + ".case.json")
    if sidecar.is_file():
        try:
            found = from_mapping(json.loads(sidecar.read_text(encoding="utf-8")))
        except (OSError, ValueError):
            found = None
        if found is not None:
            return found, f"sidecar {sidecar.name}"
    meta_case = (rec.meta or {}).get("case") if isinstance(getattr(rec, "meta", None), dict) else None
    if isinstance(meta_case, dict):
        found = from_mapping(meta_case)
        if found is not None:
            return found, "record metadata"
    if "Wind1VelX" in rec.channels:
        u = np.asarray(rec["Wind1VelX"], dtype=float)
        u = u[np.isfinite(u)]
        if u.size and float(np.mean(u)) > 0:
            d: dict[str, Any] = {"wind_speed": float(np.mean(u)), "turbulence_intensity": float(np.std(u) /
                                                                                                np.mean(u))}
            source = "mean of Wind1VelX"
            if "Wave1Elev" in rec.channels:
                from scipy.signal import welch

                eta = np.asarray(rec["Wave1Elev"], dtype=float)
                eta = eta[np.isfinite(eta)]
                if eta.size > 64 and np.std(eta) > 0:
                    f, pxx = welch(eta - eta.mean(), fs=1.0 / float(rec.dt), nperseg=min(eta.size, 8192))
                    band = (f > 0.03) & (f < 0.5)
                    d.update(hs=4.0 * float(np.std(eta)), tp=1.0 / float(f[band][np.argmax(pxx[band])]))
                    source += ", Hs and Tp from Wave1Elev"
            return from_mapping(d), source
    return None, "none (no case.json sidecar, no metadata, no Wind1VelX)"


def _select(record, settings: CompareSettings) -> np.ndarray:
    return np.ascontiguousarray(record.select(settings.channels).y)


def training_data(settings: CompareSettings) -> list[np.ndarray]:
    """The noisy training records (one ``(n_samples, n_channels)`` array per training OLC), memoised."""
    import surrogates

    def compute() -> list[np.ndarray]:
        if settings.files:
            return [_file_columns(f, settings) for f in settings.train_files]
        model = _model(settings)
        return [_select(surrogates.simulate(model, c, duration=settings.train_duration, dt=settings.dt,
                                            seed=settings.train_seed_of(c)), settings)
                for c in settings.train_cases]

    key = settings._key("train_cases", "train_duration", "train_seed", "dt", "plane", "train_files",
                        "truth_effects", "channel_map")
    return [a.copy() for a in _TRAIN_DATA.get(key, compute)]


def _file_columns(path: str, settings: CompareSettings) -> np.ndarray:
    rec = _file_record(path, settings.channel_map)
    return np.ascontiguousarray(rec.y[:, [rec.channels.index(c) for c in settings.channels]])


def held_out_data(case: int, seed: int, settings: CompareSettings) -> tuple[np.ndarray, np.ndarray]:
    """``(noisy, truth)`` arrays ``(n_samples, n_channels)`` of a test record, memoised."""
    import surrogates

    def compute() -> tuple[np.ndarray, np.ndarray]:
        if settings.files:  # the record is the truth; there is no noise-free copy of a measurement
            y = _file_columns(settings.test_files[int(case)], settings)
            return y, y
        noisy, truth = surrogates.simulate(_model(settings), int(case), duration=settings.duration, dt=settings.dt,
                                           seed=int(seed), return_truth=True)
        return _select(noisy, settings), _select(truth, settings)

    key = json.dumps([int(case), 0 if settings.files else int(seed),
                      settings._key("duration", "dt", "plane", "test_files", "truth_effects", "channel_map")])
    noisy, truth = _TEST_DATA.get(key, compute)
    return noisy.copy(), truth.copy()


def _operating_options(estimator: str, settings: CompareSettings, case: int | None) -> dict[str, Any]:
    """Records from files: ``{"linearization_case": <the test record's operating point>}`` for the sensors that
    need one (factory attribute ``needs_operating_point``), unless the user's options fix it; else ``{}``."""
    factory = _factory(estimator)
    if not (settings.files and getattr(factory, "needs_operating_point", False)):
        return {}
    if "linearization_case" in settings.estimator_options.get(estimator, {}):
        return {}
    rec = _file_record(settings.test_files[0 if case is None else int(case)], settings.channel_map)
    if rec.operating is None:
        raise ValueError(f"estimator {estimator!r} needs the operating point of test record {rec.name}: "
                         f"{rec.operating_source}; give it, e.g. {estimator}.linearization_case=7 (an OLC)")
    return {"linearization_case": rec.operating}


def _new_sensor(estimator: str, update_interval: float | None, settings: CompareSettings,
                extra: dict[str, Any] | None = None) -> Any:
    factory = _factory(estimator)
    opts = {**settings.estimator_options.get(estimator, {}), **(extra or {})}
    try:
        return factory(settings.dt, update_interval, channels=settings.channels, **opts)
    except ImportError as exc:
        raise ValueError(f"estimator {estimator!r} is not available: {exc}") from None
    except TypeError as exc:
        raise ValueError(f"estimator {estimator!r}: bad options {opts}: {exc}") from None


def _fitted(estimator: str, update_interval: float | None, settings: CompareSettings,
            case: int | None = None) -> tuple[Any, float]:
    """A deep copy of the memoised fitted sensor, and the wall-clock seconds its fit took.

    ``case`` (records from files): the test record, whose operating point model-based sensors are linearised at.
    """
    interval = update_interval if _uses_interval(estimator) else None
    refit = getattr(_factory(estimator), "refit_per_interval", True)
    fit_interval = interval if refit or interval is None else 1.0
    extra = _operating_options(estimator, settings, case)

    def compute() -> tuple[Any, float]:
        sensor = _new_sensor(estimator, fit_interval, settings, extra)
        data = training_data(settings)
        if getattr(_factory(estimator), "concatenate_training", False):
            data = np.concatenate(data, axis=0)
        t0 = time.perf_counter()
        sensor.fit(data)
        return sensor, time.perf_counter() - t0

    key = json.dumps([estimator, fit_interval, extra,
                      settings._key("train_cases", "train_duration", "train_seed", "dt", "plane", "estimator_options",
                                    "train_files", "truth_effects", "channel_map")], default=str)
    sensor, fit_s = _SENSORS.get(key, compute)
    sensor = copy.deepcopy(sensor)
    if fit_interval != interval:
        sensor.update_interval = interval  # takes effect at the sensor's next reset()
    return sensor, fit_s


@_one_blas_thread
def fit_sensor(estimator: str, settings: CompareSettings | None = None,
               update_interval: float | None = 1.0) -> Any:
    """The fitted sensor the harness uses (an independent copy), e.g. to run it live in the Gym env.

    Parameters
    ----------
    estimator : str
        Name in :data:`ESTIMATORS`.
    settings : CompareSettings, optional
        Training set-up (default :class:`CompareSettings()`).
    update_interval : float, optional
        Time between recalibrations (s), for sensors that use it.

    Returns
    -------
    object
        A fitted sensor following the virtual-sensor protocol.
    """
    settings = settings or CompareSettings()
    return _fitted(estimator, _check_interval(update_interval) if update_interval is not None else None,
                   settings)[0]


# ------------------------------------------------------------------------------------------------ scenarios
def hidden_channels(scenario: str, settings: CompareSettings) -> list[str]:
    """Names of the channels a fixed scenario hides (empty for ``"random"``)."""
    from surrogates.channels import tower_channels

    if scenario == "random":
        return []
    if scenario not in SCENARIOS:
        raise ValueError(f"unknown scenario {scenario!r}; choose from {', '.join(SCENARIO_NAMES)}")
    planar = tower_channels(settings.plane or "FA")
    present = set(settings.channels)
    return [planar[i] for i in SCENARIOS[scenario]["hidden"] if planar[i] in present]


def scenario_mask(scenario: str, n_samples: int, settings: CompareSettings, *, seed: int = 0,
                  case: int = 0) -> np.ndarray:
    """Availability mask ``(n_samples, n_channels)`` of a scenario (True = sensor available).

    Fixed scenarios hide their channels throughout. ``"random"`` runs :class:`fowt_env.faults.RandomDropout`
    (``settings.dropout_rate``, ``settings.dropout_burst_s``) on every channel, sample by sample, with a random
    stream seeded by ``(seed, case)`` (independent of the record's own noise).
    """
    channels = settings.channels
    mask = np.ones((int(n_samples), len(channels)), dtype=bool)
    if scenario == "random":
        fault = RandomDropout(settings.dropout_rate, settings.dropout_burst_s)
        fault.reset(np.random.default_rng(np.random.SeedSequence([int(seed), int(case), 0x5CE7A210])), channels,
                    settings.dt)
        y = np.zeros(len(channels))
        for k in range(mask.shape[0]):
            fault.apply(k, y, mask[k])
        return mask
    hidden = hidden_channels(scenario, settings)
    mask[:, [channels.index(c) for c in hidden]] = False
    return mask


# ------------------------------------------------------------------------------------------------ scoring
def _num(x: Any) -> float | None:
    """A JSON-safe float (None for NaN/inf)."""
    x = float(x)
    return x if math.isfinite(x) else None


def _supports_std(sensor: Any) -> bool:
    try:
        return "return_std" in inspect.signature(sensor.reconstruct).parameters
    except (TypeError, ValueError):
        return False


def _channel_scores(truth: np.ndarray, est: np.ndarray, std: np.ndarray | None, hidden: np.ndarray,
                    settings: CompareSettings) -> list[dict[str, Any]]:
    """Scores of every channel that was hidden at least once, over the samples at which it was hidden.

    A channel hidden throughout is scored on the whole record with :func:`reconstruction_scores`. For a channel
    hidden only part of the time see :func:`_hidden_scores`; for the band-passed form both signals are filtered
    over the whole record first (the filter must not see the gaps).
    """
    from scipy.signal import sosfiltfilt

    from estimators.preprocess import band_sos

    fs = 1.0 / settings.dt
    sos = band_sos(fs, settings.band)
    units = _units(settings.channels)
    rows = []
    for j in np.flatnonzero(hidden.any(axis=0)):
        h = hidden[:, j]
        row: dict[str, Any] = {"channel": settings.channels[j], "index": int(j), "unit": units[j],
                               "hidden_fraction": float(h.mean()), "n_scored": int(h.sum())}
        y, e = truth[:, j], est[:, j]
        bad = int(np.sum(~np.isfinite(e[h])))
        row["nonfinite_estimates"] = bad
        # an estimate far outside anything the channel did: the sensor diverged (reported, scored as it is)
        span = float(np.ptp(y)) or 1.0
        row["diverged"] = bool(np.any(np.abs(e[h][np.isfinite(e[h])] - np.mean(y)) > _DIVERGED * span))
        if bad or h.sum() < 2:
            row.update(r2=None, nrmse=None, r2_band=None, nrmse_band=None)
        elif h.all():
            s = reconstruction_scores(y[:, None], e[:, None], fs, band=settings.band)
            row.update({k: _num(v[0]) for k, v in s.items()})
        else:
            yf, ef = sosfiltfilt(sos, y), sosfiltfilt(sos, e)
            r2, nr = _hidden_scores(y, e, h)
            r2_band, nr_band = _hidden_scores(yf, ef, h)
            row.update(r2=r2, nrmse=nr, r2_band=r2_band, nrmse_band=nr_band)
        if std is not None and not bad:
            row["coverage95"] = float(np.mean(np.abs(y[h] - e[h]) <= 1.959964 * std[h, j]))
        rows.append(row)
    return rows


_DIVERGED = 100.0
"""An estimate further than this many times the truth's range from its mean marks the sensor as diverged."""


def _hidden_scores(y: np.ndarray, e: np.ndarray, hidden: np.ndarray) -> tuple[float | None, float | None]:
    """R² and NRMSE of the hidden samples of a channel, normalised by the whole record of its truth.

    ``R² = 1 - mean_hidden (y - e)² / var(y)`` and ``NRMSE = rms_hidden (y - e) / (max(y) - min(y))``, with
    the variance and range over the whole record: for a channel hidden throughout these are the seed paper's
    definitions (:func:`estimators.metrics.r2_score`, :func:`~estimators.metrics.nrmse`), and for one hidden in
    short bursts they do not blow up because a half-second stretch varies little about its own mean (scored on
    its own, a good reconstruction of a 0.5 s burst can get R² << 0).
    """
    err = y[hidden] - e[hidden]
    mse = float(np.mean(err * err))
    var, rng = float(np.var(y)), float(np.ptp(y))
    r2 = 1.0 - mse / var if var > 0 else (1.0 if mse == 0 else -math.inf)
    nr = math.sqrt(mse) / rng if rng > 0 else (0.0 if mse == 0 else math.inf)
    return _num(r2), _num(nr)


def _units(channels: list[str]) -> list[str]:
    import surrogates

    return surrogates.FOWTModel.units(channels)


def _median(values: Iterable[float | None]) -> float | None:
    v = [x for x in values if x is not None]
    return float(np.median(v)) if v else None


def _worst(values: Iterable[float | None]) -> float | None:
    return _best(values, min)


def _best(values: Iterable[float | None], pick: Callable[[list[float]], float]) -> float | None:
    v = [x for x in values if x is not None]
    return float(pick(v)) if v else None


def _aggregate(rows: list[dict[str, Any]]) -> dict[str, Any]:
    return {"median_r2": _median(r["r2"] for r in rows), "worst_r2": _worst(r["r2"] for r in rows),
            "median_nrmse": _median(r["nrmse"] for r in rows), "worst_nrmse": _best([r["nrmse"] for r in rows], max),
            "median_r2_band": _median(r["r2_band"] for r in rows),
            "worst_r2_band": _worst(r["r2_band"] for r in rows),
            "median_nrmse_band": _median(r["nrmse_band"] for r in rows),
            "median_coverage95": _median(r.get("coverage95") for r in rows),
            "pooled_coverage95": _pooled_coverage(rows),
            "worst_coverage95": _best([r.get("coverage95") for r in rows], _furthest_from_nominal)}


def _furthest_from_nominal(coverages: list[float]) -> float:
    return max(coverages, key=lambda c: abs(c - 0.95))


def _pooled_coverage(rows: list[dict[str, Any]]) -> float | None:
    """Fraction of all scored hidden samples (every channel of ``rows``) inside the +-1.96 std interval."""
    pairs = [(r["coverage95"], r["n_scored"]) for r in rows if r.get("coverage95") is not None and r.get("n_scored")]
    n = sum(w for _, w in pairs)
    return float(sum(c * w for c, w in pairs) / n) if n else None


def _check_interval(update_interval: Any) -> float:
    try:
        v = float(update_interval)
    except (TypeError, ValueError):
        v = float("nan")
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"update_interval must be a positive number of seconds, got {update_interval!r}")
    return v


# ------------------------------------------------------------------------------------------------ unit of work
@_one_blas_thread
def run_unit(case: int, seed: int, scenario: str, estimator: str, update_interval: float | None,
             settings: CompareSettings) -> dict[str, Any]:
    """One cell of the grid: fit (memoised), reconstruct a test record, score the hidden channels.

    A pure function of its arguments apart from the ``"wall_clock"`` entry: the rest of the returned dict is
    identical whichever process or thread runs it.

    Parameters
    ----------
    case : int
        Test OLC.
    seed : int
        Seed of the test record (and of the ``"random"`` scenario's mask stream).
    scenario : {"A", "B", "C", "random"}
    estimator : str
        Name in :data:`ESTIMATORS`.
    update_interval : float or None
        Time between recalibrations (s); ignored (reported as None) for sensors that do not use it.
    settings : CompareSettings

    Returns
    -------
    dict
        ``case``, ``seed``, ``scenario``, ``estimator``, ``update_interval``, ``case_in_training``, ``hidden``
        (channel names), ``n_samples``, ``channels`` (per hidden channel: ``r2``, ``nrmse``, ``r2_band``,
        ``nrmse_band``, ``coverage95`` if the sensor reports a standard deviation, ``hidden_fraction``,
        ``n_scored``), the aggregates ``median_r2``, ``worst_r2``, ``median_nrmse``, ``median_r2_band``,
        ``worst_r2_band``, ``median_nrmse_band``, ``median_coverage95``, ``pooled_coverage95`` (over every hidden
        sample of every hidden channel), ``worst_coverage95`` (the channel furthest from 0.95); ``trace`` (the last
        ``settings.trace_seconds`` of truth and estimate of the hidden channels, for plots) and ``wall_clock``
        (``fit_s``, ``reconstruct_s``, ``us_per_sample``; not reproducible).
    """
    if scenario not in SCENARIO_NAMES:
        raise ValueError(f"unknown scenario {scenario!r}; choose from {', '.join(SCENARIO_NAMES)}")
    interval = _check_interval(update_interval) if _uses_interval(estimator) else None
    sensor, fit_s = _fitted(estimator, interval, settings, case if settings.files else None)
    noisy, truth = held_out_data(case, seed, settings)
    mask = scenario_mask(scenario, noisy.shape[0], settings, seed=seed, case=case)
    measured = np.where(mask, noisy, np.nan)
    with_std = _supports_std(sensor)
    t0 = time.perf_counter()
    if with_std:
        est, std = sensor.reconstruct(measured, mask, return_std=True)
        std = np.asarray(std, dtype=float)
    else:
        est, std = sensor.reconstruct(measured, mask), None
    wall = time.perf_counter() - t0
    est = np.asarray(est, dtype=float)
    if est.shape != truth.shape:
        raise ValueError(f"estimator {estimator!r}: reconstruct returned shape {est.shape}, expected {truth.shape}")
    hidden = ~mask
    rows = _channel_scores(truth, est, std, hidden, settings)
    out: dict[str, Any] = {
        "scenario": scenario, "case": int(case), "seed": int(seed), "estimator": estimator,
        "update_interval": interval, "case_in_training": not settings.files and int(case) in settings.train_cases,
        "record": settings.test_name(case),
        "hidden": [r["channel"] for r in rows], "n_samples": int(truth.shape[0]),
        "lost_fraction": float(hidden.mean()), "channels": rows, **_aggregate(rows),
    }
    if settings.files:
        rec = _file_record(settings.test_files[int(case)], settings.channel_map)
        out["operating_point"] = {"wind_speed": (rec.operating or {}).get("wind_speed"),
                                  "source": rec.operating_source}
    out["trace"] = _trace(truth, est, hidden, rows, settings)
    out["wall_clock"] = {"fit_s": fit_s, "reconstruct_s": wall, "us_per_sample": 1e6 * wall / truth.shape[0]}
    return out


def _trace(truth: np.ndarray, est: np.ndarray, hidden: np.ndarray, rows: list[dict], settings: CompareSettings,
           max_channels: int = 8) -> dict[str, Any] | None:
    n = min(truth.shape[0], int(round(settings.trace_seconds / settings.dt)))
    if n < 2 or not rows:
        return None
    k0 = truth.shape[0] - n
    idx = [r["index"] for r in rows]
    if len(idx) > max_channels:  # random dropouts: the channels most often hidden in the window
        counts = hidden[k0:, idx].sum(axis=0)
        idx = [idx[i] for i in sorted(np.argsort(-counts, kind="stable")[:4])]
    return {"t0": k0 * settings.dt, "dt": settings.dt, "channels": [settings.channels[j] for j in idx],
            "units": [_units(settings.channels)[j] for j in idx],
            "truth": truth[k0:, idx].T.tolist(), "estimate": est[k0:, idx].T.tolist(),
            "hidden": hidden[k0:, idx].T.tolist()}


# ------------------------------------------------------------------------------------------------ Lyapunov
@_one_blas_thread
def lyapunov_estimate(settings: CompareSettings) -> dict[str, Any]:
    """Lyapunov time of the band-passed tower-top fore-aft acceleration of the first training record.

    Rosenstein's estimate (:func:`estimators.lyapunov_exponent`) on ``TwHt9ALxt`` (``TwHt9ALyt`` for the SS
    plane), band-passed zero-phase in ``settings.band`` as the README recommends.

    Returns
    -------
    dict
        ``time_s``, ``exponent_per_s``, ``channel``, ``case``, ``source``, ``diagnostic`` (warnings raised).
    """
    from scipy.signal import sosfiltfilt

    from estimators.lyapunov import lyapunov_exponent
    from estimators.preprocess import band_sos

    case = settings.train_cases[0]
    channel = "TwHt9ALyt" if settings.plane == "SS" else "TwHt9ALxt"
    what = Path(settings.train_files[0]).name if settings.files else f"the OLC {case}"
    if channel not in settings.channels:
        return {"time_s": None, "exponent_per_s": None, "channel": channel, "case": case,
                "source": f"not computed: the records have no {channel}", "diagnostic": ""}
    y = training_data(settings)[0][:, settings.channels.index(channel)]
    x = sosfiltfilt(band_sos(1.0 / settings.dt, settings.band), y)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = lyapunov_exponent(x, settings.dt, return_details=True)
    notes = [str(w.message) for w in caught]
    return {"time_s": _num(res.lyapunov_time), "exponent_per_s": _num(res.exponent), "channel": channel,
            "case": case, "source": f"computed: Rosenstein on band-passed {channel} of {what} training record",
            "diagnostic": "; ".join(notes + ([res.diagnostic] if res.diagnostic else []))}


# ------------------------------------------------------------------------------------------------ result
_KEY_FIELDS = ("scenario", "case", "seed", "estimator", "update_interval")


@dataclass
class CompareResult:
    """What :func:`compare` found.

    Attributes
    ----------
    settings : CompareSettings
    runs : list of dict
        One per grid cell, as :func:`run_unit` returns them without ``wall_clock`` and ``trace``; in grid order
        (scenario, case, seed, estimator, update interval).
    wall_clock : list of dict
        Per run (same order): the key fields and ``fit_s``, ``reconstruct_s``, ``us_per_sample``. Not
        reproducible.
    traces : list of dict or None
        Per run: the end of the test record (truth, estimate, hidden mask) of the scored channels, for plots.
    lyapunov : dict or None
        ``time_s`` and where it came from (given or computed, :func:`lyapunov_estimate`).
    total_s : float
        Wall-clock time of the whole comparison (s).
    """

    settings: CompareSettings
    runs: list[dict[str, Any]]
    wall_clock: list[dict[str, Any]]
    traces: list[dict[str, Any] | None]
    lyapunov: dict[str, Any] | None = None
    total_s: float = float("nan")

    @classmethod
    def from_outputs(cls, settings: CompareSettings, outputs: Iterable[dict[str, Any]],
                     lyapunov: dict[str, Any] | None = None, total_s: float = float("nan")) -> CompareResult:
        """Assemble a result from :func:`run_unit` outputs (in grid order; ``trace`` may be missing or None)."""
        runs, walls, traces = [], [], []
        for out in outputs:
            out = dict(out)
            wall = out.pop("wall_clock")
            traces.append(out.pop("trace", None))
            runs.append(out)
            walls.append({**{k: out[k] for k in _KEY_FIELDS}, **wall})
        return cls(settings, runs, walls, traces, lyapunov, total_s)

    # ------------------------------------------------------------------------------------------ tables
    def table(self) -> list[dict[str, Any]]:
        """Aggregates per (scenario, estimator, update interval) over test cases, seeds and hidden channels."""
        groups: OrderedDict[tuple, list[int]] = OrderedDict()
        for i, r in enumerate(self.runs):
            groups.setdefault((r["scenario"], r["estimator"], r["update_interval"]), []).append(i)
        out = []
        for (scenario, est, interval), idx in groups.items():
            rows = [c for i in idx for c in self.runs[i]["channels"]]
            out.append({"scenario": scenario, "estimator": est, "update_interval": interval,
                        "cases": sorted({self.runs[i]["case"] for i in idx}),
                        "seeds": sorted({self.runs[i]["seed"] for i in idx}),
                        "n_runs": len(idx), "n_channel_scores": len(rows), **_aggregate(rows)})
        return out

    def sweep(self, nrmse_limit: float = 0.05) -> list[dict[str, Any]]:
        """Where accuracy collapses: per (scenario, estimator) swept over several update intervals, the longest
        interval up to which every hidden channel stays within ``nrmse_limit`` (the paper's fatigue grade, 5 %),
        the first one beyond it, and both in Lyapunov times.

        Returns
        -------
        list of dict
            ``scenario``, ``estimator``, ``nrmse_limit``, ``longest_within_s`` (None if even the shortest
            interval fails), ``first_beyond_s`` (None if none fails), ``lyapunov_time_s`` and the two intervals
            divided by it (``*_lyapunov``), ``intervals_s`` and ``median_r2_band`` / ``worst_nrmse`` per
            interval.
        """
        lam = (self.lyapunov or {}).get("time_s")
        groups: OrderedDict[tuple, list[dict]] = OrderedDict()
        for row in self.table():
            if row["update_interval"] is not None:
                groups.setdefault((row["scenario"], row["estimator"]), []).append(row)
        out = []
        for (scenario, est), rows in groups.items():
            if len(rows) < 2:
                continue
            rows.sort(key=lambda r: r["update_interval"])
            ok, beyond = None, None
            for r in rows:
                if r["worst_nrmse"] is not None and r["worst_nrmse"] <= nrmse_limit:
                    ok = r["update_interval"]
                else:
                    beyond = r["update_interval"]
                    break
            out.append({"scenario": scenario, "estimator": est, "nrmse_limit": nrmse_limit,
                        "longest_within_s": ok, "first_beyond_s": beyond, "lyapunov_time_s": lam,
                        "longest_within_lyapunov": None if ok is None or not lam else ok / lam,
                        "first_beyond_lyapunov": None if beyond is None or not lam else beyond / lam,
                        "intervals_s": [r["update_interval"] for r in rows],
                        "median_r2_band": [r["median_r2_band"] for r in rows],
                        "worst_nrmse": [r["worst_nrmse"] for r in rows]})
        return out

    def _speed(self) -> dict[tuple, float]:
        acc: dict[tuple, list[float]] = {}
        for w in self.wall_clock:
            acc.setdefault((w["scenario"], w["estimator"], w["update_interval"]), []).append(w["us_per_sample"])
        return {k: float(np.median(v)) for k, v in acc.items()}

    def to_dict(self, *, wall_clock: bool = True, traces: bool = False) -> dict[str, Any]:
        """JSON-ready result.

        Parameters
        ----------
        wall_clock : bool
            Include the ``"wall_clock"`` part (timings; the only part that differs between identical runs).
        traces : bool
            Include the plotted time series (large).
        """
        s = self.settings
        out: dict[str, Any] = {
            "kind": "fowt-env compare",
            "metrics": {"r2": "1 - SSE/SST of the truth, per hidden channel, physical full-band signals",
                        "nrmse": "RMSE / (max - min) of the truth (fraction), physical signals",
                        "r2_band, nrmse_band": f"the same after a zero-phase 4th-order Butterworth band-pass "
                                               f"{s.band[0]}-{s.band[1]} Hz and z-scoring (the seed paper's form)",
                        "coverage95": "fraction of hidden samples within the sensor's +-1.96 std interval",
                        "pooled_coverage95": "the same over every hidden sample of every hidden channel",
                        "random scenario": "errors over the samples at which each channel was hidden, normalised "
                                           "by the variance and range of the channel's whole record"},
            "settings": s.to_dict(),
            "lyapunov": self.lyapunov,
            "table": self.table(),
            "sweep": self.sweep(),
            "runs": self.runs,
        }
        if traces:
            out["traces"] = self.traces
        if wall_clock:
            speed = self._speed()
            out["wall_clock"] = {
                "note": "wall-clock timings: machine- and load-dependent, not reproducible",
                "total_s": _num(self.total_s),
                "table": [{"scenario": k[0], "estimator": k[1], "update_interval": k[2], "us_per_sample": v}
                          for k, v in speed.items()],
                "runs": self.wall_clock,
            }
        return out

    def summary(self) -> str:
        """Readable table: scenario x estimator (x update interval) -- median and worst hidden-channel R²,
        median NRMSE (%), median band-passed R², 95 % coverage (pooled over the hidden samples, and the channel
        furthest from 0.95) and microseconds per sample."""
        s = self.settings
        plane = f"{s.plane} plane ({len(s.channels)} channels)" if s.plane else f"all {len(s.channels)} tower channels"
        if s.files:
            train = ", ".join(Path(f).name for f in s.train_files)
            lines = [f"Virtual sensing on records from files: trained on {train}; {plane} at {1 / s.dt:g} Hz; "
                     f"R2/NRMSE on the hidden channels (physical; band = "
                     f"{s.band[0]:g}-{s.band[1]:g} Hz band-passed); the test records are their own truth"]
            for i, f in enumerate(s.test_files):
                rec = _file_record(f, s.channel_map)
                op = rec.operating
                where = f"{op['wind_speed']:.2f} m/s from the {rec.operating_source}" if op else rec.operating_source
                lines.append(f"  test {i} = {Path(f).name} (operating point: {where})")
        else:
            lines = [f"Virtual sensing: trained on OLC {_ranges(s.train_cases)} ({s.train_duration:g} s each), tested "
                     f"on {s.duration:g} s records, {plane}; R2/NRMSE on the hidden channels (physical; band = "
                     f"{s.band[0]:g}-{s.band[1]:g} Hz band-passed)"]
            if s.truth_effects:
                lines.append(f"  records from a perturbed truth model {s.truth_effects}; kalman keeps the nominal "
                             f"model unless its model_perturbation option says otherwise")
        col = "test" if s.files else "OLC"
        head = (f"{'scenario':<9}{col:<7}{'hidden':>7}  {'estimator':<10}{'T_up s':>7}{'R2 med':>9}{'R2 worst':>10}"
                f"{'NRMSE%':>8}{'R2 band':>9}{'cov95':>7}{'cov95 ch':>9}{'us/smp':>9}")
        lines += [head, "-" * len(head)]
        speed = self._speed()
        for row in self.table():
            key = (row["scenario"], row["estimator"], row["update_interval"])
            n_hidden = {len(r["hidden"]) for r in self.runs
                        if (r["scenario"], r["estimator"], r["update_interval"]) == key}
            hid = str(n_hidden.pop()) if len(n_hidden) == 1 else "var"
            lines.append(
                f"{row['scenario']:<9}{_ranges(row['cases']):<7}{hid:>7}  {row['estimator']:<10}"
                f"{_fmt(row['update_interval'], '7.2f'):>7}{_fmt(row['median_r2'], '9.4f')}"
                f"{_fmt(row['worst_r2'], '10.4f')}{_fmt(_pct(row['median_nrmse']), '8.2f')}"
                f"{_fmt(row['median_r2_band'], '9.4f')}{_fmt(row['pooled_coverage95'], '7.3f')}"
                f"{_fmt(row['worst_coverage95'], '9.3f')}"
                f"{_fmt(speed.get(key), '9.1f')}")
        diverged = sorted({(r["estimator"], r.get("record") or f"OLC {r['case']}") for r in self.runs
                           if any(c.get("diverged") for c in r["channels"])})
        for est, rec in diverged:
            lines.append(f"warning: {est} diverged on {rec} (estimates beyond {_DIVERGED:g} x the hidden channel's "
                         f"range): its scores there measure the divergence")
        if any(r["case_in_training"] for r in self.runs):
            lines.append("note: some test OLCs are training OLCs (unseen seeds, not unseen load cases)")
        if self.lyapunov and self.lyapunov.get("time_s") is not None:
            lam = self.lyapunov
            lines.append(f"Lyapunov time {lam['time_s']:.2f} s ({lam.get('source', 'given')})")
        for sw in self.sweep():
            lim = f"every hidden NRMSE <= {100 * sw['nrmse_limit']:g} %"
            if sw["longest_within_s"] is None:
                ok = "fails at every interval"
            else:
                ok = f"holds up to T_up = {_when(sw, 'longest_within')}"
                ok += "" if sw["first_beyond_s"] is None else f", lost at {_when(sw, 'first_beyond')}"
            lines.append(f"sweep {sw['estimator']}, scenario {sw['scenario']}: {lim} {ok}")
        if math.isfinite(self.total_s):
            lines.append(f"({len(self.runs)} runs in {self.total_s:.1f} s wall clock)")
        return "\n".join(lines)

    # ------------------------------------------------------------------------------------------ plots
    def plot(self, folder: str | Path) -> list[Path]:
        """Write the figures (PNG) into ``folder``; returns their paths.

        * ``reconstruction_<scenario>.png``: truth and every estimator's reconstruction of the hidden channels
          (end of the first test record of the scenario);
        * ``r2_table.png``: median hidden-channel R² per scenario x estimator (heat map, values printed);
        * ``update_interval_sweep.png`` (when several intervals ran): median R² against the update interval,
          the Lyapunov time marked.
        """
        from .plots import _prepare, _pyplot, _save

        plt = _pyplot()
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = [self._plot_traces(plt, _prepare, _save, folder, sc) for sc in dict.fromkeys(r["scenario"]
                                                                                        for r in self.runs)]
        paths = [p for p in paths if p is not None]
        paths.append(self._plot_table(plt, _save, folder / "r2_table.png"))
        if len({r["update_interval"] for r in self.runs if r["update_interval"] is not None}) > 1:
            paths.append(self._plot_sweep(plt, _save, folder / "update_interval_sweep.png"))
        return paths

    def _label(self, estimator: str, interval: float | None) -> str:
        return estimator if interval is None else f"{estimator} ({interval:g} s)"

    def _plot_traces(self, plt, prepare, save, folder: Path, scenario: str) -> Path | None:
        first = next(r for r in self.runs if r["scenario"] == scenario)
        picks: list[int] = []
        for est in dict.fromkeys(r["estimator"] for r in self.runs):
            cands = [i for i, r in enumerate(self.runs) if r["scenario"] == scenario and r["estimator"] == est
                     and r["case"] == first["case"] and r["seed"] == first["seed"] and self.traces[i] is not None]
            if cands:  # the interval nearest 1 s (the paper's) for sensors that use one
                picks.append(min(cands, key=lambda i: abs(math.log(self.runs[i]["update_interval"] or 1.0))))
        if not picks:
            return None
        tr0 = self.traces[picks[0]]
        names = tr0["channels"]
        n = len(names)
        ncol = 2 if n > 4 else 1
        nrow = -(-n // ncol)
        fig, axes = plt.subplots(nrow, ncol, figsize=(7 * ncol, 1.9 * nrow + 1.0), sharex=True, squeeze=False)
        colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        for k, name in enumerate(names):
            ax = axes[k % nrow, k // nrow]
            t = tr0["t0"] + tr0["dt"] * np.arange(len(tr0["truth"][k]))
            ax.plot(t, tr0["truth"][k], color="k", lw=1.4, label="truth (noise-free)")
            hid = np.asarray(tr0["hidden"][k])
            if not hid.all():  # shade the hidden stretches (random dropouts)
                ax.fill_between(t, 0, 1, where=hid, transform=ax.get_xaxis_transform(), color="0.85", lw=0,
                                label="hidden")
            for c, i in enumerate(picks):
                tr = self.traces[i]
                if name in tr["channels"]:
                    j = tr["channels"].index(name)
                    r = self.runs[i]
                    score = next((row["r2"] for row in r["channels"] if row["channel"] == name), None)
                    lab = self._label(r["estimator"], r["update_interval"])
                    lab += f", R2 {score:.3f}" if score is not None else ""
                    ax.plot(t, tr["estimate"][j], color=colors[c % len(colors)], lw=0.9, label=lab)
            ax.set_ylabel(f"{name}\n[{tr0['units'][k]}]", fontsize=8)
            ax.legend(fontsize=6, loc="upper right")
            ax.grid(alpha=0.3)
        for ax in axes[-1]:
            ax.set_xlabel("time (s)")
        for k in range(n, nrow * ncol):
            axes[k % nrow, k // nrow].set_visible(False)
        st = self.settings
        desc = (f"random dropouts ({100 * st.dropout_rate:.0f} %, bursts {st.dropout_burst_s:g} s)"
                if scenario == "random" else SCENARIOS[scenario]["description"])
        over = "the samples at which it was hidden" if scenario == "random" else "the whole record"
        fig.suptitle(f"Scenario {scenario}: {desc}, OLC {first['case']}, seed {first['seed']}\n"
                     f"hidden channels: truth vs reconstruction (R2 over {over})", fontsize=9)
        return save(fig, prepare(folder / f"reconstruction_{scenario}.png"))

    def _plot_table(self, plt, save, path: Path) -> Path:
        table = self.table()
        scen = list(dict.fromkeys(r["scenario"] for r in table))
        cols = list(dict.fromkeys(self._label(r["estimator"], r["update_interval"]) for r in table))
        val = np.full((len(scen), len(cols)), np.nan)
        for r in table:
            v = r["median_r2"]
            val[scen.index(r["scenario"]), cols.index(self._label(r["estimator"], r["update_interval"]))] = (
                np.nan if v is None else v)
        fig, ax = plt.subplots(figsize=(1.3 * len(cols) + 2.5, 0.7 * len(scen) + 2.0))
        im = ax.imshow(np.clip(val, 0.0, 1.0), cmap="viridis", vmin=0.0, vmax=1.0, aspect="auto")
        for i in range(len(scen)):
            for j in range(len(cols)):
                txt = "n/a" if np.isnan(val[i, j]) else f"{val[i, j]:.4f}"
                ax.text(j, i, txt, ha="center", va="center", fontsize=8,
                        color="w" if np.isnan(val[i, j]) or val[i, j] < 0.6 else "k")
        ax.set_xticks(range(len(cols)), cols, rotation=30, ha="right", fontsize=8)
        ax.set_yticks(range(len(scen)), [f"scenario {s}" for s in scen], fontsize=8)
        fig.colorbar(im, ax=ax, label="median hidden-channel R2 (-), clipped to [0, 1]")
        ax.set_title("Virtual sensing: median R2 of the hidden channels (physical signals)", fontsize=9)
        return save(fig, path)

    def _plot_sweep(self, plt, save, path: Path) -> Path:
        table = self.table()
        scen = list(dict.fromkeys(r["scenario"] for r in table))
        fig, axes = plt.subplots(2, len(scen), figsize=(4.2 * len(scen) + 0.8, 7.0), squeeze=False, sharex=True)
        colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        ests = list(dict.fromkeys(r["estimator"] for r in table))
        intervals = sorted({r["update_interval"] for r in table if r["update_interval"] is not None})
        lam = (self.lyapunov or {}).get("time_s")
        for row, (suffix, what) in enumerate([("", "physical signals"),
                                              ("_band", "band-passed, z-scored (paper's form)")]):
            swept = [r[f"worst_r2{suffix}"] for r in table if r["update_interval"] is not None]
            swept = [v for v in swept if v is not None]
            lo = max(min(swept + [0.9]) - 0.05, -1.0)
            for ax, sc in zip(axes[row], scen, strict=True):
                for c, est in enumerate(ests):
                    rows = [r for r in table if r["scenario"] == sc and r["estimator"] == est
                            and r[f"median_r2{suffix}"] is not None]
                    if not rows:
                        continue
                    color = colors[c % len(colors)]
                    if rows[0]["update_interval"] is None:  # assimilates every sample: one level
                        v = rows[0][f"median_r2{suffix}"]
                        ax.axhline(max(v, lo), color=color, ls="--", lw=1.2, label=f"{est} (every sample)")
                        if v < lo:
                            ax.annotate(f"{est}: {v:.2f} (off scale)", (0.98, 0.02), xycoords="axes fraction",
                                        ha="right", va="bottom", fontsize=7, color=color)
                        continue
                    rows.sort(key=lambda r: r["update_interval"])
                    x = [r["update_interval"] for r in rows]
                    ax.plot(x, [r[f"median_r2{suffix}"] for r in rows], "o-", color=color, label=f"{est}: median")
                    ax.plot(x, [r[f"worst_r2{suffix}"] for r in rows], "v:", color=color, ms=4,
                            label=f"{est}: worst channel")
                if lam is not None:
                    ax.axvline(lam, color="crimson", lw=1.2, label=f"Lyapunov time {lam:.2f} s")
                ax.set_xscale("log", base=2)
                ax.set_xticks(intervals, [f"{v:g}" for v in intervals])
                ax.set_ylim(lo, 1.0 + 0.03 * (1.0 - lo))
                ax.grid(alpha=0.3)
                if row == 0:
                    ax.set_title(f"scenario {sc}", fontsize=9)
                else:
                    ax.set_xlabel("update interval T_up (s)")
            axes[row, 0].set_ylabel(f"hidden-channel R2 (-)\n{what}", fontsize=8)
        axes[0, -1].legend(fontsize=7, loc="lower left")
        fig.suptitle("Where accuracy collapses: hidden-channel R2 against the update (recalibration) interval",
                     fontsize=10)
        return save(fig, path)


def parse_int_list(text: str, name: str = "value") -> list[int]:
    """``"1,3,4,6,8-12"`` -> ``[1, 3, 4, 6, 8, 9, 10, 11, 12]`` (for the command line).

    Raises
    ------
    ValueError
        Naming ``name`` and the bad item.
    """
    out: list[int] = []
    for item in str(text).split(","):
        item = item.strip()
        lo, dash, hi = item.partition("-")
        try:
            out.extend(range(int(lo), int(hi) + 1) if dash else [int(item)])
        except ValueError:
            raise ValueError(f"{name}: expected integers or ranges like 1,3,8-12, got {item!r}") from None
    return out


def _when(sweep_row: dict[str, Any], key: str) -> str:
    ratio = sweep_row[f"{key}_lyapunov"]
    return f"{sweep_row[f'{key}_s']:g} s" + ("" if ratio is None else f" ({ratio:.2f} Lyapunov times)")


def _fmt(v: float | None, spec: str) -> str:
    if v is None:
        return f"{'-':>{int(spec.split('.')[0])}}"
    text = format(v, spec)
    return format(0.0, spec) if float(text) == 0.0 else text  # no "-0.0000"


def _pct(v: float | None) -> float | None:
    return None if v is None else 100.0 * v


def _ranges(values: Iterable[int]) -> str:
    """1,3,4,6,8,9,10 -> '1,3,4,6,8-10'."""
    v = sorted(set(int(x) for x in values))
    parts, i = [], 0
    while i < len(v):
        j = i
        while j + 1 < len(v) and v[j + 1] == v[j] + 1:
            j += 1
        parts.append(f"{v[i]}-{v[j]}" if j - i >= 2 else ",".join(str(x) for x in v[i:j + 1]))
        i = j + 1
    return ",".join(parts)


# ------------------------------------------------------------------------------------------------ driver
@_one_blas_thread  # held in the caller's thread while the units run in pool threads (see _OneBlasThread)
def compare(
    scenarios: Sequence[str] = ("A", "B", "C"),
    estimators: Sequence[str] = ("hold", "kalman", "dmd"),
    *,
    cases: Sequence[int] | None = None,
    seeds: Sequence[int] = (0,),
    update_intervals: Sequence[float] = (1.0,),
    settings: CompareSettings | None = None,
    lyapunov_time: float | str | None = "auto",
    executor: Executor | None = None,
) -> CompareResult:
    """Run the virtual-sensing grid and score every estimator on the hidden channels.

    Parameters
    ----------
    scenarios : sequence of {"A", "B", "C", "random"}
        Failure scenarios (the seed paper's Table 6, or random Markov dropouts).
    estimators : sequence of str
        Names in :data:`ESTIMATORS`.
    cases : sequence of int, optional
        Test OLCs, each run under every scenario. Default: each scenario on its paper OLC
        (:data:`DEFAULT_TEST_CASES`: A on 5, B on 7, C on 2; random on 7).
    seeds : sequence of int
        Seeds of the test records (each must differ from the training seed of the same OLC).
    update_intervals : sequence of float
        Recalibration intervals (s) for the sensors that use one (``dmd``); :data:`SWEEP_INTERVALS` is the
        standard sweep 0.25-4 s.
    settings : CompareSettings, optional
        Training set-up, record lengths, plane, band... (default :class:`CompareSettings()`).
    lyapunov_time : float, "auto" or None
        Lyapunov time (s) to mark on the sweep plot: given, computed (:func:`lyapunov_estimate`), or none.
    executor : concurrent.futures.Executor, optional
        Runs the units (:func:`run_unit`) concurrently; default serially in this thread. The result does not
        depend on it (apart from ``wall_clock``).

    Returns
    -------
    CompareResult

    Raises
    ------
    ValueError
        Unknown scenario or estimator, an estimator that cannot be imported, a bad OLC number, seed or update
        interval, or a test record that would be a training record.
    """
    settings = settings if settings is not None else CompareSettings()
    units = grid_units(scenarios, estimators, cases=cases, seeds=seeds, update_intervals=update_intervals,
                       settings=settings)
    lyap = _lyapunov_request(lyapunov_time)
    t0 = time.perf_counter()
    if executor is None:
        outputs = [run_unit(*u) for u in units]
        if lyap == {}:
            lyap = lyapunov_estimate(settings)
    else:
        futures = [executor.submit(run_unit, *u) for u in units]
        lyap_future = executor.submit(lyapunov_estimate, settings) if lyap == {} else None
        outputs = [f.result() for f in futures]
        if lyap_future is not None:
            lyap = lyap_future.result()
    return CompareResult.from_outputs(settings, outputs, lyap, time.perf_counter() - t0)


def grid_units(
    scenarios: Sequence[str] = ("A", "B", "C"),
    estimators: Sequence[str] = ("hold", "kalman", "dmd"),
    *,
    cases: Sequence[int] | None = None,
    seeds: Sequence[int] = (0,),
    update_intervals: Sequence[float] = (1.0,),
    settings: CompareSettings | None = None,
) -> list[tuple]:
    """The validated grid of :func:`compare`: ``(case, seed, scenario, estimator, update_interval, settings)``
    argument tuples of :func:`run_unit`, in result order (scenario, case, seed, estimator, update interval).

    Takes the arguments of :func:`compare` and raises the same errors (ValueError), before any work is done.
    """
    import surrogates

    settings = settings if settings is not None else CompareSettings()
    scenarios = list(scenarios)
    if not scenarios:
        raise ValueError("scenarios must name at least one scenario")
    for sc in scenarios:
        if sc not in SCENARIO_NAMES:
            raise ValueError(f"unknown scenario {sc!r}; choose from {', '.join(SCENARIO_NAMES)}")
    estimators = list(estimators)
    if not estimators:
        raise ValueError("estimators must name at least one estimator")
    intervals = [_check_interval(v) for v in update_intervals]
    if not intervals:
        raise ValueError("update_intervals must hold at least one interval")
    for est in estimators:  # unknown or unavailable (not importable) estimators fail here, before any work
        _new_sensor(est, intervals[0] if _uses_interval(est) else None, settings,
                    _operating_options(est, settings, None))
    case_list = None if cases is None else [int(c) for c in cases]
    if settings.files:  # the test "cases" are the test records
        n_test = len(settings.test_files)
        case_list = list(range(n_test)) if case_list is None else case_list
        bad = [c for c in case_list if not 0 <= c < n_test]
        if bad:
            raise ValueError(f"cases: with records from files a case is a test file's index, 0 to {n_test - 1}; "
                             f"got {bad}")
        for est in estimators:  # every test record must have an operating point for model-based sensors
            for c in case_list:
                _operating_options(est, settings, c)
        for sc in scenarios:
            if sc != "random" and not hidden_channels(sc, settings):
                raise ValueError(f"scenario {sc}: the records have none of the channels it hides")
    for c in (case_list or []) if not settings.files else []:
        try:
            surrogates.load_case(c)
        except ValueError as exc:
            raise ValueError(f"cases: {exc}") from None
    seed_list = [int(s) for s in seeds]
    if not seed_list or any(s < 0 for s in seed_list):
        raise ValueError(f"seeds must be non-negative integers (at least one), got {list(seeds)!r}")
    units: list[tuple] = []
    for sc in scenarios:
        for case in (case_list if case_list is not None else [DEFAULT_TEST_CASES[sc]]):
            for seed in seed_list:
                if not settings.files and case in settings.train_cases and seed == settings.train_seed_of(case):
                    raise ValueError(f"test OLC {case} with seed {seed} is the training record of that OLC; "
                                     f"use another seed or train_seed")
                for est in estimators:
                    for iv in (intervals if _uses_interval(est) else [None]):
                        units.append((case, seed, sc, est, iv, settings))
    return units


def _lyapunov_request(lyapunov_time: float | str | None) -> dict[str, Any] | None:
    """None (no Lyapunov time), ``{}`` (to be computed: :func:`lyapunov_estimate`) or the given one."""
    if lyapunov_time is None or lyapunov_time == "none":
        return None
    if lyapunov_time == "auto":
        return {}
    try:
        lt = float(lyapunov_time)
    except (TypeError, ValueError):
        lt = float("nan")
    if not (math.isfinite(lt) and lt > 0):
        raise ValueError(f"lyapunov_time must be a positive number of seconds, 'auto' or None, "
                         f"got {lyapunov_time!r}")
    return {"time_s": lt, "source": "given"}
