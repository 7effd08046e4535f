"""Progress of long steps, shown with a total and an ETA on a terminal and nowhere else.

One helper for every long step of the library and the command line (identification, the discrepancy search,
sensing, comparisons, campaigns, validation, episodes): a `tqdm <https://tqdm.github.io>`_ bar on standard
error that

* appears only on a terminal (``progress=None``, the command line's choice) or when asked (``progress=True``);
  piped or redirected output carries no bars, no carriage returns;
* appears, on a terminal, only once the step has run for :data:`DEFAULT_DELAY_S` seconds (2 s; the environment
  variable ``FOWT_ENV_PROGRESS_DELAY`` sets another delay, 0 = at once), so quick steps stay quiet; a bar asked
  for explicitly (``progress=True``) appears at once;
* always shows the done/total count and the estimated time left, ``ETA mm:ss``, and is erased when the step ends;
* keeps its elapsed time moving every second while one unit of work runs, even inside a C call that holds the
  GIL (a small helper process redraws it on a real terminal; elsewhere a thread does).

Examples
--------
>>> from fowt_env.progress import progress_bar
>>> with progress_bar(3, "fitting", progress=False) as bar:
...     for _ in range(3):
...         bar.update(1)
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import IO, Any

__all__ = ["BAR_FORMAT", "DEFAULT_DELAY_S", "DELAY_ENV", "delay_s", "on_terminal", "progress_bar", "resolve",
           "simulation_bar"]

#: Seconds a step runs before its bar appears.
DEFAULT_DELAY_S: float = 2.0
#: Environment variable overriding :data:`DEFAULT_DELAY_S` (seconds, >= 0).
DELAY_ENV: str = "FOWT_ENV_PROGRESS_DELAY"
#: Done/total and the time left spelt out (tqdm's default writes the ETA as ``<mm:ss``).
BAR_FORMAT: str = ("{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} {unit} "
                   "[{elapsed} elapsed, ETA {remaining}{postfix}]")


def on_terminal(stream: IO[str] | None = None) -> bool:
    """Whether ``stream`` (default standard error) is a terminal.

    Parameters
    ----------
    stream : text stream, optional
        The stream the bar would be written to (default ``sys.stderr``).

    Returns
    -------
    bool
    """
    stream = sys.stderr if stream is None else stream
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


def resolve(progress: bool | None, stream: IO[str] | None = None) -> bool:
    """The ``progress`` argument of the library's long functions as a yes/no.

    Parameters
    ----------
    progress : bool or None
        True: show; False: do not; None: show when ``stream`` is a terminal.
    stream : text stream, optional
        Default standard error.

    Returns
    -------
    bool
    """
    return on_terminal(stream) if progress is None else bool(progress)


def delay_s() -> float:
    """Seconds a step runs before its bar appears: ``$FOWT_ENV_PROGRESS_DELAY`` if it is a number >= 0, else
    :data:`DEFAULT_DELAY_S`.

    Returns
    -------
    float
    """
    text = os.environ.get(DELAY_ENV, "").strip()
    try:
        value = float(text)
    except ValueError:
        return DEFAULT_DELAY_S
    return value if value >= 0 else DEFAULT_DELAY_S


def progress_bar(total: float | None, desc: str, *, unit: str = "steps", progress: bool | None = None,
                 initial: float = 0, leave: bool = False, stream: IO[str] | None = None, tick_s: float = 1.0) -> Any:
    """A progress bar with a total and an ETA, or a silent stand-in with the same methods.

    Parameters
    ----------
    total : float or None
        Units of work in the step (None: unknown, then no ETA can be given; avoid).
    desc : str
        What is running (``"identify"``, ``"discrepancy"``...).
    unit : str
        Name of the unit of work, plural (``"steps"``, ``"simulations"``, ``"tasks"``).
    progress : bool or None
        True: show at once; False: silent; None (default): show when ``stream`` is a terminal, once the step has
        run for :func:`delay_s` seconds.
    initial : float
        Work already done (a resumed campaign).
    leave : bool
        Keep the finished bar on screen (default: erase it).
    stream : text stream, optional
        Default standard error.
    tick_s : float
        Redraw the bar this often (s) while one unit of work runs, so that a long unit still shows the time
        going by; 0: redraw only on updates.

    Returns
    -------
    tqdm.tqdm
        ``update(n)``, ``set_postfix_str(text)``, ``close()``, a context manager; the total may grow
        (``bar.total += n; bar.refresh()``) when later work becomes known.
    """
    stream = sys.stderr if stream is None else stream
    return _bar_class()(total=total, desc=desc, unit=unit, initial=initial, file=stream,
                        disable=not resolve(progress, stream), leave=leave,
                        delay=delay_s() if progress is None else 0.0, dynamic_ncols=True,
                        smoothing=0.1, bar_format=BAR_FORMAT if total is not None else None, mininterval=0.2,
                        tick_s=tick_s)


@contextmanager
def simulation_bar(total_s: float, desc: str = "simulate", *, progress: bool | None = None,
                   stream: IO[str] | None = None) -> Iterator[tuple[Any, Callable[[float], None]]]:
    """A bar of simulated seconds and the hook that advances it, for ``surrogates.simulate(..., on_progress=hook)``.

    Parameters
    ----------
    total_s : float
        Simulated seconds the run will integrate (duration + transient, times the number of seeds).
    desc : str
        What is running.
    progress : bool or None
        As :func:`progress_bar`.
    stream : text stream, optional
        Default standard error.

    Yields
    ------
    bar : tqdm.tqdm
        The bar (whole seconds; ``set_postfix_str`` names the phase: before the first call of the hook it says
        ``set-up, waves and wind``).
    hook : callable
        ``hook(seconds)``: that many more simulated seconds are done; thread-safe (a batch of seeds calls it from
        several threads).
    """
    total = max(1, int(round(total_s)))
    lock = threading.Lock()
    done = [0.0]
    with progress_bar(total, desc, unit="s simulated", progress=progress, stream=stream) as bar:
        bar.set_postfix_str("set-up, waves and wind", refresh=False)

        def hook(seconds: float) -> None:
            with lock:
                if done[0] == 0.0:
                    bar.set_postfix_str("time stepping", refresh=False)
                done[0] += float(seconds)
                step = min(total, int(done[0] + 1e-6)) - bar.n
                if step > 0:
                    bar.update(step)

        yield bar, hook


_BAR: type | None = None

# The clock of a bar on a terminal is kept by a small helper process: a thread of this process cannot redraw
# while a C extension holds the GIL (one scipy.linalg.eigh or svd call held it 36-66 s on the busy 2-core
# machine, freezing the bar's elapsed time and ETA; numpy.linalg releases it). The helper hears the bar's state
# at every draw, postfix change and (at most every 0.1 s) update, draws the bar's own frames (the only writer of
# them, so that a redraw cannot land after a newer frame), and redraws it with the time gone by whenever it has
# heard nothing for a tick; it stops when told or when this process ends (its stdin closes).
_CLOCK_SOURCE = r"""
import json, os, select, signal, sys, time
signal.signal(signal.SIGINT, signal.SIG_IGN)
tick = float(sys.argv[1])
state, heard, fmt, pending, done = None, time.monotonic(), None, b"", False
out = os.fdopen(1, "w", encoding="utf-8", errors="replace")
while not done:
    ready, _, _ = select.select([0], [], [], tick)
    if ready:  # read the pipe itself: a buffered reader would keep lines that select() cannot see
        data = os.read(0, 1 << 16)
        pending += data
        *lines, pending = pending.split(b"\n")
        for line in lines:
            if line.strip() == b"stop":
                done = True
            elif line.strip():
                state, heard = json.loads(line), time.monotonic()
                if state.pop("draw", False) and not done:  # the bar's own frame: this process is its only writer
                    d = dict(state)
                    d.pop("delay", None)
                    if fmt is None:
                        from tqdm import tqdm
                        fmt = tqdm.format_meter
                    out.write("\r" + fmt(**d))
                    out.flush()
        done = done or not data
        continue
    if state is None or time.monotonic() - heard < tick:
        continue
    d = dict(state)
    delay = d.pop("delay", 0.0)
    d["elapsed"] = d["elapsed"] + time.monotonic() - heard
    if d["elapsed"] < delay:
        continue
    if fmt is None:
        from tqdm import tqdm
        fmt = tqdm.format_meter
    out.write("\r" + fmt(**d))
    out.flush()
