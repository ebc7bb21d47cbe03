"""Progress bars (tqdm) for the client's long calls, and nothing when they are not wanted.

Every long call (readings, load_readings, wait, export, grid, interpolate_batch,
interpolate_grid) takes `progress`: True shows a tqdm bar on standard error, False none, None (the
default) one when someone watches: standard error is a terminal, or the code runs in a Jupyter
kernel. tqdm is Debian's python3-tqdm; without it there is no bar and nothing else changes.

A bar never outlives its call: it is closed when the call returns, raises, or is interrupted
(Ctrl-C), so a cancelled stream leaves no half-drawn line behind.
"""

import sys
from types import TracebackType
from typing import Any, Optional, Type


def _in_kernel() -> bool:
    """True inside a Jupyter (IPython) kernel, where standard error is not a terminal."""
    shell = sys.modules.get("IPython")
    if shell is None:
        return False
    try:
        ip = shell.get_ipython()
    except Exception:  # pylint: disable=broad-except
        return False
    return ip is not None and hasattr(ip, "kernel")


def wanted(progress: Optional[bool]) -> bool:
    """Whether to show a bar: `progress` if given, else when a person is watching."""
    if progress is not None:
        return bool(progress)
    try:
        tty = sys.stderr.isatty()
    except (AttributeError, ValueError):
        tty = False
    return tty or _in_kernel()


class Bar:
    """A tqdm bar, or a stand-in that does nothing (no tqdm, or not wanted).

    total: the count at the end (None: unknown, the bar counts up); desc: what is being done;
    unit: what is counted ("reading", "direction", "%").
    """

    def __init__(self, progress: Optional[bool], total: Optional[float] = None, desc: str = "",
                 unit: str = "it") -> None:
        self._bar: Any = None
        if not wanted(progress):
            return
        try:
            from tqdm import tqdm  # pylint: disable=import-outside-toplevel
        except ImportError:
            return
        # A percentage reads as one: no rate, no "n/total".
        fmt = "{desc}: {percentage:3.0f}%|{bar}| {elapsed}" if unit == "%" else None
        self._bar = tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, leave=True,
                         dynamic_ncols=True, bar_format=fmt)

    @property
    def shown(self) -> bool:
        """True when a bar is drawn."""
        return self._bar is not None

    def update(self, n: float = 1) -> None:
        """Adds `n` to the count."""
        if self._bar is not None:
            self._bar.update(n)

    def moveto(self, n: float, total: Optional[float] = None, desc: Optional[str] = None) -> None:
        """Sets the count to `n` (and the total, and the description when given)."""
        if self._bar is None:
            return
        if total is not None and total != self._bar.total:
            self._bar.total = total
        if desc is not None:
            self._bar.set_description_str(desc, refresh=False)
        self._bar.update(n - self._bar.n)

    def close(self) -> None:
        """Ends the bar (idempotent)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> "Bar":
        return self

    def __exit__(self, kind: Optional[Type[BaseException]], value: Optional[BaseException],
                 tb: Optional[TracebackType]) -> None:
        self.close()
