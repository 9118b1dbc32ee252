"""A progress line on stderr for runs that take a while: points done, rate and time left for
many scenes, or which run of ``auto``'s ladder one scene is on. Jupyter redraws a ``\\r``
line in place, as a terminal does."""

from __future__ import annotations

import sys
import time
from typing import Optional

#: Without an explicit ``progress=True``, a run says nothing for this long: a quick call
#: prints nothing at all.
QUIET_FOR_S = 2.0
#: The line is redrawn at most this often.
REDRAW_S = 0.2


def interactive() -> bool:
    """Whether someone is watching: a terminal on stderr, or a Jupyter kernel. A process
    with no stderr at all (``sys.stderr`` is None under some GUIs and notebook launchers)
    has nobody watching it."""
    stream = sys.stderr
    if stream is None:
        return False
    return "ipykernel" in sys.modules or bool(getattr(stream, "isatty", lambda: False)())


class Progress:
    """One line, redrawn in place, ended by a newline when the run is done.

    ``enabled`` is ``True`` (always shown), ``False`` (never) or ``None`` (shown when
    :func:`interactive`, once the run has taken :data:`QUIET_FOR_S`). Anything else is
    refused with a ``TypeError``, a callable included: it would never be called.
    """

    def __init__(self, label: str, enabled: Optional[bool]) -> None:
        if enabled is not None and not isinstance(enabled, bool):
            raise TypeError(
                f"{label}: progress must be True, False or None, got {type(enabled).__name__}"
                " (a callable is not called: read the returned table instead)"
            )
        self.label = label
        self.always = enabled is True
        self.enabled = interactive() if enabled is None else enabled
        self.started = time.monotonic()
        self.drawn_at = 0.0
        self.width = 0

    def points(self, done: int, total: int) -> None:
        """Many scenes: ``done`` of ``total``, the rate and the time left."""
        elapsed = time.monotonic() - self.started
        rate = done / elapsed if elapsed > 0 else 0.0
        text = f"{self.label}: {done}/{total} points, {rate:.3g}/s"
        if 0 < done < total and rate > 0:
            text += f", about {_duration((total - done) / rate)} left"
        elif done == total:
            text += f", {_duration(elapsed)}"
        self._draw(text, final=done == total)

    def run(self, run: int, t: float, t_end: float) -> None:
        """One scene: run ``run`` of ``auto``'s ladder (each repeats the scene from t = 0)
        has reached ``t`` of ``t_end``."""
        text = f"{self.label}: run {run} of auto's ladder, t = {t:.6g} of {t_end:.6g}"
        self._draw(text, final=t >= t_end)

    def close(self) -> None:
        """Ends the line, if one was drawn."""
        if self.width and sys.stderr is not None:
            sys.stderr.write("\n")
            sys.stderr.flush()
        self.width = 0

    def _draw(self, text: str, final: bool) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if not self.always and now - self.started < QUIET_FOR_S:
            return
        if not final and now - self.drawn_at < REDRAW_S:
            return
        self.drawn_at = now
        stream = sys.stderr
        if stream is None:
            return
        stream.write("\r" + text.ljust(self.width))
        stream.flush()
        self.width = len(text)


def _duration(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, rest = divmod(int(seconds), 60)
    if minutes < 60:
        return f"{minutes} min {rest} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes} min"