out.close()
"""


def _bar_class() -> type:
    """tqdm whose elapsed time and ETA keep moving while a long unit of work runs (built on first use: importing
    this module does not import tqdm): redrawn every ``tick_s`` seconds by a helper process on a real terminal,
    else by a thread."""
    global _BAR
    if _BAR is not None:
        return _BAR
    import json
    import subprocess
    import time

    from tqdm import tqdm

    class _TickingBar(tqdm):  # type: ignore[misc,valid-type]
        """tqdm that redraws every ``tick_s`` seconds once its delay has passed."""

        def __init__(self, *args: Any, tick_s: float = 1.0, **kwargs: Any) -> None:
            self._clock: subprocess.Popen[bytes] | None = None
            self._sent = 0.0
            super().__init__(*args, **kwargs)
            self._stop = threading.Event()
            if self.disable or tick_s <= 0:
                return
            fd = _terminal_fd(self.fp)
            if fd is not None:
                try:
                    self._clock = subprocess.Popen([sys.executable, "-c", _CLOCK_SOURCE, str(float(tick_s))],
                                                   stdin=subprocess.PIPE, stdout=fd, stderr=subprocess.DEVNULL,
                                                   close_fds=True)
                except OSError:
                    self._clock = None
            if self._clock is not None:
                self._tell(force=True)
            else:
                threading.Thread(target=self._tick, args=(float(tick_s),), daemon=True).start()

        def _tell(self, force: bool = False, draw: bool = False) -> None:
            """Send the bar's state to the clock process (every call when forced, else at most every 0.1 s); with
            ``draw`` the clock draws it at once."""
            clock = getattr(self, "_clock", None)
            if clock is None or clock.stdin is None:
                return
            now = time.monotonic()
            if not force and now - self._sent < 0.1:
                return
            self._sent = now
            state = dict(self.format_dict)
            state["delay"] = float(self.delay or 0.0)
            state["draw"] = draw
            try:
                clock.stdin.write((json.dumps(state, default=str) + "\n").encode())
                clock.stdin.flush()
            except (OSError, ValueError):  # the clock is gone: the bar still works, without it
                self._clock = None

        def display(self, msg: str | None = None, pos: int | None = None) -> Any:
            if getattr(self, "_clock", None) is not None and msg is None and not pos:
                # the clock process draws every frame, so that its redraws and this one cannot cross on the
                # terminal (a stale count drawn after a newer one: 0, 5, 0, 600 under load)
                self._tell(force=True, draw=True)
                return True
            out = super().display(msg=msg, pos=pos)
            self._tell(force=True)
            return out

        def update(self, n: float = 1) -> Any:
            out = super().update(n)
            self._tell()
            return out

        def set_postfix_str(self, *args: Any, **kwargs: Any) -> None:
            super().set_postfix_str(*args, **kwargs)
            self._tell(force=True)

        def set_postfix(self, *args: Any, **kwargs: Any) -> None:
            super().set_postfix(*args, **kwargs)
            self._tell(force=True)

        def _tick(self, tick_s: float) -> None:
            while not self._stop.wait(tick_s):
                if not self.disable and self._time() - self.start_t >= self.delay:
                    self.refresh()

        def close(self) -> None:
            stop = getattr(self, "_stop", None)
            if stop is not None:
                stop.set()
            clock = getattr(self, "_clock", None)
            if clock is not None:
                self._clock = None
                try:  # told to stop, it exits without drawing again; one still starting up is simply ended
                    if clock.stdin is not None:
                        clock.stdin.write(b"stop\n")
                        clock.stdin.close()
                    clock.wait(timeout=0.5)
                except (OSError, ValueError, subprocess.TimeoutExpired):
                    clock.kill()
                    clock.wait()
            super().close()

    _BAR = _TickingBar
    return _BAR


def _terminal_fd(stream: Any) -> int | None:
    """The file descriptor of ``stream`` if it is a real terminal (a helper process can write to it), else None
    (a notebook's or a test's stand-in stream: the bar's thread draws there)."""
    if os.name == "nt":
        return None
    try:
        fd = stream.fileno()
    except (AttributeError, ValueError, OSError):
        return None
    return fd if os.isatty(fd) else None
