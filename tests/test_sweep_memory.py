"""Issue 74 (the suite's time), round 9: a sweep run's garbage collection
(faultgen.runs.worker.run_memory, through faultgen.collection.young_only) looks only at what the run
made and leaves nothing frozen; a process's own freeze is left as it is."""

from __future__ import annotations

import gc
import weakref

import pytest

from faultgen import collection
from faultgen.runs import worker


def test_a_runs_cyclic_garbage_is_collected_at_its_end_and_nothing_stays_frozen():
    """faultgen.runs.worker.run_memory, around every run of a sweep: what was alive before the run is
    frozen during it (left out of the run's collection), the run's own cyclic garbage is collected when
    it ends, and everything is thawed after it, also when the run fails."""
    class Node:
        pass

    freed = []
    old = Node()
    old.cycle = old
    weakref.finalize(old, freed.append, "old")
    assert gc.get_freeze_count() == 0
    with worker.run_memory():
        assert gc.get_freeze_count() > 0 and gc.is_tracked(old)
        made = Node()
        made.cycle = made
        weakref.finalize(made, freed.append, "made")
        del made, old  # both now cyclic garbage: the run's own, and one from before the run
    assert freed == ["made"] and gc.get_freeze_count() == 0
    gc.collect()  # thawed: the older garbage goes at the next full collection
    assert freed == ["made", "old"]
    with pytest.raises(RuntimeError), worker.run_memory():
        raise RuntimeError("a run that failed")
    assert gc.get_freeze_count() == 0


def test_a_process_that_froze_its_own_objects_keeps_them_frozen_and_collects_in_full():
    """Where the process had frozen objects itself, young_only neither freezes more nor thaws them, and
    a collection inside the block is a full one (a run's garbage still goes at its end)."""
    class Node:
        pass

    def still_frozen(count: int) -> bool:  # none thawed, none added; a frozen object another thread of
        # the worker drops (its count falls by one or two under load) is neither
        return 0 <= count - gc.get_freeze_count() <= 50 and count > 50

    freed = []
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        with worker.run_memory():
            assert still_frozen(frozen)
            made = Node()
            made.cycle = made
            weakref.finalize(made, freed.append, "made")
            del made
        assert freed == ["made"] and still_frozen(frozen)
        with collection.young_only():
            assert still_frozen(frozen)
        assert still_frozen(frozen)
    finally:
        gc.unfreeze()

