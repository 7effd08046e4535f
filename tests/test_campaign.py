"""Campaigns (fowt_env.campaign, `fowt-env campaign`, `fowt-env compare --scheduler`): the same numbers whatever
the executor (serial, threads, a Dask cluster), results written as tasks finish, resume after an interruption,
retries and reported failures.

The reference is always fowt_env.compare.compare run serially in this process; equality is of the JSON text
(everything but the clearly named, machine-dependent ``wall_clock`` part).
"""

import dataclasses
import json
import socket
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from fowt_env import campaign as K
from fowt_env import compare as C
from fowt_env.cli import main

# small and quick: two training OLCs of 60 s, 30 s test records (the settings of tests/test_compare.py, so that
# the memoised simulations and fits are shared when both files run in one session)
SETTINGS = C.CompareSettings(train_cases=(1, 6), train_duration=60.0, duration=30.0,
                             estimator_options={"kalman": {"em_iter": 3}})
SEED = 3
CLI_SMALL = ["--train-cases", "1,6", "--train-duration", "60", "--duration", "30", "--seeds", str(SEED),
             "--option", "kalman.em_iter=3"]
# the grid: scenario B on two unseen OLCs, two seeds, the floor and the Hankel-DMD sensor (BLAS-heavy)
GRID = {"scenarios": ["B"], "estimators": ["hold", "dmd"], "cases": [2, 5], "seeds": [SEED, 4],
        "settings": SETTINGS}
N_TASKS = 2 * 2 * 2 + 1  # cases x seeds x estimators, + the Lyapunov time


def without_wall_clock(data: dict) -> str:
    return json.dumps({k: v for k, v in data.items() if k != "wall_clock"})


@pytest.fixture(scope="module")
def reference() -> str:
    """compare's JSON for GRID, serial in this process."""
    return without_wall_clock(C.compare(**GRID, lyapunov_time="auto").to_dict())


def summary_of(folder) -> dict:
    return json.loads((folder / "summary.json").read_text())


def journal(folder) -> list[dict]:
    return [json.loads(line) for line in (folder / "results.jsonl").read_text().splitlines()]


@pytest.fixture
def calls(monkeypatch) -> list:
    """What really runs in this process: grid keys (scenario, case, seed, estimator, interval) of run_unit calls
    and "lyapunov" for lyapunov_estimate."""
    seen, lock = [], threading.Lock()
    run_unit, lyapunov_estimate = C.run_unit, C.lyapunov_estimate

    def counting_unit(*args):
        with lock:
            seen.append((args[2], args[0], args[1], args[3], args[4]))
        return run_unit(*args)

    def counting_lyapunov(*args):
        with lock:
            seen.append("lyapunov")
        return lyapunov_estimate(*args)

    monkeypatch.setattr(C, "run_unit", counting_unit)
    monkeypatch.setattr(C, "lyapunov_estimate", counting_lyapunov)
    return seen


# ------------------------------------------------------------------------------------------------ schedulers
def test_scheduler_specs_and_their_errors(capsys):
    with K.parse_scheduler("serial") as ex:
        assert isinstance(ex, K.SerialExecutor) and ex.submit(pow, 2, 5).result() == 32
        failed = ex.submit(int, "x")
        assert failed.done() and isinstance(failed.exception(), ValueError)
    with K.parse_scheduler(None) as ex:
        assert isinstance(ex, K.SerialExecutor)
    with K.parse_scheduler("threads:2") as ex:
        assert isinstance(ex, ThreadPoolExecutor) and ex.submit(pow, 3, 2).result() == 9
    bar = K.ProgressExecutor(K.SerialExecutor(), total=2, desc="demo", enabled=True)
    assert [bar.submit(pow, 2, k).result() for k in (1, 2)] == [2, 4]
    bar.shutdown()
    assert "demo" in capsys.readouterr().err
    for spec, needle in [("dask", "unknown scheduler 'dask'"), ("threads:0", "positive integer"),
                         ("local:x", "positive integer"), ("processes", "unknown scheduler")]:
        with pytest.raises(ValueError, match=needle), K.parse_scheduler(spec):
            pass
    # an existing cluster by its address (here one in this process, on a loopback port the OS picks)
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1",
                      scheduler_port=0, dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        with K.parse_scheduler(cluster.scheduler_address) as ex:
            assert ex.submit(pow, 2, 10).result() == 1024
        assert cluster.workers  # the cluster is left running: only the client was closed
    # nothing listens on a port just released: a one-line error, not a hang
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(ValueError, match="cannot connect to a Dask scheduler"), \
            K.parse_scheduler(f"tcp://127.0.0.1:{port}", timeout="1s"):
        pass


