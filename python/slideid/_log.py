"""Push logs in Python: reading, making from arrays, writing, simulating, datasets, imports."""

import os
import re
import warnings
from collections.abc import Mapping

import numpy as np

from . import _core
from ._errors import missing_files_named


class SlideidWarning(UserWarning):
    """A likely mistake in the input (absurd magnitudes, gaps in t) or a suspect estimate."""


#: The numeric columns of the log format (log-format.md), in file order.
COLUMNS = (
    "t", "x", "y", "theta", "vx", "vy", "wz", "fx", "fy", "fz",
    "px", "py", "pz", "tx", "ty", "tz", "ax", "ay", "pt", "po", "pr", "sigma",
)

#: The source named in messages about a log made from arrays.
ARRAYS_SOURCE = "arrays"


def _warn(messages, stacklevel=3):
    for message in messages:
        warnings.warn(message, SlideidWarning, stacklevel=stacklevel)


class Log:
    """A push log (log-format.md): its columns as read-only numpy arrays, and its metadata.

    ``log.t``, ``log.x``, ... are the columns as ``write_log`` writes them (``None`` for a
    column the log does not have): poses (theta unwrapped), velocities, the force, the push
    point, the moments (about the CM, besides r x f at the push point when there is one) and,
    for a noiseless simulated log, the simulator's step columns and ``log.mode``.
    ``log.mass`` [kg], ``log.inertia`` [kg m^2], ``log.com_height`` [m], ``log.gravity``
    [m/s^2], ``log.patch``, ``log.truth`` (the friction a simulated log was made with) and
    ``log.extra`` (further metadata) are its metadata. A Log is immutable: ``replace`` makes
    a changed copy. Logs pickle (as their exact text), so they can be sent to other processes.
    """

    def __init__(self, handle, simulation=None):
        self._handle = handle
        self._columns = None
        self._metadata = None
        #: For a simulated log, the simulation's summary (steps, rest_time [s], ecp_margin
        #: [m], ...); None otherwise.
        self.simulation = simulation

    @property
    def columns(self):
        """Name -> read-only numpy array (``mode``: a tuple of str), in file order."""
        if self._columns is None:
            columns = self._handle.columns()
            for name, values in columns.items():
                if name == "mode":
                    columns[name] = tuple(values)
                else:
                    values.flags.writeable = False
            self._columns = columns
        return dict(self._columns)

    @property
    def metadata(self):
        """source, mass, inertia, com_height, gravity, patch, tip_radius, truth and extra, as
        a dict."""
        if self._metadata is None:
            self._metadata = self._handle.metadata()
        return dict(self._metadata)

    def __getattr__(self, name):
        if name in COLUMNS or name == "mode":
            return self.columns.get(name)
        if name in ("source", "mass", "inertia", "com_height", "gravity", "patch", "truth",
                    "extra"):
            return self.metadata[name]
        raise AttributeError(f"'Log' object has no attribute '{name}'")

    @property
    def rows(self):
        """The number of rows."""
        return self._handle.rows

    def __len__(self):
        return self._handle.rows

    @property
    def warnings(self):
        """What the reader found likely to be a mistake, each naming the file and line."""
        return list(self._handle.warnings)

    @property
    def notes(self):
        """Plain facts the reader noticed (velocities from poses, unknown columns, ...)."""
        return list(self._handle.notes)

    def to_csv(self):
        """The log as the text of a log file (what write_log writes)."""
        return self._handle.text()

    def replace(self, **changes):
        """A copy with some columns or metadata changed (the arguments of make_log)."""
        arguments = {name: values for name, values in self.columns.items()}
        metadata = self.metadata
        arguments.update({key: metadata[key] for key in
                          ("mass", "inertia", "com_height", "gravity", "patch", "truth",
                           "extra", "source")})
        arguments.update(changes)
        return make_log(**arguments)

    def __repr__(self):
        names = ",".join(self.columns)
        return f"<slideid.Log {self.source or '(no source)'}: {self.rows} rows, columns {names}>"

    def __getstate__(self):
        return {"handle": self._handle, "simulation": self.simulation}

    def __setstate__(self, state):
        self.__init__(state["handle"], state["simulation"])


