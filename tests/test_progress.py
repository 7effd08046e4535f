"""Long steps show progress with a total and an ETA on a terminal, and nothing when piped (issue 19 item 3)."""

import fcntl
import io
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios
import time

import pytest

import surrogates
from fowt_env import discrepancy
from fowt_env.progress import DELAY_ENV, delay_s, progress_bar

# "identify:  50%|#####     | 2/4 steps [00:01 elapsed, ETA 00:01, SSI-COV]"
_BAR = re.compile(r"identify: +\d+%\|[^|]*\| (\d+)/(\d+) steps \[(\d\d:\d\d) elapsed, ETA (\d\d:\d\d|\?)")


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    path = tmp_path_factory.mktemp("progress") / "olc7.npz"
    surrogates.simulate(surrogates.FOWTModel(), 7, duration=60.0, seed=3).save(path)
    return path


def _identify_argv(path) -> list[str]:
    return [sys.executable, "-m", "fowt_env.cli", "identify", str(path), "--plane", "FA", "--no-reference"]


def _env() -> dict[str, str]:
    return {**os.environ, DELAY_ENV: "0", "COLUMNS": "120"}  # the bar at once: the step need not last 2 s here


def _run_on_a_terminal(argv: list[str], timeout: float = 300.0) -> tuple[int, str]:
    """Run ``argv`` with stdout and stderr on a pseudo-terminal (120 x 40); its return code and all it wrote."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 120, 0, 0))
    proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=slave, stderr=slave, env=_env(), close_fds=True)
    os.close(slave)
    chunks = []
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.5)
            if ready:
                try:
                    data = os.read(master, 65536)
                except OSError:  # EIO: the child closed the terminal
                    break
                if not data:
                    break
                chunks.append(data)
            elif proc.poll() is not None:
                break
        code = proc.wait(timeout=max(1.0, deadline - time.monotonic()))
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
    return code, b"".join(chunks).decode("utf-8", "replace")


def test_identify_on_a_terminal_shows_the_total_and_an_eta(record):
    code, out = _run_on_a_terminal(_identify_argv(record))
    assert code == 0, out
    bars = _BAR.findall(out)
    assert bars, out
    # band-pass, Hankel-DMD, SSI-COV, order tracking (the record has RotSpeed)
    assert {total for _, total, _, _ in bars} == {"4"}
    assert any(eta != "?" for *_, eta in bars), bars  # a time left, once a step is done
    assert [int(n) for n, *_ in bars] == sorted(int(n) for n, *_ in bars)
    assert "Hankel-DMD: delays" in out  # and the results, after the bar


def test_identify_piped_has_no_progress(record):
    proc = subprocess.run(_identify_argv(record), capture_output=True, text=True, env=_env(), timeout=300,
                          stdin=subprocess.DEVNULL)
    assert proc.returncode == 0, proc.stderr
    assert "Hankel-DMD: delays" in proc.stdout
    for stream in (proc.stdout, proc.stderr):
        assert "ETA" not in stream and "\r" not in stream and "%|" not in stream


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_bar_shows_only_on_a_terminal_and_only_after_its_delay(monkeypatch):
    monkeypatch.setenv(DELAY_ENV, "0")
    tty, pipe = _Terminal(), io.StringIO()
    for stream in (tty, pipe):
        with progress_bar(3, "work", stream=stream) as bar:
            bar.update(3)
    assert "/3 steps" in tty.getvalue() and "ETA" in tty.getvalue()
    assert pipe.getvalue() == ""
    forced = io.StringIO()  # asked for explicitly: shown, at once, on any stream
    with progress_bar(2, "work", unit="runs", progress=True, stream=forced) as bar:
        bar.update(2)
    assert "/2 runs" in forced.getvalue()
    monkeypatch.setenv(DELAY_ENV, "30")
    quick = _Terminal()
    with progress_bar(3, "work", stream=quick) as bar:  # done long before its delay: never drawn
        bar.update(3)
    assert quick.getvalue() == ""


@pytest.mark.parametrize(("text", "expected"), [("", 2.0), ("0", 0.0), ("0.5", 0.5), ("-1", 2.0), ("soon", 2.0)])
def test_delay_from_the_environment(monkeypatch, text, expected):
    monkeypatch.setenv(DELAY_ENV, text)
    assert delay_s() == expected


def test_discrepancy_progress_counts_every_simulation_it_runs(capsys, monkeypatch):
    """The total the bar announces is the work done: it ends at n == total (the ETA was honest)."""
    bars = []

    def keep(*args, **kwargs):
        bars.append(progress_bar(*args, **kwargs))
        return bars[-1]

    monkeypatch.setattr(discrepancy, "progress_bar", keep)
    model = surrogates.FOWTModel()
    measured = surrogates.simulate(model.without("mooring_nonlinear"), 7, duration=150.0, seed=4, dt=0.05)
    rep = discrepancy.run(measured, model, 7, candidates=["mooring_nonlinear"], n_seeds=3, n_scatter=4,
                          strengths=(0.0, 0.5, 1.5), max_effects=1, progress=True)
    err = capsys.readouterr().err
    assert re.search(r"discrepancy: +\d+%\|[^|]*\| \d+/\d+ simulations \[", err), err
    (bar,) = bars
    assert bar.n == bar.total
    # every simulation the workflow ran was counted: the scatter seeds (4), the screening probe and the profile
    # (when the gap is significant) and the spectra of the figure
    assert bar.total == rep.n_simulations >= 4 + 1
    assert rep.gap_before >= 0


# "simulate:  40%|####      | 72/180 s simulated [00:01 elapsed, ETA 00:01, time stepping]"
_SIM_BAR = re.compile(r"simulate: +\d+%\|[^|]*\| (\d+)/(\d+) s simulated \[(\d\d:\d\d) elapsed, ETA (\d\d:\d\d|\?)")


def _simulate_argv(path) -> list[str]:
    return [sys.executable, "-m", "fowt_env.cli", "simulate", "--case", "7", "--duration", "120", "--out", str(path)]


def test_simulate_on_a_terminal_shows_simulated_seconds_and_an_eta(tmp_path):
    code, out = _run_on_a_terminal(_simulate_argv(tmp_path / "r.npz"))
    assert code == 0, out
    bars = _SIM_BAR.findall(out)
    assert bars, out
    assert {total for _, total, _, _ in bars} == {"180"}  # 120 s + the 60 s transient
    assert any(eta != "?" for *_, eta in bars), bars
    assert [int(n) for n, *_ in bars] == sorted(int(n) for n, *_ in bars)
    assert "wrote " in out and (tmp_path / "r.npz").is_file()


@pytest.mark.slow  # the class is covered by the default identify tests; ~10-17 s of subprocess
def test_simulate_piped_has_no_progress(tmp_path):
    proc = subprocess.run(_simulate_argv(tmp_path / "r.npz"), capture_output=True, text=True, env=_env(), timeout=300,
                          stdin=subprocess.DEVNULL)
    assert proc.returncode == 0, proc.stderr
    assert "wrote " in proc.stdout
    for stream in (proc.stdout, proc.stderr):
        assert "ETA" not in stream and "\r" not in stream and "%|" not in stream



@pytest.mark.slow
def test_simulate_replay_on_a_terminal_shows_the_records_seconds(tmp_path):
    from pathlib import Path

    import fowt_env

    src = Path(fowt_env.__file__).parent / "data" / "openfast_reference" / "c_op12_Hs2p5_Tp10.npz"
    code, out = _run_on_a_terminal([sys.executable, "-m", "fowt_env.cli", "simulate", "--replay", str(src),
                                    "--out", str(tmp_path / "replay.npz")])
    assert code == 0, out
    bars = re.findall(r"replay: +\d+%\|[^|]*\| (\d+)/(\d+) s simulated \[\d\d:\d\d elapsed, ETA (\d\d:\d\d|\?)", out)
    assert bars and {total for _, total, _ in bars} == {"600"}, out  # the record's 600 s
    counts = [int(n) for n, _, _ in bars]  # the final frame may be skipped (see the identify figures test)
    assert counts == sorted(counts) and max(counts) > 0 and any(eta != "?" for *_, eta in bars)


@pytest.mark.slow  # the class is covered by the default identify tests; ~10-17 s of subprocess
def test_identify_plot_on_a_terminal_counts_its_figures(record, tmp_path):
    """The figures (13.8 s for four on a busy 2-core machine, 600 s record) have their own bar."""
    code, out = _run_on_a_terminal([*_identify_argv(record), "--no-ssi", "--rotor-speed", "none", "--plot",
                                    str(tmp_path / "figs")])
    assert code == 0, out
    bars = re.findall(r"figures: +\d+%\|[^|]*\| (\d+)/(\d+) figures \[\d\d:\d\d elapsed, ETA (\d\d:\d\d|\?)", out)
    assert bars and {total for _, total, _ in bars} == {"3"}, out  # eigenvalues, singular values, spectrogram
    # counts never go back; the final frame itself may be skipped (tqdm redraws at most every 0.2 s and the bar is
    # erased at close: under load the last figure can finish within that interval)
    counts = [int(n) for n, _, _ in bars]
    assert counts == sorted(counts) and len(list((tmp_path / "figs").glob("*.png"))) == 3


def test_episode_on_a_terminal_shows_its_steps_from_the_set_up_on(tmp_path):
    """The environment's set-up and warm-up (10-20 s on a busy machine) and the files written are inside the bar."""
    code, out = _run_on_a_terminal([sys.executable, "-m", "fowt_env.cli", "episode", "--duration", "20",
                                    "--out", str(tmp_path / "ep.npz")])
    assert code == 0, out
    bars = re.findall(r"episode: +\d+%\|[^|]*\| (\d+)/(\d+) steps \[\d\d:\d\d elapsed, ETA (\d\d:\d\d|\?)([^\]]*)\]",
                      out)
    assert bars and {total for _, total, _, _ in bars} == {"1599"}, out
    assert any("set-up and warm-up" in phase for *_, phase in bars) and any(eta != "?" for _, _, eta, _ in bars)
    assert (tmp_path / "ep.npz").is_file() and (tmp_path / "ep_truth.npz").is_file()