# ------------------------------------------------------------------------------------------------ same numbers
def test_compare_cli_gives_the_same_json_serially_and_on_a_dask_local_cluster(tmp_path, capsys):
    """The issue's done-when, on a small grid: ``compare ... --json a.json`` and the same with ``--scheduler
    local:2`` (two Dask worker processes, each simulating and fitting on its own) write the same JSON."""
    argv = ["compare", *CLI_SMALL, "--cases", "2,5", "--scenario", "B", "--estimators", "hold,dmd"]
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert main([*argv, "--json", str(a)]) == 0
    assert main([*argv, "--json", str(b), "--scheduler", "local:2"]) == 0
    assert "R2 med" in capsys.readouterr().out
    assert a.read_bytes() == b.read_bytes()  # identical files: the JSON holds no wall-clock part by default
    ja = json.loads(a.read_text())
    assert [r["case"] for r in ja["runs"]] == [2, 2, 5, 5] and ja["lyapunov"]["time_s"] > 0
    assert "wall_clock" not in ja
    c = tmp_path / "c.json"
    assert main([*argv, "--json", str(c), "--scheduler", "threads:2", "--timings"]) == 0
    jc = json.loads(c.read_text())
    assert without_wall_clock(jc) == without_wall_clock(ja)
    assert len(jc["wall_clock"]["runs"]) == 4  # the timings, on request, apart


def test_a_bad_scheduler_is_a_one_line_cli_error(capsys):
    assert main(["compare", *CLI_SMALL, "--scheduler", "warp:3"]) == 2
    err = capsys.readouterr().err
    assert "unknown scheduler 'warp:3'" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_campaign_summary_is_compare_json_with_threads_and_an_in_process_dask_cluster(reference, tmp_path):
    with K.parse_scheduler("threads:2") as ex:
        threaded = K.run_campaign(tmp_path / "threads", **GRID, executor=ex)
    C.clear_cache()  # the Dask workers (threads of this process) simulate and fit again
    with K.parse_scheduler("local:2", processes=False) as ex:
        dask = K.run_campaign(tmp_path / "dask", **GRID, executor=ex)
    for done in (threaded, dask):
        assert done.ok and (done.n_tasks, done.ran, done.reused, done.retried) == (N_TASKS, N_TASKS, 0, 0)
        assert without_wall_clock(summary_of(done.out)) == reference
        assert without_wall_clock(done.to_dict()) == reference
        lines = journal(done.out)
        assert len(lines) == N_TASKS and all(r["status"] == "ok" and r["attempts"] == 1 for r in lines)
        camp = summary_of(done.out)["wall_clock"]["campaign"]
        assert camp["tasks"] == N_TASKS and camp["failed"] == 0
    # the result is ordered by the grid, whatever order the tasks finished in
    assert [(r["case"], r["seed"], r["estimator"]) for r in threaded.result.runs] == [
        (c, s, e) for c in (2, 5) for s in (SEED, 4) for e in ("hold", "dmd")]


# ------------------------------------------------------------------------------------------------ resume
def test_an_interrupted_campaign_resumes_with_only_the_missing_tasks(reference, tmp_path, calls):
    out = tmp_path / "camp"
    seen = []

    def stop_after_three(record):
        seen.append(record["key"])
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt), K.parse_scheduler("threads:2") as ex:
        K.run_campaign(out, **GRID, executor=ex, on_record=stop_after_three)
    first = journal(out)
    assert [r["key"] for r in first] == seen and len(first) == 3  # written as they finished, then stopped
    assert not (out / "summary.json").exists()

    calls.clear()
    done = K.run_campaign(out, **GRID)
    recorded = [r["key"] for r in first]
    expected = [["B", c, s, e, None if e == "hold" else 1.0] for c in (2, 5) for s in (SEED, 4)
                for e in ("hold", "dmd")] + ["lyapunov"]
    missing = [k for k in expected if k not in recorded]
    assert [list(c) if isinstance(c, tuple) else c for c in calls] == missing  # only the missing ones, in order
    assert (done.ran, done.reused) == (N_TASKS - 3, 3) and done.ok
    assert without_wall_clock(summary_of(out)) == reference
    assert len(journal(out)) == N_TASKS

    # once more: nothing to do; a bigger grid (one more seed) runs only its new tasks
    calls.clear()
    assert K.run_campaign(out, **GRID).ran == 0 and calls == []
    grown = K.run_campaign(out, **{**GRID, "seeds": [SEED, 4, 7]})
    assert calls == [("B", c, 7, e, None if e == "hold" else 1.0) for c in (2, 5) for e in ("hold", "dmd")]
    assert (grown.ran, grown.reused, len(grown.result.runs)) == (4, N_TASKS, 12)


