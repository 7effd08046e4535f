"""Campaigns: the comparison grid on any executor, written as it runs, resumable, with retries.

A campaign is the grid of :func:`fowt_env.compare.compare` -- load cases x seeds x scenarios x estimators (x update
intervals) -- run task by task through any :class:`concurrent.futures.Executor`: this thread
(:class:`SerialExecutor`), a thread or process pool, or a Dask distributed cluster (``client.get_executor()``), on
one machine or many. :func:`parse_scheduler` turns a scheduler spec into such an executor:

==================== ==================================================================================
``serial``           this thread, one task after another (the default)
``threads:N``        a :class:`~concurrent.futures.ThreadPoolExecutor` of N threads
``processes:N``      a :class:`~concurrent.futures.ProcessPoolExecutor` of N processes (spawned)
``local:N``          a Dask distributed ``LocalCluster`` of N single-threaded worker processes
``tcp://HOST:PORT``  an existing Dask cluster (its scheduler's address); every worker needs fowt-env installed
==================== ==================================================================================

The results do not depend on the executor: every task (:func:`fowt_env.compare.run_unit`) is a pure function of
its grid key and the settings (seeded simulations, no shared state that changes a result), results are ordered by
the grid and not by completion, and wall-clock timings are kept apart in the ``"wall_clock"`` part; the harness
computes with one BLAS thread everywhere (a thread count changes the last digits of OpenBLAS's sums). The tasks on
one test record (OLC, seed) are sent to a worker together, so that it simulates the record once for all of them.

:func:`run_campaign` writes one JSON line per finished task to ``DIR/results.jsonl`` (its key, status, attempts
and result or error) as soon as it finishes (appended and flushed), so a campaign that is interrupted -- Ctrl-C,
a killed process, a lost cluster -- resumes when it is run again: tasks whose result is already there are not
run again. A task that raises is retried (``retries`` times), then recorded as failed with its error and
reported; it is never dropped silently. At the end the summary -- the same JSON as ``fowt-env compare --json``,
plus a ``"failed"`` list if any task failed -- goes to ``DIR/summary.json``. ``DIR/campaign.json`` holds the
settings: a directory is never resumed with other settings (the grid may grow: added seeds or cases only run the
new tasks). One campaign at a time runs in a directory: it holds an exclusive lock on ``DIR/.lock`` (``flock``,
released when the process ends, even when it is killed), and a second run on the same directory stops at once
with :class:`CampaignBusyError` naming the holder's PID and host (a lock on a network file system is only as good
as that file system's ``flock``). Files are replaced through temporary files of unique names.

Security: a ``tcp://`` scheduler runs the tasks and sends their results back pickled, and the client unpickles
them: whoever controls that address (or the network path to it) can run code in this process. Addresses other
than loopback are refused unless the connection uses TLS (``tls://`` with a security configuration, see
:func:`parse_scheduler`) or ``insecure=True`` (``--insecure``) says the network is trusted.

Examples
--------
>>> from fowt_env.campaign import parse_scheduler, run_campaign
>>> from fowt_env.compare import CompareSettings
>>> settings = CompareSettings(train_cases=(1, 6), train_duration=30.0, duration=10.0)
>>> with parse_scheduler("threads:2") as executor:  # doctest: +SKIP
...     done = run_campaign("campaign_dir", ["B"], ["hold"], cases=[2, 5], seeds=[0, 1], settings=settings,
...                         executor=executor, lyapunov_time=None)
>>> done.ok, done.n_tasks  # doctest: +SKIP
(True, 4)
"""

from __future__ import annotations

import json
import logging
import os
import sys
import time
import traceback
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, CancelledError, Executor, Future, wait
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .compare import CompareResult, CompareSettings, _lyapunov_request, _one_blas_thread, grid_units

__all__ = [
    "LOCK_FILE",
    "LYAPUNOV_KEY",
    "CampaignBusyError",
    "SCHEDULER_HELP",
    "CampaignResult",
    "SECURITY_WARNING",
    "ProgressExecutor",
    "SerialExecutor",
    "load_security",
    "parse_scheduler",
    "run_campaign",
    "task_label",
]

