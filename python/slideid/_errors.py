"""The module's errors beyond those of its compiled core (InputError, OptionError,
NumericalError): a missing file."""

import contextlib
import errno
import os

from . import _core


class MissingFileError(FileNotFoundError, _core.InputError):
    """A file that does not exist: a FileNotFoundError (errno ENOENT, filename set) and
    slideid's bad input (slideid.InputError, a ValueError). Its text is the tools' message."""

    def __init__(self, message, filename):
        super().__init__(errno.ENOENT, os.strerror(errno.ENOENT), filename)
        self.message = message

    def __str__(self):
        return self.message


@contextlib.contextmanager
def missing_files_named(paths):
    """Re-raises the core's bad-input error as MissingFileError when one of `paths` (str)
    does not exist: the reader's message, the error's type saying why."""
    try:
        yield
    except _core.InputError as error:
        for path in paths:
            if isinstance(path, str) and not os.path.exists(path):
                raise MissingFileError(str(error), path) from None
        raise
