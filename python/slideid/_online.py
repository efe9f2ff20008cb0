"""Identification while pushing: slideid.OnlineIdentifier (docs/online.md)."""

import json
from collections.abc import Mapping

import numpy as np

from . import _core
from ._log import Log, _metadata_entries

#: The columns a row carries unless the identifier is told otherwise: time and pose, and
#: the force at the CM.
DEFAULT_COLUMNS = ("t", "x", "y", "theta", "fx", "fy")


class OnlineIdentifier:
    """The friction identified row by row as a push is logged (estimator/online_identifier.h).

    ``metadata`` is a ``slideid.Log`` (its slider properties, patch and tip radius) or a
    dict with ``mass`` [kg], ``inertia`` [kg m^2], ``com_height`` [m] and optionally
    ``gravity``, ``patch`` and ``tip_radius`` [m]. ``columns`` names what each row carries, in order (log-format.md's column
    names: ``t``, ``x``, ``y``, ``theta``, ``fx``, ``fy``, ``px``, ``py``, ``pz``, ...); rows
    are read as the log reader reads a file's rows (moments r x f at a push point).

    ``update(row)`` takes one row (a sequence in the columns' order, or a dict by name) and
    returns the estimate after it; ``update_many(array)`` takes an (n, columns) array and
    returns the estimate after each row, running without the GIL. An estimate is a plain
    dict, the JSON line of ``identify --follow``: ``row``, ``t``, ``started``, and for
    ``e_t_mu``, ``e_o_over_e_t``, ``e_r_over_e_t`` a dict of ``value``, ``stderr``, ``ci95``
    and ``verdict``; ``mu_pusher`` likewise (with ``lower_bound``, ``contact_rows`` and
    ``sliding_rows``) where the rows carry the tip (columns ``tip_x``, ``tip_y``) and the
    metadata its radius and the patch; ``changes`` (how many changes of the friction so far) and ``change``
    (the one found at this row, or None); ``batch_checks`` and ``batch_takeovers``.

    ``batch_check_rows``: the rows after which the estimate is first checked against the
    trajectory fit of the rows so far (then after twice, four times as many ...), the fit's
    taken over where the filter ran off; an update that runs a check takes the fit's time.
    0: no check.
    """

    def __init__(self, metadata, columns=DEFAULT_COLUMNS, batch_check_rows=128):
        if isinstance(metadata, Log):
            metadata = metadata.metadata
        if not isinstance(metadata, Mapping):
            raise TypeError("OnlineIdentifier: metadata must be a slideid.Log or a dict")
        missing = [k for k in ("mass", "inertia", "com_height") if metadata.get(k) is None]
        if missing:
            raise ValueError(f"OnlineIdentifier: metadata needs {', '.join(missing)}")
        self.columns = tuple(str(c) for c in columns)
        tip = metadata.get("tip_radius")
        entries = _metadata_entries(metadata["mass"], metadata["inertia"],
                                    metadata["com_height"], metadata.get("gravity"),
                                    metadata.get("patch"), None,
                                    None if tip is None else {"tip_radius": repr(float(tip))})
        if isinstance(batch_check_rows, bool) or int(batch_check_rows) != batch_check_rows:
            raise TypeError("OnlineIdentifier: batch_check_rows must be an integer")
        if batch_check_rows < 0:
            raise ValueError("OnlineIdentifier: batch_check_rows must be >= 0 (0: no check)")
        self._core = _core.OnlineCore(entries, list(self.columns), int(batch_check_rows))

    def update(self, row):
        """The estimate after one more row (a sequence in the columns' order, or a dict)."""
        if isinstance(row, Mapping):
            unknown = sorted(set(row) - set(self.columns))
            if unknown:
                raise ValueError(f"OnlineIdentifier.update: unknown columns {unknown} "
                                 f"(the identifier's are {list(self.columns)})")
            absent = [c for c in self.columns if c not in row]
            if absent:
                raise ValueError(f"OnlineIdentifier.update: the row lacks {absent}")
            row = [row[c] for c in self.columns]
        return self.update_many(np.asarray([row], dtype=np.float64))[0]

    def update_many(self, rows):
        """The estimate after each row of an (n, columns) array, in order."""
        array = np.asarray(rows, dtype=np.float64)
        if array.ndim != 2 or array.shape[1] != len(self.columns):
            raise ValueError(f"OnlineIdentifier.update_many: rows must have shape (n, "
                             f"{len(self.columns)}), got {array.shape}")
        return [json.loads(line) for line in self._core.update_many(np.ascontiguousarray(array))]