def read_log(path, *, mass=None, inertia=None, com_height=None, gravity=None,
             max_gap_ratio=None, regular_times=None, missing_as_gaps=None):
    """Reads a push log (CSV, log-format.md). The keywords override its metadata, as
    identify's options do; max_gap_ratio is identify's --max-gap-ratio (10 by default, 0: no
    limit); regular_times=True is --regular-times (each run's rows on a regular grid, for a
    logger that stamps rows on arrival, which the reader warns of); missing_as_gaps=True is
    --missing-as-gaps (a row with an empty or NaN cell dropped, the next one starting a run).
    Raises slideid.InputError (a ValueError) naming the file, line and column of what
    is wrong; slideid.MissingFileError (also a FileNotFoundError) for a file that does not
    exist."""
    options = {"mass": mass, "inertia": inertia, "com_height": com_height,
               "gravity": gravity, "max_gap_ratio": max_gap_ratio,
               "regular_times": regular_times, "missing_as_gaps": missing_as_gaps}
    with missing_files_named([os.fspath(path)]):
        handle = _core.read_log(os.fspath(path), **{k: v for k, v in options.items()
                                                      if v is not None})
    _warn(handle.warnings)
    return Log(handle)


def _number_text(value):
    return repr(float(value))


def _metadata_entries(mass, inertia, com_height, gravity, patch, truth, extra):
    entries = [("mass", _number_text(mass)), ("inertia", _number_text(inertia)),
               ("com_height", _number_text(com_height))]
    if gravity is not None:
        entries.append(("gravity", _number_text(gravity)))
    if patch is not None:
        entries.append(("patch", str(patch)))
    if truth is not None:
        missing = [key for key in ("mu", "e_t", "e_o", "e_r") if key not in truth]
        if missing:
            raise ValueError(f"make_log: truth needs mu, e_t, e_o and e_r (missing "
                             f"{', '.join(missing)})")
        entries += [(key, _number_text(truth[key])) for key in ("mu", "e_t", "e_o", "e_r")]
    for key, value in (extra or {}).items():
        entries.append((str(key), str(value)))
    return entries


_LOCATION = re.compile(r"^(?P<source>.*?):(?P<line>\d+): (?P<what>.*)$", re.DOTALL)
_LINE = re.compile(r"\bline (\d+)")


def _rows_not_lines(message, source, first_row_line):
    """The reader's message about a log made from arrays, with rows (from 0) for lines."""
    match = _LOCATION.match(message)
    if not match or match["source"] != source:
        return message
    line = int(match["line"])
    what = _LINE.sub(lambda m: (f"row {int(m[1]) - first_row_line}"
                                if int(m[1]) >= first_row_line else m[0]), match["what"])
    if line >= first_row_line:
        return f"{source} row {line - first_row_line}: {what}"
    if line == first_row_line - 1:
        return f"{source}: {what}"
    return f"{source}: {'' if line == 0 else 'metadata: '}{what}"


def make_log(*, t, mass, inertia, com_height, x=None, y=None, theta=None, vx=None, vy=None,
             wz=None, fx=None, fy=None, fz=None, px=None, py=None, pz=None, tx=None, ty=None,
             tz=None, ax=None, ay=None, pt=None, po=None, pr=None, sigma=None, mode=None,
             gravity=None, patch=None, truth=None, extra=None, source=ARRAYS_SOURCE,
             max_gap_ratio=None):
    """A push log from arrays (one value per row; SI units, as in log-format.md) and metadata.

    It is read exactly as the file these columns and metadata make would be: the same
    checks (t strictly increasing, finite numbers, complete column groups, ...), velocities
    from the poses when only poses are given, moments r x f added at push points. A bad
    value raises ValueError naming the row (from 0) and the column. truth is
    ``{"mu": ..., "e_t": ..., "e_o": ..., "e_r": ...}`` (simulated logs); extra is further
    ``key: value`` metadata.
    """
    given = {"t": t, "x": x, "y": y, "theta": theta, "vx": vx, "vy": vy, "wz": wz, "fx": fx,
             "fy": fy, "fz": fz, "px": px, "py": py, "pz": pz, "tx": tx, "ty": ty, "tz": tz,
             "ax": ax, "ay": ay, "pt": pt, "po": po, "pr": pr, "sigma": sigma}
    columns = {}
    for name in COLUMNS:
        if given[name] is None:
            continue
        try:
            columns[name] = np.asarray(given[name], dtype=np.float64)
        except (TypeError, ValueError) as error:
            raise ValueError(f"make_log: column '{name}': {error}") from None
    metadata = _metadata_entries(mass, inertia, com_height, gravity, patch, truth, extra)
    keywords = {} if max_gap_ratio is None else {"max_gap_ratio": max_gap_ratio}
    try:
        handle = _core.make_log(columns, None if mode is None else [str(m) for m in mode],
                                metadata, str(source), **keywords)
    except ValueError as error:
        raise ValueError(_rows_not_lines(str(error), str(source), len(metadata) + 2)) from None
    _warn(_rows_not_lines(w, str(source), len(metadata) + 2) for w in handle.warnings)
    return Log(handle)


