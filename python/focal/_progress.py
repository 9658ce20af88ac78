"""The progress= argument: a callable of the caller's, or a tqdm bar on a terminal (tqdm is
optional: without it, or when stderr is not a terminal, nothing is shown)."""

from __future__ import annotations

import importlib
import sys
from typing import Any, Callable, Optional

from ._errors import InvalidInputError

# progress(stage, pass_number, fraction): what the library reports (Execution::progress and
# pass_progress in include/focal/core/execution.h). pass_number 0: the stage begins (fraction
# 0.0) or ends (1.0); k >= 1: the k-th parallel pass of the stage, `fraction` of that pass done
# (a stage runs one or more passes; how many depends on the input).
ProgressCallable = Callable[[str, int, float], Any]


class _TqdmBars:
    """One tqdm bar a stage (nested stages nest their bars), its percent that of the running
    pass; drawn only once a stage has run a second (tqdm's delay), removed when it ends."""

    def __init__(self, tqdm: Any) -> None:
        self._tqdm = tqdm
        self._bars: list = []  # [bar, stage, pass number] of the stages begun, innermost last

    def __call__(self, stage: str, pass_number: int, fraction: float) -> None:
        if pass_number == 0:
            if fraction == 0.0:
                bar = self._tqdm(total=100, desc=stage, unit="%", leave=False, delay=1.0)
                self._bars.append([bar, stage, 0])
            elif self._bars:
                self._bars.pop()[0].close()
            return
        if not self._bars:
            return
        entry = self._bars[-1]
        bar = entry[0]
        if entry[2] != pass_number:
            entry[2] = pass_number
            bar.reset(total=100)
            bar.set_description(f"{entry[1]}, pass {pass_number}", refresh=False)
        bar.update(int(100 * fraction) - bar.n)


def _stderr_is_terminal() -> bool:
    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except (AttributeError, ValueError):  # replaced by an object without it, or closed
        return False


def _progress(progress: Any) -> Optional[ProgressCallable]:
    """progress= resolved: None (the default): a tqdm bar when tqdm is installed and stderr is a
    terminal, else nothing; False: nothing; a callable: called as ProgressCallable says."""
    if progress is False:
        return None
    if progress is None:
        if not _stderr_is_terminal():
            return None
        try:  # by name: tqdm is optional, and without stubs of its own
            tqdm = importlib.import_module("tqdm").tqdm
        except ImportError:
            return None
        return _TqdmBars(tqdm)
    if callable(progress):
        return progress
    raise InvalidInputError(
        "progress must be None (a tqdm bar on a terminal, when tqdm is installed), False or a "
        f"callable progress(stage, pass_number, fraction), got {type(progress).__name__}"
    )
