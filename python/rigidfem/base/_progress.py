"""A progress bar for long runs: tqdm when installed, otherwise one line on stderr."""

from __future__ import annotations

import sys


class ProgressBar:
    """Progress ``done`` of ``total`` (in ``unit``), shown as ``desc``; ``update(done)`` sets it."""

    def __init__(self, total: float, unit: str, desc: str):
        self.total, self.unit, self.desc = total, unit, desc
        try:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=total, unit=unit, desc=desc)
        except ImportError:
            self.bar = None

    def update(self, done: float) -> None:
        if self.bar is not None:
            self.bar.update(done - self.bar.n)
        else:
            print(f"\r{self.desc}: {done:.4g} of {self.total:g} {self.unit}", end="", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        else:
            print(file=sys.stderr)
