"""Campaign directories under concurrency and interruption (issue 18, Campaigns): one campaign at a time per
directory (a second run stops at once, naming the holder's PID), unique temporary names, and a campaign
interrupted by SIGINT or SIGKILL in the middle of a task leaves a valid journal that a rerun completes with exactly
the missing tasks."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from fowt_env import campaign as K
from fowt_env import compare as C
from fowt_env.cli import main

sys.path.insert(0, str(Path(__file__).parent))
import campaign_slow_sensor  # noqa: E402

SETTINGS = C.CompareSettings(train_cases=(1, 6), train_duration=60.0, duration=30.0,
                             estimator_options={"kalman": {"em_iter": 3}})
CLI_SMALL = ["--train-cases", "1,6", "--train-duration", "60", "--duration", "30", "--option", "kalman.em_iter=3",
             "--scenario", "B", "--cases", "2", "--lyapunov-time", "none", "--no-progress"]
HELPER = str(Path(campaign_slow_sensor.__file__))


def journal(folder: Path) -> list[dict]:
    return [json.loads(line) for line in (folder / "results.jsonl").read_text().splitlines()]


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


@pytest.fixture
def slow_sensor():
    campaign_slow_sensor.register(0.0)
    yield
    C.ESTIMATORS.pop("slow", None)


@pytest.fixture
def calls(monkeypatch) -> list:
    """Grid keys [scenario, case, seed, estimator, interval] of the run_unit calls made in this process."""
    seen, lock = [], threading.Lock()
    run_unit = C.run_unit

    def counting(*args):
        with lock:
            seen.append([args[2], args[0], args[1], args[3], args[4]])
        return run_unit(*args)

    monkeypatch.setattr(C, "run_unit", counting)
    return seen


def test_a_second_campaign_on_a_busy_directory_stops_at_once_naming_the_holder(tmp_path, capsys):
    out = tmp_path / "camp"
    grid = {"scenarios": ["B"], "estimators": ["hold"], "cases": [2, 5], "seeds": [3], "settings": SETTINGS,
            "lyapunov_time": None}
    first_written, go_on = threading.Event(), threading.Event()
    outcome: dict = {}

    def hold_the_directory(record):
        first_written.set()
        assert go_on.wait(120)

    def first_campaign():
        outcome["done"] = K.run_campaign(out, **grid, on_record=hold_the_directory)

    runner = threading.Thread(target=first_campaign)
    runner.start()
    try:
        assert first_written.wait(300)
        with pytest.raises(K.CampaignBusyError, match=f"in use by another running campaign \\(PID {os.getpid()} on "):
            K.run_campaign(out, **grid)
        with pytest.raises(K.CampaignBusyError):  # --fresh cannot delete the journal the first one appends to
            K.run_campaign(out, **grid, fresh=True)
        capsys.readouterr()
        argv = ["campaign", *CLI_SMALL, "--seeds", "3", "--estimators", "hold", "--cases", "2,5", "--out", str(out)]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert f"PID {os.getpid()}" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    finally:
        go_on.set()
        runner.join(300)
    assert outcome["done"].ok and outcome["done"].ran == 2
    assert len(journal(out)) == 2  # each task once: the refused runs ran nothing
    again = K.run_campaign(out, **grid)  # the lock went with the first run
    assert (again.ran, again.reused) == (0, 2)
    assert leftovers(out) == []


def test_temporary_names_are_unique(tmp_path, monkeypatch):
    seen = []
    real_replace = os.replace

    def spy(src, dst):
        seen.append(Path(src).name)
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", spy)
    for _ in range(2):
        K._replace_atomically(tmp_path / "summary.json", "{}")
    assert len(set(seen)) == 2 and all(name.startswith(".summary.json.") for name in seen)
    assert all(str(os.getpid()) in name for name in seen)


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _helper_command(seconds: float, markers: Path, argv: list[str]) -> list[str]:
    return [sys.executable, HELPER, str(seconds), str(markers), "--", *argv]


@pytest.mark.slow
def test_two_campaign_processes_on_one_directory(tmp_path):
    """Two `fowt-env campaign` processes started together on one --out: one runs every task once, the other stops
    at once with a one-line error naming the first one's PID."""
    out, markers = tmp_path / "camp", tmp_path / "markers"
    markers.mkdir()
    argv = ["campaign", *CLI_SMALL, "--seeds", "3,4", "--estimators", "hold,slow", "--out", str(out)]
    procs = [subprocess.Popen(_helper_command(2.0, markers, argv), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(2)]
    results = [(p.pid, p.wait(600), *p.communicate()) for p in procs]
    codes = sorted(code for _, code, _, _ in results)
    assert codes == [0, 2], results
    (winner,) = [pid for pid, code, _, _ in results if code == 0]
    (err,) = [e for _, code, _, e in results if code == 2]
    assert f"in use by another running campaign (PID {winner} on " in err and "Traceback" not in err, err
    lines = journal(out)
    assert len(lines) == 4 and len({json.dumps(r["key"]) for r in lines}) == 4
    assert all(r["status"] == "ok" for r in lines) and leftovers(out) == []


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL], ids=["SIGINT", "SIGKILL"])
def test_a_campaign_signalled_in_the_middle_of_a_task_resumes_with_exactly_the_missing_tasks(
        tmp_path, capsys, slow_sensor, calls, sig):
    out, markers = tmp_path / "camp", tmp_path / "markers"
    markers.mkdir()
    argv = ["campaign", *CLI_SMALL, "--seeds", "3,4,5", "--estimators", "hold,slow", "--out", str(out)]
    # SIGINT as a terminal user sends it: a child started from a background job (`cmd &` in a script, as CI may
    # run) inherits SIGINT ignored, and Python then installs no KeyboardInterrupt handler; restore the default
    proc = subprocess.Popen(_helper_command(3.0, markers, argv), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            preexec_fn=_default_sigint,
                            text=True)
    try:
        deadline = time.monotonic() + 300
        while len(list(markers.iterdir())) < 2 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert proc.poll() is None, proc.communicate()[1]
        time.sleep(0.3)  # well inside the second seed's slow task (3 s)
        proc.send_signal(sig)
        code = proc.wait(120)
    finally:
        if proc.poll() is None:
            proc.kill()
        err = proc.communicate()[1]
    if sig == signal.SIGINT:
        assert code == 130 and "interrupted" in err and "Traceback" not in err, err
    else:
        assert code == -signal.SIGKILL
    # the journal: whole lines, each a finished task; the batch under way (seed 4) left nothing
    before = (out / "results.jsonl").read_text()
    assert before.endswith("\n")
    recorded = [r["key"] for r in journal(out)]
    assert recorded == [["B", 2, 3, "hold", None], ["B", 2, 3, "slow", None]]
    assert all(r["status"] == "ok" for r in journal(out))

    capsys.readouterr()
    assert main(argv) == 0  # the same command, in this process (the slow sensor registered without its naps)
    assert calls == [["B", 2, s, e, None] for s in (4, 5) for e in ("hold", "slow")]  # exactly the missing ones
    assert "6 tasks, 4 ran, 2 reused from results.jsonl" in capsys.readouterr().out
    assert (out / "results.jsonl").read_text().startswith(before) and len(journal(out)) == 6
    assert (out / "summary.json").is_file() and leftovers(out) == []
