"""Identification in Python: identify (logs in, a Result out) and identify_file (one file
in, one plain dict out: what a batch or a Dask map over many logs wants)."""

import copy
import hashlib
import json
import os
import warnings

from . import _core
from ._errors import missing_files_named
from ._log import Log, SlideidWarning

#: The identifiable parameters: a = e_t mu, b = e_o / e_t, c = e_r / e_t [m].
PARAMETERS = ("e_t_mu", "e_o_over_e_t", "e_r_over_e_t")


def _view(key, value):
    """A JSON value as attributes: the objects of the result become Records."""
    if key in PARAMETERS:
        return Record(value)
    if key == "logs":
        return [Record(entry) for entry in value]
    if key == "nuisance":
        return {name: [Record(entry) for entry in entries] for name, entries in value.items()}
    if key == "heterogeneity":
        return {name: Record(entry) for name, entry in value.items()}
    return copy.deepcopy(value)


class Record:
    """A JSON object of the identify result, read by attribute or by key (``est.value``,
    ``est["ci95"]``); nulls are None. ``to_dict()`` gives the JSON object itself."""

    def __init__(self, data):
        self._data = data

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return _view(name, self._data[name])
        except KeyError:
            raise AttributeError(f"no field '{name}' (fields: {', '.join(self._data)})") from None

    def __getitem__(self, key):
        return _view(key, self._data[key])

    def __contains__(self, key):
        return key in self._data

    def keys(self):
        return self._data.keys()

    def to_dict(self):
        """The JSON object, as json.loads reads what identify --json prints."""
        return copy.deepcopy(self._data)

    def __eq__(self, other):
        return isinstance(other, Record) and self._data == other._data

    def __repr__(self):
        return f"{type(self).__name__}({self._data!r})"


def _format_estimate(name, estimate):
    if estimate["value"] is None:
        return f"  {name:13s} not identifiable (held at {estimate['held_at']:.6g})"
    lo, hi = estimate["ci95"]
    return (f"  {name:13s} {estimate['value']:.6g} +- {estimate['stderr']:.2g}  "
            f"95% [{lo:.6g}, {hi:.6g}]  {estimate['verdict']}")


class Result(Record):
    """What identify returns: the fields of ``identify --json`` as attributes (e_t_mu,
    e_o_over_e_t, e_r_over_e_t, method, status, converged, message, steps_used, logs,
    nuisance, heterogeneity, ...), plus what the JSON leaves out: residuals (numpy arrays),
    truth (what simulated logs record, else None), warnings and notes.
    ``result.to_dict()`` equals ``json.loads`` of identify --json on the same logs and
    options (but for "seconds", the run time)."""

    def __init__(self, data, residuals=None, truth=None, warnings=(), notes=()):
        super().__init__(data)
        #: Per-step residuals: arrays log, row, t, the method's channels, used.
        self.residuals = residuals or {}
        #: The truth (e_t_mu, e_o_over_e_t, e_r_over_e_t) the logs record, or None.
        self.truth = truth
        self.warnings = list(warnings)
        self.notes = list(notes)

    @property
    def parameters(self):
        """Name -> Record of the three parameters, in the order a, b, c."""
        return {name: Record(self._data[name]) for name in PARAMETERS}

    def __repr__(self):
        lines = [f"<slideid.Result {self._data['method']}: {self._data['status']}"]
        lines += [_format_estimate(name, self._data[name]) for name in PARAMETERS]
        return "\n".join(lines) + ">"

    def __getstate__(self):
        return self.__dict__

    def __setstate__(self, state):
        self.__dict__.update(state)


def _inputs(logs):
    items = logs if isinstance(logs, (list, tuple)) else [logs]
    inputs = []
    for item in items:
        if isinstance(item, Log):
            inputs.append(item._handle)
        elif isinstance(item, (str, os.PathLike)):
            inputs.append(os.fspath(item))
        else:
            raise TypeError(f"identify() takes a Log, a path, or a list of them, not "
                            f"{type(item).__name__}")
    return inputs


def _raise_with(error_type, message, result):
    error = error_type(message)
    error.result = result
    raise error


