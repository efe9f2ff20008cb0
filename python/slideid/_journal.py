"""A batch's results file as identify --batch keeps it (pipeline/batch.h,
docs/robustness.md): JSON lines appended one whole line per write, fsync'ed at most
FSYNC_INTERVAL_S apart; resumed, the lines of logs unchanged since (same path and SHA-256)
are kept and those logs skipped, and a torn last line is dropped with a warning. Any other
file is written whole to a temporary beside it and renamed into place."""

import contextlib
import json
import os
import tempfile
import time
import warnings

from ._identify import file_sha256
from ._log import SlideidWarning

#: The most seconds between two fsyncs of a results file (and one at the end).
FSYNC_INTERVAL_S = 1.0


class JsonLines:
    """An append-only file of lines, each written by one os.write; a failed write is cut
    back to the last whole line. Raises OSError naming the file."""

    def __init__(self, path, truncate=False, fsync_interval_s=FSYNC_INTERVAL_S):
        self.path = os.fspath(path)
        self.interval = fsync_interval_s
        flags = os.O_WRONLY | os.O_CREAT | os.O_APPEND | (os.O_TRUNC if truncate else 0)
        self.fd = os.open(self.path, flags, 0o666)
        self.synced = time.monotonic()
        self.unsynced = False

    def append(self, entry):
        data = (json.dumps(entry, ensure_ascii=False) + "\n").encode("utf-8")
        size = os.fstat(self.fd).st_size
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(self.fd, view):]
        except OSError as error:
            with contextlib.suppress(OSError):
                os.ftruncate(self.fd, size)
            raise OSError(error.errno, error.strerror, self.path) from error
        self.unsynced = True
        if time.monotonic() - self.synced >= self.interval:
            self.sync()

    def sync(self):
        if self.unsynced:  # a line was appended since the last sync
            os.fsync(self.fd)
            self.unsynced = False
        self.synced = time.monotonic()

    def close(self):
        if self.fd >= 0:
            try:
                self.sync()
            finally:
                os.close(self.fd)
                self.fd = -1

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.close()


@contextlib.contextmanager
def _naming(path):
    """OSErrors of the file operations as OSErrors whose filename is `path`."""
    try:
        yield
    except OSError as error:
        if error.filename == path:
            raise
        raise OSError(error.errno, error.strerror or str(error), path) from error


def write_atomically(path, write, newline=""):
    """Writes text `path` through write(stream) to a temporary in its directory, fsync'ed,
    then renamed over it: complete or absent. Raises OSError naming the file when a file
    operation fails; what write() raises (writing to the stream included) propagates as it
    is, the temporary removed."""
    path = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(path))
    with _naming(path):
        fd, temp = tempfile.mkstemp(prefix=f".{name}.tmp-", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline=newline) as stream:
            write(stream)
            with _naming(path):
                stream.flush()
                os.fsync(stream.fileno())
        with _naming(path):
            os.chmod(temp, 0o666 & ~_umask())
            os.replace(temp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(temp)
        raise


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def read_done(path, paths):
    """The entries a results file already holds for a resumed batch over `paths`:
    {file: entry}. Dropped with a SlideidWarning naming the line (and the file rewritten
    without them, atomically): a torn last line, a line that is not a result, a second
    line for a file, and the line of one of `paths` whose SHA-256 differs from the file's
    now. Lines of other files are kept. A missing file holds nothing."""
    path = os.fspath(path)
    try:
        with open(path, "rb") as data:
            text = data.read()
    except FileNotFoundError:
        return {}
    batch = set(paths)
    kept, done, dropped = [], {}, False

    def drop(number, why):
        nonlocal dropped
        warnings.warn(f"{path}:{number}: {why}", SlideidWarning, stacklevel=3)
        dropped = True

    lines = text.split(b"\n")
    for number, raw in enumerate(lines, start=1):
        if number == len(lines):  # after the last line break
            if raw:
                drop(number, f"a torn last line ({len(raw)} bytes without a line break, "
                             "from an interrupted run) dropped")
            break
        try:
            entry = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError):
            entry = None
        if not isinstance(entry, dict) or not isinstance(entry.get("file"), str) \
                or not isinstance(entry.get("ok"), bool):
            drop(number, 'not a batch result (no JSON object with "file" and "ok"); dropped')
            continue
        file = entry["file"]
        if file in done:
            drop(number, f"a second line for {file}; dropped")
            continue
        if file in batch:
            digest = entry.get("sha256")
            if digest is None or digest != file_sha256(file):
                drop(number, f"{file} " + ("could not be read then" if digest is None
                                           else "has changed since (SHA-256)")
                     + ": its line dropped, the log is fitted again")
                continue
        done[file] = entry
        kept.append(raw.decode("utf-8"))
    if dropped:
        write_atomically(path, lambda stream: stream.writelines(line + "\n" for line in kept))
    return done
