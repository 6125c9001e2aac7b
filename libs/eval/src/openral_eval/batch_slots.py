"""Slots of a batch of observations (gymnasium's layout for a space: arrays with one row per
env, in dicts and tuples), written and copied without walking the tree every step.

A vector step writes every env's observation into its row and copies rows out of shared
memory: a few microseconds each, on the path of every step. :class:`BatchSlots` finds the
arrays of a batch once; a flat ``Dict`` of arrays (the scene env's observation) or one
array is then a loop over its arrays, anything else the general walk.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def place(batch: Any, i: int, value: Any) -> None:
    """Write one env's ``value`` into slot ``i`` of a batch (dicts, tuples, arrays)."""
    if isinstance(batch, dict):
        for key, part in batch.items():
            place(part, i, value[key])
    elif isinstance(batch, tuple):
        for part, item in zip(batch, value, strict=True):
            place(part, i, item)
    else:
        batch[i] = value


def copied(batch: Any, i: int | None = None) -> Any:
    """A copy of a batch (dicts, tuples, arrays), or of its slot ``i`` only (a batch read
    from shared memory: the next step overwrites it)."""
    if isinstance(batch, dict):
        return {key: copied(part, i) for key, part in batch.items()}
    if isinstance(batch, tuple):
        return tuple(copied(part, i) for part in batch)
    return np.array(batch if i is None else batch[i], copy=True)


class BatchSlots:
    """The rows of one batch (see the module doc)."""

    def __init__(self, batch: Any) -> None:
        self.batch = batch
        flat = isinstance(batch, dict) and all(isinstance(v, np.ndarray) for v in batch.values())
        self._arrays: list[tuple[str, np.ndarray]] | None = list(batch.items()) if flat else None
        """(key, array) of a flat Dict batch (None: another layout)."""
        self._array = batch if isinstance(batch, np.ndarray) else None
        """The batch when it is one array."""

    def write(self, i: int, value: Any) -> None:
        """Write one env's observation ``value`` into row ``i``."""
        if self._array is not None:
            self._array[i] = value
        elif self._arrays is not None:
            for key, array in self._arrays:
                array[i] = value[key]
        else:
            place(self.batch, i, value)

    def copy_row(self, source: BatchSlots, row: int, i: int) -> None:
        """Copy ``source``'s row ``row`` (a batch of the same space) into row ``i``."""
        if self._arrays is not None and source._arrays is not None:
            theirs = source.batch
            for key, array in self._arrays:
                array[i] = theirs[key][row]
        elif self._array is not None and source._array is not None:
            self._array[i] = source._array[row]
        else:
            place(self.batch, i, copied(source.batch, row))

    def row(self, i: int) -> Any:
        """A copy of row ``i`` (the next write overwrites the batch)."""
        if self._array is not None:
            return self._array[i].copy()
        return copied(self.batch, i)

    def fresh(self) -> BatchSlots:
        """The rows of a new batch of the same layout (its values not yet written)."""
        if self._arrays is not None:
            return BatchSlots({key: np.empty_like(array) for key, array in self._arrays})
        if self._array is not None:
            return BatchSlots(np.empty_like(self._array))
        return BatchSlots(copied(self.batch))

    def copy(self) -> Any:
        """A copy of the whole batch."""
        if self._arrays is not None:
            return {key: array.copy() for key, array in self._arrays}
        return copied(self.batch)