def test_figures_of_discrepancy_compare_and_campaign_draw_under_a_bar(capsys, monkeypatch):
    """The CLI's figure writing (10-16 s for discrepancy's and compare's figures on a busy machine) shows a bar."""
    from fowt_env import cli, progress

    monkeypatch.setenv(DELAY_ENV, "0")
    monkeypatch.setattr(progress, "on_terminal", lambda stream=None: True)
    assert cli._drawn(lambda: ["a.png", "b.png"]) == ["a.png", "b.png"]
    assert re.search(r"figures: +\d+%\|[^|]*\| [01]/1 steps \[\d\d:\d\d elapsed, ETA", capsys.readouterr().err)


def test_the_clock_moves_while_a_c_call_holds_the_gil(tmp_path):
    """A thread cannot redraw while one C call holds the GIL (scipy.linalg.eigh/svd held it 36-66 s on the busy
    machine); the bar's helper process can. Here libc's sleep(4) through ctypes.PyDLL, which keeps the GIL."""
    script = tmp_path / "held.py"
    script.write_text("import ctypes\nfrom fowt_env.progress import progress_bar\n"
                      "with progress_bar(1, 'held', progress=True) as bar:\n"
                      "    ctypes.PyDLL(None).sleep(4)\n"
                      "    bar.update(1)\n")
    code, out = _run_on_a_terminal([sys.executable, str(script)])
    assert code == 0, out
    elapsed = set(re.findall(r"held: +0%\|[^|]*\| 0/1 steps \[(\d\d:\d\d) elapsed", out))
    assert {"00:02", "00:03"} & elapsed, out  # redrawn during the call, not only before and after it


@pytest.mark.slow  # ~5-10 s of subprocess; the class (a bar on a terminal) is covered by the default tests
def test_modes_on_a_terminal_counts_its_two_steps():
    code, out = _run_on_a_terminal([sys.executable, "-m", "fowt_env.cli", "modes", "--case", "7"])
    assert code == 0, out
    assert re.search(r"modes.*[012]/2 steps", out), out  # a bar with its total (tqdm may skip a redraw <0.2 s)
    assert "tower_fa_1" in out