def test_a_killed_campaign_with_a_torn_journal_resumes_from_the_cli(reference, tmp_path, capsys):
    """A campaign killed half-way (simulated: its journal cut to half its lines, the last one torn mid-write)
    completes only the missing tasks when the same command runs again, and ends with the uninterrupted summary."""
    out = tmp_path / "camp"
    argv = ["campaign", *CLI_SMALL, "--seeds", f"{SEED},4", "--cases", "2,5", "--scenario", "B",
            "--estimators", "hold,dmd", "--out", str(out), "--no-progress"]
    assert main(argv) == 0
    full = (out / "results.jsonl").read_text().splitlines(keepends=True)
    assert len(full) == N_TASKS and without_wall_clock(summary_of(out)) == reference
    keep = N_TASKS // 2
    (out / "results.jsonl").write_text("".join(full[:keep]) + full[keep][: len(full[keep]) // 2])
    capsys.readouterr()
    assert main(argv + ["--json", str(tmp_path / "copy.json")]) == 0
    text = capsys.readouterr().out
    assert f"{N_TASKS} tasks, {N_TASKS - keep} ran, {keep} reused from results.jsonl" in text and "R2 med" in text
    lines = (out / "results.jsonl").read_text().splitlines()
    assert len(lines) == N_TASKS and all(json.loads(line)["status"] == "ok" for line in lines)  # fragment gone
    assert lines[:keep] == [f.rstrip("\n") for f in full[:keep]]
    assert without_wall_clock(summary_of(out)) == reference
    assert without_wall_clock(json.loads((tmp_path / "copy.json").read_text())) == reference


def test_other_settings_in_the_same_directory_are_refused(tmp_path, capsys):
    out = tmp_path / "camp"
    K.run_campaign(out, ["B"], ["hold"], cases=[2], seeds=[SEED], settings=SETTINGS, lyapunov_time=None)
    other = dataclasses.replace(SETTINGS, duration=20.0)
    with pytest.raises(ValueError, match="other settings .*duration"):
        K.run_campaign(out, ["B"], ["hold"], cases=[2], seeds=[SEED], settings=other, lyapunov_time=None)
    assert K.run_campaign(out, ["B"], ["hold"], cases=[2], seeds=[SEED], settings=other, lyapunov_time=None,
                          fresh=True).ran == 1
    argv = ["campaign", *CLI_SMALL, "--cases", "2", "--scenario", "B", "--estimators", "hold", "--out", str(out),
            "--lyapunov-time", "none"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "other settings" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


# ------------------------------------------------------------------------------------------------ failures
class Flaky:
    """Hold-last-value whose first fit fails (a transient error), and one whose reconstruct always fails."""

    fits = 0
    lock = threading.Lock()

    def __init__(self, broken: bool) -> None:
        self.broken = broken

    def fit(self, Y, mask=None):
        with Flaky.lock:
            Flaky.fits += 1
            first = Flaky.fits == 1
        if first and not self.broken:
            raise ConnectionError("transient: the data store blinked")
        self.mean_ = np.mean(np.concatenate(Y), axis=0)
        return self

    def reconstruct(self, Y, mask):
        if self.broken:
            raise RuntimeError("sensor exploded\nsecond line of the message")
        return np.broadcast_to(self.mean_, Y.shape).copy()


@pytest.fixture
def flaky_estimators():
    Flaky.fits = 0
    C.register_estimator("flaky", lambda dt, ui, **_: Flaky(broken=False), uses_update_interval=False)
    C.register_estimator("broken", lambda dt, ui, **_: Flaky(broken=True), uses_update_interval=False)
    yield
    for name in ("flaky", "broken"):
        del C.ESTIMATORS[name]


def test_a_failing_task_is_retried_then_reported_never_dropped(flaky_estimators, tmp_path, capsys, calls):
    out = tmp_path / "camp"
    grid = {"scenarios": ["B"], "estimators": ["hold", "flaky", "broken"], "cases": [2], "seeds": [SEED],
            "settings": SETTINGS, "lyapunov_time": None}
    done = K.run_campaign(out, **grid, retries=2)
    hold, flaky, broken = (("B", 2, SEED, e, None) for e in ("hold", "flaky", "broken"))
    # the transient failure is retried once and succeeds; the broken sensor is tried 1 + 2 times
    assert calls == [hold, flaky, broken, flaky, broken, broken]
    assert not done.ok and done.retried == 3 and done.ran == 3
    assert done.failed == [{"key": ["B", 2, SEED, "broken", None], "task": f"scenario B, OLC 2, seed {SEED}, broken",
                            "attempts": 3, "error": "RuntimeError: sensor exploded"}]
    assert [r["estimator"] for r in done.result.runs] == ["hold", "flaky"]
    lines = {r["key"][3]: r for r in journal(out)}
    assert lines["flaky"]["status"] == "ok" and lines["flaky"]["attempts"] == 2
    assert lines["broken"]["status"] == "failed" and "sensor exploded" in lines["broken"]["traceback"]
    summary = summary_of(out)
    assert summary["failed"] == done.failed and [r["estimator"] for r in summary["runs"]] == ["hold", "flaky"]
    assert "FAILED after 3 attempt(s): scenario B, OLC 2, seed 3, broken: RuntimeError: sensor exploded" in (
        done.summary())

    # the CLI: rerunning retries only the failed task (default --retries 1: two attempts), exit code 1
    capsys.readouterr()
    argv = ["campaign", *CLI_SMALL, "--cases", "2", "--scenario", "B", "--estimators", "hold,flaky,broken",
            "--lyapunov-time", "none", "--out", str(out)]
    assert main(argv) == 1
    cap = capsys.readouterr()
    assert "3 tasks, 1 ran, 2 reused from results.jsonl, 1 retried, 1 failed" in cap.out
    assert "FAILED after 2 attempt(s)" in cap.out
    assert "1 task(s) failed" in cap.err and "Traceback" not in cap.err


def test_the_progress_bar_goes_to_stderr(tmp_path, capsys):
    K.run_campaign(tmp_path / "c", ["B"], ["hold"], cases=[2, 5], seeds=[SEED], settings=SETTINGS,
                   lyapunov_time=None, progress=True)
    err = capsys.readouterr().err
    assert "campaign" in err and "2/2" in err
    K.run_campaign(tmp_path / "c", ["B"], ["hold"], cases=[2, 5], seeds=[SEED], settings=SETTINGS,
                   lyapunov_time=None)  # default: off
    assert capsys.readouterr().err == ""


def test_a_campaign_process_killed_half_way_resumes(reference, tmp_path):
    """A real kill (SIGKILL, no chance to clean up) of ``fowt-env campaign`` once some tasks are recorded; the
    same campaign run again does only the tasks that were not recorded and ends with the uninterrupted summary."""
    out = tmp_path / "camp"
    argv = ["campaign", *CLI_SMALL, "--seeds", f"{SEED},4", "--cases", "2,5", "--scenario", "B",
            "--estimators", "hold,dmd", "--out", str(out), "--no-progress"]
    proc = subprocess.Popen([sys.executable, "-m", "fowt_env.cli", *argv], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    results = out / "results.jsonl"
    deadline = time.monotonic() + 120.0
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if results.exists() and results.read_text().count("\n") >= 2:
                break
            time.sleep(0.01)
    finally:
        proc.kill()
        _, err = proc.communicate(timeout=60)
    recorded = results.read_text().count("\n")
    assert recorded >= 2, err.decode()[-2000:]
    print(f"killed with {recorded} of {N_TASKS} tasks recorded")
    done = K.run_campaign(out, **GRID)
    assert (done.ran, done.reused) == (N_TASKS - recorded, recorded) and done.ok
    assert without_wall_clock(summary_of(out)) == reference