def write_log(log, path):
    """Writes a log as a CSV file (log-format.md), at full precision: read_log reads it back
    bit for bit. A failed write raises OSError and leaves no complete-looking file."""
    _core.write_log(log._handle, os.fspath(path))


def _ini_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, (list, tuple, np.ndarray)):
        return " ".join(_ini_value(v) for v in value)
    return str(value)


def scene_text(sections):
    """The INI text of a scene given as ``{"slider": {"mass": 0.8, ...}, "friction": {...}}``
    (sections and keys of README "Scene files" and datasets/README.md)."""
    lines = []
    for section, keys in sections.items():
        if not isinstance(keys, Mapping):
            raise ValueError(f"scene: section [{section}] must be a dict of keys")
        lines.append(f"[{section}]")
        lines += [f"{key} = {_ini_value(value)}" for key, value in keys.items()]
    return "\n".join(lines) + "\n"


def simulate(scene, *, dt=None, duration=None, **log_options):
    """Simulates a scene (a scene file's path, or a dict of its sections) and returns the
    log a sensor would record, as ``simulate --out`` writes it. dt and duration [s] override
    the scene's; log_options are simulate's log options (log_every, write="poses",
    push_columns, step_info, wrap_theta, noise_pose [m], noise_angle [rad], ..., seed).
    Raises NumericalError when a step does not converge or the slider would tip (the
    message names the time and the ECP)."""
    if isinstance(scene, Mapping):
        text, is_path, source = scene_text(scene), False, "scene"
    else:
        text, is_path, source = os.fspath(scene), True, ""
    handle, summary = _core.simulate(text, is_path, source, dt, duration, **log_options)
    return Log(handle, simulation=summary)


def _range_text(value):
    if isinstance(value, tuple) and len(value) == 2:
        return f"{_ini_value(value[0])}:{_ini_value(value[1])}"
    return value


def make_dataset(count=10, seed=1, out=None, **options):
    """A synthetic dataset, as make-dataset makes it: count sliders and friction parameters
    drawn from ranges (e.g. ``mass_range=(0.3, 1.5)``; the options of make-dataset), each
    pushed by a random push program and logged with noise. Deterministic by seed.

    With out (a directory) it writes out/log_0000.csv, ... and out/truth.csv, and each entry
    has the "path" of its log; without, each entry has its "log" (a Log). Every entry also
    has the truth.csv fields: file, mass, inertia, com_height, mu, e_t, e_o, e_r, e_t_mu,
    e_o_over_e_t, e_r_over_e_t, noise, patch, rows, redraw_reasons."""
    keywords = {key: _range_text(value) for key, value in options.items()}
    keywords.update(count=count, seed=seed)
    if out is not None:
        keywords["out"] = os.fspath(out)
    entries = _core.make_dataset(**keywords)
    for entry in entries:
        if "log" in entry:
            entry["log"] = Log(entry["log"])
    return entries


def import_log(format, files, out_dir, **options):
    """Imports real recordings, as import-log does: format "mit-push" (MIT push dataset JSON
    files into push logs; give objects="table.csv" or mass, inertia, com_height and patch),
    "mit-push-h5" (the same dataset's .h5 files), "streams" (one CSV per stream: files=[] and
    pose="pose.csv:t=stamp,x=px,...", tip=..., force=..., as import-log's --pose, --tip and
    --force), "rosbag" or "mcap" (ROS 1 bags, ROS 2 MCAP files: the same, with object_topic, tip_topic,
    force_topic and, for TF topics, object_frame and tip_frame) or "zhou-tripod" (tripod logs
    into wrench-twist pairs). Each file is imported into
    out_dir or rejected with its reason, on its own. Returns the summary: files, accepted,
    accepted_lines, rejections (one line per rejected file) and report_path."""
    if isinstance(files, (str, os.PathLike)):
        files = [files]
    return _core.import_log(str(format), [os.fspath(f) for f in files], os.fspath(out_dir),
                            **options)
