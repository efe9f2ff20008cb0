"""Many logs: the files a directory or a glob names, and their results as a table: one flat row per log, read off the per-file dicts that
identify_file returns, that slideid.dask writes, and that ``identify --batch`` writes as
JSON lines (the same objects, but for "error_type")."""

import json
import os

from . import _core
from ._identify import PARAMETERS

#: The columns of a row, in order. Per parameter p (e_t_mu = a, e_o_over_e_t = b,
#: e_r_over_e_t = c [m]): p (the estimate, None when not identifiable or failed),
#: p_stderr, p_lo and p_hi (the 95% interval) and p_verdict ("ok", "suspect",
#: "not identifiable").
ROW_FIELDS = (
    ("file", "ok", "status", "method", "rows", "seconds")
    + tuple(f"{p}{suffix}" for p in PARAMETERS
            for suffix in ("", "_stderr", "_lo", "_hi", "_verdict"))
    + ("warnings", "error", "error_type"))


def rows_fitted(result):
    """The rows of the logs a result fitted, as identify --batch counts them."""
    if result["logs"]:
        return sum(log["rows"] for log in result["logs"])
    return result["steps_total"] + 1


def result_row(entry):
    """One flat dict (the keys of ROW_FIELDS) from one log's dict: what identify_file
    returns, or a line of identify --batch or of slideid.dask.write_results. A failed log
    has ok False, its error (and error_type when Python made it), and the status, method and
    seconds of its fit when the fit ran; its estimates, rows and verdicts are None.
    Several rows make a table: ``pandas.DataFrame(rows)`` or ``csv.DictWriter``."""
    row = dict.fromkeys(ROW_FIELDS)
    row["file"] = entry["file"]
    row["ok"] = bool(entry["ok"])
    result = entry if row["ok"] else entry.get("result")
    if result is not None:
        row["status"] = result["status"]
        row["method"] = result["method"]
        row["seconds"] = result["seconds"]
    if row["ok"]:
        row["rows"] = rows_fitted(entry)
        for p in PARAMETERS:
            estimate = entry[p]
            row[p] = estimate["value"]
            row[f"{p}_stderr"] = estimate["stderr"]
            row[f"{p}_lo"], row[f"{p}_hi"] = estimate["ci95"]
            row[f"{p}_verdict"] = estimate["verdict"]
        row["warnings"] = "; ".join(entry.get("warnings", ()))
    else:
        row["error"] = entry["error"]
        row["error_type"] = entry.get("error_type")
    return row


def log_files(directory_or_glob):
    """The logs a directory (its *.csv files, without the truth.csv and import_report.csv
    that make-dataset and import-log write beside their logs) or a glob names, sorted: the
    files of ``identify --batch`` and ``--logs``, whose shards split this list. Raises
    ValueError when it names none."""
    return _core.log_files(os.fspath(directory_or_glob))


def read_results(path):
    """The per-log dicts of a JSON-lines file written by identify --batch or
    slideid.dask.write_results, one at a time (several shards' files may be concatenated).
    Raises ValueError naming the file and line for a line that is not such an object."""
    name = os.fspath(path)
    with open(name, encoding="utf-8") as lines:
        for number, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            try:
                entry = json.loads(line)
            except json.JSONDecodeError as error:
                raise ValueError(f"{name}:{number}: not JSON ({error.msg}, column "
                                 f"{error.colno})") from None
            if not isinstance(entry, dict) or "file" not in entry or "ok" not in entry:
                raise ValueError(f"{name}:{number}: not a result line (an object with "
                                 "\"file\" and \"ok\")")
            yield entry