log = logging.getLogger(__name__)

LYAPUNOV_KEY = "lyapunov"
"""Journal key of the Lyapunov-time task (grid tasks are keyed ``[scenario, case, seed, estimator, interval]``)."""

SCHEDULER_HELP = ("serial (default), threads:N, processes:N, local:N (a Dask LocalCluster of N worker processes) "
                  "or tcp://HOST:PORT (an existing Dask cluster's scheduler)")

RESULTS_FILE, SUMMARY_FILE, MANIFEST_FILE = "results.jsonl", "summary.json", "campaign.json"
LOCK_FILE = ".lock"
"""Held (``flock``, exclusive) by the campaign running in a directory; it names the holder's PID and host."""
_FORMAT = 1


# ------------------------------------------------------------------------------------------------ executors
class SerialExecutor(Executor):
    """An :class:`~concurrent.futures.Executor` without concurrency: ``submit`` runs the call in this thread and
    returns a finished future. An exception is stored in the future; ``KeyboardInterrupt`` and ``SystemExit``
    propagate at once, as they would without an executor."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        fut: Future = Future()
        fut.set_running_or_notify_cancel()
        try:
            result = fn(*args, **kwargs)
        except Exception as exc:
            fut.set_exception(exc)
        else:
            fut.set_result(result)
        return fut


class ProgressExecutor(Executor):
    """Wraps an executor and advances a tqdm bar (on stderr) as its tasks finish; for callers such as
    :func:`fowt_env.compare.compare` that only see an executor. Closing it closes the bar, not the executor."""

    def __init__(self, executor: Executor, *, total: int | None = None, desc: str = "tasks",
                 enabled: bool | None = None) -> None:
        self.executor = executor
        self.bar = _bar(total, desc, enabled)

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        fut = self.executor.submit(fn, *args, **kwargs)
        fut.add_done_callback(lambda _: self.bar.update(1))
        return fut

    def shutdown(self, wait: bool = True, **kwargs: Any) -> None:
        self.bar.close()


def _bar(total: int | None, desc: str, enabled: bool | None, initial: int = 0):
    """The shared progress bar (:func:`fowt_env.progress.progress_bar`: total and ETA, on a terminal by default),
    left on screen when done."""
    from .progress import progress_bar

    return progress_bar(total, desc, unit="tasks", progress=enabled, initial=initial, leave=True, stream=sys.stderr)


def _count(spec: str, text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"scheduler {spec!r}: the number of workers must be a positive integer, got {text!r}")
    return n


def _distributed(spec: str):
    try:
        import distributed
    except ImportError as exc:  # a declared dependency: only a broken install gets here
        raise ValueError(f"scheduler {spec!r} needs Dask distributed ({exc}); install it with "
                         f"pip install 'dask[distributed]'") from None
    return distributed


SECURITY_WARNING = ("Dask sends task results pickled and this client unpickles them: whoever controls a "
                    "tcp:// scheduler's address (or the network to it) can run code in this process")


def _is_loopback(host: str | None) -> bool:
    import ipaddress

    if host is None:
        return False
    if host.lower() in ("localhost", "localhost.localdomain"):
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def load_security(path: str | os.PathLike[str]) -> Any:
    """A Dask ``distributed.Security`` (TLS) from a YAML or JSON file.

    The file holds either Dask's own configuration layout (``distributed: comm: {require-encryption: true, tls:
    {ca-file: ..., client: {cert: ..., key: ...}}}``, as in ``~/.config/dask/*.yaml``) or the keyword arguments of
    ``distributed.Security`` (``tls_ca_file``, ``tls_client_cert``, ``tls_client_key``, ``require_encryption``).
    Relative certificate paths are taken from the file's folder.

    Parameters
    ----------
    path : str or path-like
        The security file.

    Returns
    -------
    distributed.Security

    Raises
    ------
    ValueError
        A missing or unreadable file, unknown keys, or a certificate file that does not exist.
    """
    import yaml

    p = Path(path)
    try:
        data = yaml.safe_load(p.read_text())
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ValueError(f"scheduler security file {str(p)!r}: cannot read it ({' '.join(str(exc).split())})") from None
    if not isinstance(data, dict):
        raise ValueError(f"scheduler security file {str(p)!r}: expected a mapping (Dask's 'distributed: comm: tls:' "
                         "layout or distributed.Security keywords)")
    distributed = _distributed("tls://")
    if "distributed" in data:  # Dask's configuration layout
        tls = (data.get("distributed") or {}).get("comm") or {}
        flat = {"require_encryption": tls.get("require-encryption")}
        t = tls.get("tls") or {}
        flat.update(tls_ca_file=t.get("ca-file"), tls_ciphers=t.get("ciphers"),
                    tls_client_cert=(t.get("client") or {}).get("cert"),
                    tls_client_key=(t.get("client") or {}).get("key"))
        data = {k: v for k, v in flat.items() if v is not None}
    for key in ("tls_ca_file", "tls_client_cert", "tls_client_key"):
        value = data.get(key)
        if isinstance(value, str) and "-----BEGIN" not in value:  # a path, not PEM text
            full = (p.parent / value).expanduser() if not Path(value).expanduser().is_absolute() else \
                Path(value).expanduser()
            if not full.is_file():
                raise ValueError(f"scheduler security file {str(p)!r}: {key} {str(full)!r} does not exist")
            data[key] = str(full)
    try:
        return distributed.Security(**data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"scheduler security file {str(p)!r}: {exc}") from None


@contextmanager
def parse_scheduler(spec: str | None = "serial", *, security: Any = None, insecure: bool = False,
                    **cluster_options: Any) -> Iterator[Executor]:
    """An executor for a scheduler spec, as a context manager that closes what it started.

    Parameters
    ----------
    spec : str or None
        ``"serial"`` (or None): this thread; ``"threads:N"``; ``"processes:N"`` (spawned worker processes);
        ``"local:N"``: a Dask distributed ``LocalCluster`` of N single-threaded worker processes (no dashboard);
        ``"tcp://HOST:PORT"`` (or ``tls://``...): the scheduler of an existing Dask cluster, whose workers must be
        able to import fowt_env (same version) -- the cluster is left running, only the client is closed.
        **Trust**: Dask sends the results pickled and this client unpickles them, so whoever controls that address
        can run code here. A ``tcp://`` address other than loopback is refused unless ``insecure=True``; use
        ``tls://`` with `security` (or Dask's own TLS configuration) across a network.
    security : distributed.Security, str or path-like, optional
        TLS credentials for a ``tls://`` scheduler: a ``Security`` object or a file for :func:`load_security`.
        Default: Dask's configuration (``distributed.comm.tls.*`` in ``~/.config/dask`` or ``DASK_*`` variables).
    insecure : bool
        Accept a plain ``tcp://`` scheduler that is not on this machine (a trusted, private network).
    **cluster_options
        For ``local:N``: extra ``LocalCluster`` keyword arguments (e.g. ``processes=False`` for in-process
        workers); for ``tcp://``: extra ``Client`` keyword arguments (e.g. ``timeout="30s"``).

    Yields
    ------
    concurrent.futures.Executor
        For Dask, ``client.get_executor(pure=False)`` (a retried task really runs again).

    Raises
    ------
    ValueError
        An unknown spec, a bad worker count, a plain ``tcp://`` address beyond loopback without `insecure`, a bad
        security file, no Dask scheduler at the address, or workers without fowt-env.
    """
    spec = "serial" if spec is None else str(spec).strip()
    kind, colon, arg = spec.partition(":")
    if cluster_options and kind not in ("local", "tcp", "tls", "ucx", "inproc"):
        raise ValueError(f"scheduler {spec!r} takes no options (got {sorted(cluster_options)})")
    if security is not None and "://" not in spec:
        raise ValueError(f"scheduler {spec!r}: a security configuration applies to tcp:// or tls:// schedulers only")
    if spec == "serial":
        yield SerialExecutor()
    elif kind == "threads" and colon:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=_count(spec, arg), thread_name_prefix="fowt-campaign") as pool:
            yield pool
    elif kind == "processes" and colon:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        spawn = multiprocessing.get_context("spawn")  # no fork of a process that runs threads
        with ProcessPoolExecutor(max_workers=_count(spec, arg), mp_context=spawn) as pool:
            yield pool
    elif kind == "local":
        n = _count(spec, arg) if colon else (os.cpu_count() or 1)
        distributed = _distributed(spec)
        options = {"n_workers": n, "threads_per_worker": 1, "processes": True, "dashboard_address": None,
                   **cluster_options}
        with distributed.LocalCluster(**options) as cluster, distributed.Client(cluster) as client:
            yield client.get_executor(pure=False)
    elif "://" in spec:
        from urllib.parse import urlsplit

        try:
            host = urlsplit(spec).hostname
        except ValueError:
            host = None
        if kind not in ("tls", "inproc") and not _is_loopback(host) and not insecure:
            raise ValueError(f"scheduler {spec!r}: refused, {SECURITY_WARNING}; across a network use tls://HOST:PORT "
                             "with --scheduler-security FILE (or Dask's TLS configuration), or pass --insecure on a "
                             "network you trust")
        distributed = _distributed(spec)
        if security is not None and not isinstance(security, distributed.Security):
            security = load_security(security)
        if security is not None:
            cluster_options = {"security": security, **cluster_options}
        try:
            client = distributed.Client(spec, **{"timeout": "10s", **cluster_options})
        except (OSError, TimeoutError) as exc:
            raise ValueError(f"scheduler {spec!r}: cannot connect to a Dask scheduler there "
                             f"({' '.join(str(exc).split())})") from None
        with client:
            _check_workers(client, spec)
            yield client.get_executor(pure=False)
    else:
        raise ValueError(f"unknown scheduler {spec!r}: expected {SCHEDULER_HELP}")


def _check_workers(client: Any, spec: str) -> None:
    """Every worker of an existing cluster must import fowt_env; another version is worth a warning."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        workers = client.run(exec, "import fowt_env.compare")  # builtins only: a worker without fowt_env can run it
    except ImportError as exc:
        raise ValueError(f"scheduler {spec!r}: a Dask worker cannot import fowt_env ({exc}); install fowt-env "
                         f"(the same version) on every worker") from None
    if not workers:
        log.warning("the Dask cluster at %s has no workers yet: tasks wait for some to join", spec)
    try:
        mine, theirs = version("fowt-env"), client.run(version, "fowt-env")
    except PackageNotFoundError:  # running from a source tree somewhere
        return
    other = {w: v for w, v in theirs.items() if v != mine}
    if other:
        log.warning("Dask workers run other fowt-env versions than this one (%s): %s", mine, other)


# ------------------------------------------------------------------------------------------------ keys
def _key(unit: tuple) -> tuple:
    case, seed, scenario, estimator, interval = unit[:5]
    return (scenario, int(case), int(seed), estimator, None if interval is None else float(interval))


def _from_json_key(key: Any) -> tuple | str:
    if key == LYAPUNOV_KEY:
        return LYAPUNOV_KEY
    scenario, case, seed, estimator, interval = key
    return (scenario, int(case), int(seed), estimator, None if interval is None else float(interval))


def _to_json_key(key: tuple | str) -> list | str:
    return key if isinstance(key, str) else list(key)


def task_label(key: Sequence | str) -> str:
    """``["B", 5, 0, "dmd", 1.0]`` -> ``"scenario B, OLC 5, seed 0, dmd (1 s)"``."""
    if key == LYAPUNOV_KEY:
        return "Lyapunov time"
    scenario, case, seed, estimator, interval = key
    return f"scenario {scenario}, OLC {case}, seed {seed}, {estimator}" + (
        "" if interval is None else f" ({interval:g} s)")


# ------------------------------------------------------------------------------------------------ journal
def _canonical(settings: dict[str, Any]) -> str:
    return json.dumps(settings, sort_keys=True, default=str)


def _read_journal(path: Path) -> dict[tuple | str, dict[str, Any]]:
    """The last line per key of ``results.jsonl``; a torn last line (a write cut short) is cut off the file."""
    out: dict[tuple | str, dict[str, Any]] = {}
    if not path.exists():
        return out
    data = path.read_bytes()
    keep = data.rfind(b"\n") + 1
    if keep < len(data):  # interrupted in the middle of a line: drop the fragment
        with open(path, "r+b") as fh:
            fh.truncate(keep)
        log.warning("%s: dropped an incomplete last line (an interrupted write)", path)
    for n, line in enumerate(data[:keep].decode("utf-8", errors="replace").splitlines(), 1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
            key = _from_json_key(rec["key"])
            rec["status"]  # noqa: B018
        except (ValueError, KeyError, TypeError):
            log.warning("%s:%d: unreadable line skipped (its task will run again)", path, n)
            continue
        out[key] = rec
    return out


class _Journal:
    """Appends one JSON line per finished task, flushed to disk at once."""

    def __init__(self, path: Path) -> None:
        self.fh = open(path, "a", encoding="utf-8")  # noqa: SIM115

    def write(self, record: dict[str, Any]) -> None:
        self.fh.write(json.dumps(record) + "\n")
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


class CampaignBusyError(ValueError):
    """The campaign directory is in use by another running campaign (its PID is in the message)."""


@contextmanager
def _exclusive(out: Path) -> Iterator[None]:
    """Hold an exclusive lock on the campaign directory ``out`` (``out/.lock``, ``flock``) while the block runs.

    The lock dies with its process (a killed campaign leaves no stale lock); the file keeps the holder's PID and
    host for the message another run gets. Where ``fcntl`` is missing (Windows) no lock is taken.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        log.warning("no file locking on this platform: do not run two campaigns on %s at once", out)
        yield
        return
    path = out / LOCK_FILE
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 200, 0).decode("utf-8", "replace").strip() or "a process that has not said which"
            raise CampaignBusyError(
                f"{out} is in use by another running campaign ({holder}); wait for it to finish or use another "
                "directory") from None
        except OSError as exc:  # a file system without flock (some network mounts): run, but say so
            log.warning("cannot lock %s (%s): do not run two campaigns on it at once", out, exc.strerror or exc)
            yield
            return
        os.ftruncate(fd, 0)
        import socket

        os.pwrite(fd, f"PID {os.getpid()} on {socket.gethostname()}\n".encode(), 0)
        try:
            yield
        finally:
            os.ftruncate(fd, 0)  # released: no holder to name (the lock itself goes with the descriptor)
    finally:
        os.close(fd)


def _replace_atomically(dest: Path, text: str) -> None:
    """Write ``text`` to a temporary file of a unique name beside ``dest``, then move it onto ``dest``."""
    import uuid

    tmp = dest.with_name(f".{dest.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, dest)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _prepare_dir(out: Path, settings: CompareSettings, fresh: bool) -> None:
    manifest = out / MANIFEST_FILE
    mine = json.loads(json.dumps(settings.to_dict(), default=str))
    if fresh:
        for name in (RESULTS_FILE, SUMMARY_FILE):
            (out / name).unlink(missing_ok=True)
    elif manifest.exists():
        try:
            theirs = json.loads(manifest.read_text())["settings"]
        except (ValueError, KeyError, TypeError):
            raise ValueError(f"{manifest} is not a fowt-env campaign manifest; use another directory") from None
        if _canonical(theirs) != _canonical(mine):
            diff = sorted(k for k in set(mine) | set(theirs) if _canonical(mine.get(k)) != _canonical(theirs.get(k)))
            raise ValueError(f"{out} holds a campaign with other settings (differing: {', '.join(diff)}); use "
                             f"another directory, the same settings, or start afresh (fresh=True, --fresh)")
    elif (out / RESULTS_FILE).exists():
        raise ValueError(f"{out / RESULTS_FILE} exists without {MANIFEST_FILE}; use another directory")
    _replace_atomically(manifest, json.dumps({"kind": "fowt-env campaign", "format": _FORMAT, "settings": mine},
                                             indent=1))


# ------------------------------------------------------------------------------------------------ result
@dataclass
class CampaignResult:
    """What :func:`run_campaign` did.

    Attributes
    ----------
    out : Path
        The campaign directory (``results.jsonl``, ``summary.json``, ``campaign.json``).
    result : CompareResult
        The successful runs in grid order (all of them when :attr:`ok`), the Lyapunov time if it was asked for.
    n_tasks : int
        Tasks of the grid (the Lyapunov time counts as one when it is computed).
    ran : int
        Tasks run by this call (successfully or not); the others were found in ``results.jsonl``.
    reused : int
        Tasks whose result was found in ``results.jsonl``.
    retried : int
        Attempts that failed and were retried in this call.
    failed : list of dict
        Tasks that failed every attempt: ``key``, ``task``, ``attempts``, ``error``.
    total_s : float
        Wall-clock time of this call (s).
    """

    out: Path
    result: CompareResult
    n_tasks: int
    ran: int
    reused: int
    retried: int = 0
    failed: list[dict[str, Any]] = field(default_factory=list)
    total_s: float = float("nan")

    @property
    def ok(self) -> bool:
        """True if every task succeeded."""
        return not self.failed

    @property
    def summary_path(self) -> Path:
        return self.out / SUMMARY_FILE

    @property
    def results_path(self) -> Path:
        return self.out / RESULTS_FILE

    def to_dict(self, *, wall_clock: bool = True) -> dict[str, Any]:
        """The summary: :meth:`CompareResult.to_dict` (the JSON of ``fowt-env compare``), plus ``"failed"`` when a
        task failed; the campaign's own bookkeeping goes to ``wall_clock["campaign"]`` (run-dependent)."""
        out = self.result.to_dict(wall_clock=wall_clock)
        if self.failed:
            out["failed"] = self.failed
        if wall_clock:
            out["wall_clock"]["campaign"] = {"tasks": self.n_tasks, "ran": self.ran, "reused": self.reused,
                                             "retried": self.retried, "failed": len(self.failed),
                                             "total_s": self.total_s}
        return out

    def report(self) -> str:
        """One line on the tasks (ran, reused, retried, failed), then one per failed task."""
        lines = [f"campaign {self.out}: {self.n_tasks} tasks, {self.ran} ran, {self.reused} reused from "
                 f"{RESULTS_FILE}, {self.retried} retried, {len(self.failed)} failed ({self.total_s:.1f} s)"]
        lines += [f"FAILED after {f['attempts']} attempt(s): {f['task']}: {f['error']}" for f in self.failed]
        return "\n".join(lines)

    def summary(self) -> str:
        """The comparison table (:meth:`CompareResult.summary`) and :meth:`report`."""
        return (self.result.summary() + "\n" if self.result.runs else "") + self.report()


# ------------------------------------------------------------------------------------------------ driver
@_one_blas_thread  # held in the caller's thread while tasks run in pool threads (fowt_env.compare._OneBlasThread)
def run_campaign(
    out: str | Path,
    scenarios: Sequence[str] = ("A", "B", "C"),
    estimators: Sequence[str] = ("hold", "kalman", "dmd"),
    *,
    cases: Sequence[int] | None = None,
    seeds: Sequence[int] = (0,),
    update_intervals: Sequence[float] = (1.0,),
    settings: CompareSettings | None = None,
    lyapunov_time: float | str | None = "auto",
    executor: Executor | None = None,
    retries: int = 1,
    progress: bool | None = False,
    keep_traces: bool = False,
    fresh: bool = False,
    max_in_flight: int | None = None,
    on_record: Callable[[dict[str, Any]], None] | None = None,
) -> CampaignResult:
    """Run (or resume) the comparison grid task by task, recording every finished task in ``out/results.jsonl``.

    The grid arguments are those of :func:`fowt_env.compare.compare` and are checked the same way before any
    work. When every task succeeds, ``out/summary.json`` holds the same JSON as ``compare(...).to_dict()`` (apart
    from the run-dependent ``wall_clock`` part), whatever the executor and however often the campaign was
    interrupted and resumed.

    Parameters
    ----------
    out : str or Path
        Campaign directory (created). Rerunning with the same directory and settings resumes: tasks already
        recorded as successful are not run again; failed ones are tried again.
    scenarios, estimators, cases, seeds, update_intervals, settings, lyapunov_time
        As :func:`fowt_env.compare.compare`.
    executor : concurrent.futures.Executor, optional
        Runs the tasks (default :class:`SerialExecutor`: this thread); see :func:`parse_scheduler`. With
        processes or a Dask cluster, estimators must be registered in a module the workers import.
    retries : int
        Extra attempts for a task that raises (default 1); then it is recorded as failed with its error.
    progress : bool or None
        tqdm bar on stderr: True, False (default), None = when stderr is a terminal.
    keep_traces : bool
        Also record each run's trace (the end of the test record, for :meth:`CompareResult.plot`; large).
    fresh : bool
        Forget earlier results in ``out`` and start again.
    max_in_flight : int, optional
        At most this many batches (the tasks on one test record) submitted at once (default: all; a synchronous
        executor runs one batch at a time).
    on_record : callable, optional
        Called with each journal record (``key``, ``status``, ``attempts``, ``result`` or ``error``) right after
        it is written; an exception it raises stops the campaign (what was written stays).

    Returns
    -------
    CampaignResult
        Check :attr:`CampaignResult.ok`: failed tasks are reported there (and in ``summary.json``), not raised.

    Raises
    ------
    ValueError
        Bad grid arguments (as :func:`compare`), or ``out`` holds a campaign with other settings.
    CampaignBusyError
        (a ValueError) ``out`` is in use by another running campaign; the message names its PID and host.
    KeyboardInterrupt
        From a task or ``on_record``: the campaign stops, tasks not yet finished are cancelled, the journal
        keeps what finished.
    """
    settings = settings if settings is not None else CompareSettings()
    retries = int(retries)
    if retries < 0:
        raise ValueError(f"retries must be >= 0, got {retries}")
    if max_in_flight is not None and int(max_in_flight) < 1:
        raise ValueError(f"max_in_flight must be a positive integer, got {max_in_flight!r}")
    units = grid_units(scenarios, estimators, cases=cases, seeds=seeds, update_intervals=update_intervals,
                       settings=settings)
    lyap = _lyapunov_request(lyapunov_time)
    calls: dict[tuple | str, tuple] = {_key(u): ("unit", u) for u in units}
    if lyap == {}:
        calls[LYAPUNOV_KEY] = ("lyapunov", (settings,))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with _exclusive(out):  # one campaign per directory at a time (--fresh deletes what another would append to)
        return _run_locked(out, calls, settings, fresh, lyap, executor, retries, progress, keep_traces,
                           max_in_flight, on_record)


def _run_locked(out: Path, calls: dict[tuple | str, tuple], settings: CompareSettings, fresh: bool, lyap: Any,
                executor: Executor | None, retries: int, progress: bool | None, keep_traces: bool,
                max_in_flight: int | None, on_record: Callable[[dict[str, Any]], None] | None) -> CampaignResult:
    """:func:`run_campaign` once its arguments are checked and the directory is locked."""
    _prepare_dir(out, settings, fresh)
    (out / SUMMARY_FILE).unlink(missing_ok=True)  # a summary is only there when it matches the journal
    journal_path = out / RESULTS_FILE
    done = {k: r for k, r in _read_journal(journal_path).items() if k in calls and r.get("status") == "ok"}
    # tasks on one test record (case, seed) go together: the record is simulated once, where they run
    batches: dict[Any, list] = {}
    for k in calls:
        if k not in done:
            batches.setdefault(k if k == LYAPUNOV_KEY else (k[1], k[2]), []).append(k)
    todo = deque(batches.values())
    order = {k: i for i, k in enumerate(calls)}
    executor = executor if executor is not None else SerialExecutor()
    attempts: dict[tuple | str, int] = {}
    failed: dict[tuple | str, dict[str, Any]] = {}
    inflight: dict[Future, list] = {}
    retried = 0
    t0 = time.perf_counter()
    journal = _Journal(journal_path)
    bar = _bar(len(calls), "campaign", progress, initial=len(done))
    try:
        while todo or inflight:
            while todo and (max_in_flight is None or len(inflight) < int(max_in_flight)):
                batch = todo.popleft()
                for k in batch:
                    attempts[k] = attempts.get(k, 0) + 1
                fut = executor.submit(_run_batch, [calls[k] for k in batch])
                inflight[fut] = batch
                if fut.done():  # a synchronous executor: record it before the next one runs
                    break
            finished, _ = wait(list(inflight), return_when=FIRST_COMPLETED)
            for fut in sorted(finished, key=lambda f: order[inflight[f][0]]):
                batch = inflight.pop(fut)
                try:
                    exc = fut.exception()
                except CancelledError as err:  # e.g. a lost Dask worker
                    exc = err
                if exc is not None and not isinstance(exc, Exception):
                    raise exc  # KeyboardInterrupt or SystemExit inside a task: stop
                outcomes = fut.result() if exc is None else [_failure(exc)] * len(batch)
                again = []
                for key, outcome in zip(batch, outcomes, strict=True):
                    if "error" in outcome and attempts[key] <= retries:
                        retried += 1
                        log.warning("%s failed (attempt %d of %d): %s; retrying", task_label(_to_json_key(key)),
                                    attempts[key], retries + 1, outcome["error"])
                        again.append(key)
                        continue
                    record: dict[str, Any] = {"key": _to_json_key(key), "attempts": attempts[key]}
                    if "error" in outcome:
                        record.update(status="failed", **outcome)
                        failed[key] = {"key": record["key"], "task": task_label(record["key"]),
                                       "attempts": attempts[key], "error": outcome["error"]}
                    else:
                        result = outcome["result"]
                        if not keep_traces and isinstance(result, dict) and "trace" in result:
                            result = {**result, "trace": None}
                        record.update(status="ok", result=result)
                        done[key] = record
                    journal.write(record)
                    bar.update(1)
                    if failed:
                        bar.set_postfix(failed=len(failed), refresh=False)
                    if on_record is not None:
                        on_record(record)
                if again:
                    todo.appendleft(again)
    except BaseException:
        for fut in inflight:
            fut.cancel()
        raise
    finally:
        bar.close()
        journal.close()
    total = time.perf_counter() - t0
    outputs = [done[k]["result"] for k in calls if k != LYAPUNOV_KEY and k in done]
    lyapunov = lyap if lyap != {} else (done[LYAPUNOV_KEY]["result"] if LYAPUNOV_KEY in done else None)
    result = CompareResult.from_outputs(settings, outputs, lyapunov, total)
    camp = CampaignResult(out, result, n_tasks=len(calls), ran=len(attempts),
                          reused=len(calls) - len(attempts), retried=retried,
                          failed=[failed[k] for k in calls if k in failed], total_s=total)
    _replace_atomically(out / SUMMARY_FILE, json.dumps(camp.to_dict(), indent=1))
    return camp


def _run_batch(calls: list[tuple[str, tuple]]) -> list[dict[str, Any]]:
    """Run tasks one after another where this is called (a worker): ``("unit", run_unit arguments)`` or
    ``("lyapunov", (settings,))``. Each gives ``{"result": ...}`` or ``{"error": ..., "traceback": ...}``; a
    ``KeyboardInterrupt`` or ``SystemExit`` propagates."""
    from . import compare

    outcomes = []
    for kind, args in calls:
        fn = compare.run_unit if kind == "unit" else compare.lyapunov_estimate
        try:
            outcomes.append({"result": fn(*args)})
        except Exception as exc:
            outcomes.append(_failure(exc))
    return outcomes


def _failure(exc: BaseException) -> dict[str, str]:
    return {"error": _error(exc), "traceback": "".join(traceback.format_exception(exc))}


def _error(exc: BaseException) -> str:
    """``"ValueError: first line of the message"``."""
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0]}" if lines else type(exc).__name__
