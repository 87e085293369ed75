"""The garbage collector around a piece of work that ends in a full collection.

A full ``gc.collect()`` walks every object of the process: in a process that has imported faultgen's
commands (a test session, a notebook, a sweep's worker) hundreds of thousands of them, 0.17 s of CPU
a sweep's run and 0.76 s of a 5.3 s calibration (statsmodels' Holm adjustment collects on each call).
:func:`young_only` freezes what is alive before the work (``gc.freeze``), so that a collection during
or at the end of it looks at what the work made, and thaws it after (``gc.unfreeze``), also when the
work fails. Used by a sweep's run (:func:`faultgen.runs.worker.run_memory`) and by the calibration's
residual tests (:mod:`faultgen.calibrate.residual_tests`).
"""

from __future__ import annotations

import contextlib
import gc


@contextlib.contextmanager
def young_only():
    """Within the block, every object alive when it began is frozen: the collector leaves it alone
    (an older object that becomes garbage inside goes at the next collection after the block). Where
    the process had frozen objects of its own, nothing is frozen or thawed (its freeze is left as it
    is, and a collection inside is a full one)."""
    own = not gc.get_freeze_count()
    if own:
        gc.freeze()
    try:
        yield
    finally:
        if own:
            gc.unfreeze()