def identify(logs, method="trajectory", *, strict=False, **options):
    """Identifies a, b and c from one push log or several (pooled), as the identify tool
    does. logs: a Log, a path, or a list of either (not mixed); with method="quasi-static",
    paths of wrench-twist pair files. options are identify's options: segment, substeps,
    loss, fit_force_bias, fit_delay ("shared" or "per-log"), max_delay, threads,
    max_iterations, skip_bad, max_gap_ratio, regular_times, missing_as_gaps, and mass, inertia, com_height, gravity, which
    override the logs' metadata; report=PATH also writes identify --report's HTML page there.

    Raises slideid.InputError (a ValueError) for bad input and for logs that determine no
    parameter (the message as identify's), slideid.MissingFileError (also a
    FileNotFoundError) for a file that does not exist, slideid.NumericalError when the fit did not converge, or with
    strict=True when an estimate is suspect (the error's .result holds the result).
    Suspect estimates and the readers' warnings are issued as SlideidWarning.
    """
    inputs = _inputs(logs)
    with missing_files_named(inputs):
        run = _core.identify(inputs, method=method, **options)
    data = json.loads(run["json"])
    result = Result(data, run["residuals"], run["truth"], run["warnings"], run["notes"])
    for message in run["fresh_warnings"]:  # read_log has issued those of its logs
        warnings.warn(message, SlideidWarning, stacklevel=2)
    what = run["what"]
    if run["too_little_excitation"]:
        _raise_with(ValueError, f"{what}: {data['message']}", result)
    if run["failure"]:
        _raise_with(_core.NumericalError, f"{what}: {run['failure']}", result)
    if run["suspects"]:
        message = f"{what}: {run['suspect_summary']}"
        if strict:
            _raise_with(_core.NumericalError, message, result)
        warnings.warn(message, SlideidWarning, stacklevel=2)
    return result


def file_sha256(path):
    """The SHA-256 of a file's bytes, as 64 hex digits (what identify --batch records as
    "sha256": a resumed batch knows a log by its path and this); None when it cannot be
    read."""
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as data:
            for block in iter(lambda: data.read(1 << 16), b""):
                digest.update(block)
    except OSError:
        return None
    return digest.hexdigest()


def identify_file(path, **options):
    """One log file to one plain dict, for maps over many logs (a loop, a process pool, a
    Dask cluster: slideid.dask): ``{"file": path, "sha256": ..., "ok": True,
    **identify(path, **options).to_dict(), "warnings": [...]}``, or, when the file cannot be
    identified, ``{"file": path, "ok": False, "error": message, "error_type": "ValueError" |
    "NumericalError" | "OSError"}`` (with "result", the result's dict, when the fit ran but
    failed). These are the lines of ``identify --batch`` (io/result_json.h, FormatBatchLine),
    which has no "error_type". It raises only for bad options (TypeError for an unknown
    one, slideid.OptionError for a bad value), which would fail every file.
    """
    name = os.fspath(path)
    head = {"file": name}
    digest = file_sha256(name)  # of what is about to be read
    if digest is not None:
        head["sha256"] = digest
    try:
        with warnings.catch_warnings(record=True):
            warnings.simplefilter("always")
            result = identify(name, **options)
    except _core.OptionError:
        raise
    except (ValueError, _core.NumericalError, OSError) as error:
        # The documented kinds: bad input (a missing file too) is "ValueError".
        kind = ("NumericalError" if isinstance(error, _core.NumericalError) else
                "ValueError" if isinstance(error, ValueError) else "OSError")
        entry = {**head, "ok": False, "error": str(error), "error_type": kind}
        if getattr(error, "result", None) is not None:
            entry["result"] = error.result.to_dict()
        return entry
    entry = {**head, "ok": True}
    entry.update(result.to_dict())
    entry["warnings"] = result.warnings
    return entry


def check(logs, *, method="trajectory", **options):
    """The check before fitting, as ``identify --check --json`` gives it: fits nothing, and
    says per log its rates, gaps, noise, force at rest and dead channels, its excitation
    (rotation range, push and slide directions, how far pushes pass from the CM, the share
    of the time sliding), which of e_t_mu, e_o_over_e_t, e_r_over_e_t (and mu_pusher) the
    trajectory fit could identify and how precisely (the fit's own rules on J^T J at its
    seed), cond(J^T J), the correlations, and what would help ("advice"). logs: a Log, a
    path, or a list of either (not mixed); options as identify's. Returns one dict for one
    log, a list of dicts for a list (docs/identify.md, "Check before fitting").

    Raises slideid.InputError for a log that cannot be read (slideid.MissingFileError, also
    a FileNotFoundError, for a missing file), slideid.OptionError for a bad option value or
    another method. The readers' warnings are issued as SlideidWarning.
    """
    inputs = _inputs(logs)
    with missing_files_named(inputs):
        run = _core.check(inputs, method=method, **options)
    for message in run["warnings"]:
        warnings.warn(message, SlideidWarning, stacklevel=2)
    results = [json.loads(line) for line in run["json"]]
    return results if isinstance(logs, (list, tuple)) else results[0]
