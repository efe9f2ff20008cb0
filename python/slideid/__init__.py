"""slideid: the friction of a sliding object, identified from pushing logs.

Python interface to the slideid libraries (docs/python.md). Arrays are numpy arrays;
results are plain Python objects whose ``to_dict()`` is exactly the JSON of
``identify --json``. Options are the command-line options of the tools, with ``_`` for ``-``
(``fit_force_bias=True`` is ``--fit-force-bias``), checked as the tools check them.

Errors: bad input raises slideid.InputError, a ValueError, with the tools' message (file,
line and column; a missing file raises its subclass slideid.MissingFileError, also a
FileNotFoundError; a bad option value raises slideid.OptionError, a ValueError naming the
keyword);
a fit or a simulation that does not converge raises slideid.NumericalError; a file that
cannot be written raises OSError. Warnings (absurd magnitudes, gaps in t, suspect
estimates) are issued as slideid.SlideidWarning.

    import slideid
    log = slideid.read_log("datasets/logs/default_push.csv")
    result = slideid.identify(log)
    print(result.e_t_mu.value, result.e_t_mu.ci95)

Many logs: log_files lists them as identify --batch does, identify_file gives one plain dict
per file, result_row a flat table row of it, read_results reads the JSON lines of identify
--batch; slideid.dask (import it, with python3-distributed) runs them on a Dask cluster.

What a friction predicts: predict replays a push with it (by the pusher's path or the force),
validate cross-validates over logs; both return the tools' JSON. Which push next:
advise_push ranks candidate pushes by what they are expected to teach (advise-push --json).
"""

import sys as _sys

try:
    import numpy as _numpy  # noqa: F401
    from ._core import InputError, NumericalError, OptionError, __version__
except ImportError as error:  # most likely another interpreter than the one it was built for
    raise ImportError(
        f"slideid did not load in {_sys.executable} ({error}). It is built for one interpreter, "
        "Debian's /usr/bin/python3 unless configured otherwise, which needs python3-numpy "
        "(docs/python.md)") from error
from ._errors import MissingFileError
from ._identify import Record, Result, check, identify, identify_file
from ._log import (
    Log,
    SlideidWarning,
    import_log,
    make_dataset,
    make_log,
    read_log,
    simulate,
    write_log,
)
from ._online import OnlineIdentifier
from ._predict import advise_push, predict, validate
from ._results import ROW_FIELDS, log_files, read_results, result_row

__all__ = [
    "InputError",
    "Log",
    "MissingFileError",
    "NumericalError",
    "OnlineIdentifier",
    "OptionError",
    "ROW_FIELDS",
    "Record",
    "Result",
    "SlideidWarning",
    "__version__",
    "advise_push",
    "check",
    "identify",
    "identify_file",
    "import_log",
    "log_files",
    "make_dataset",
    "make_log",
    "predict",
    "read_log",
    "read_results",
    "result_row",
    "simulate",
    "validate",
    "write_log",
]

# What the package imported for itself is not part of it (dir(slideid) lists the API).
del _numpy, _sys
