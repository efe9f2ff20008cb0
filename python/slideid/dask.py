"""Identification of many logs on a Dask cluster (Dask distributed): each log fitted on its
own by slideid.identify_file on the cluster's workers, the results gathered as they
complete, into a table or written to a file line by line.

    import distributed, slideid.dask
    client = distributed.Client("tcp://scheduler:8786")     # or None: a local cluster
    table = slideid.dask.identify_many(slideid.log_files("pushes/"), client)
    summary = slideid.dask.write_results("pushes/", "results.jsonl", client, segment=20)

From a shell: ``python3 -m slideid.dask --batch DIR|GLOB --out results.jsonl
[--scheduler ADDRESS | --scheduler-file FILE | --local-workers N] [identify's options]``
(docs/scale-out.md).

Files are sent in tasks of several logs (a short log fits in milliseconds, less than a
task's round trip through the scheduler), and only a few tasks per worker thread are out
at once, refilled as they complete: memory stays bounded however many logs there are, on
the client, the scheduler and the workers. Every worker must import the same slideid
(built for its interpreter) and read the log files at the same paths (a shared file
system). Importing this module needs python3-distributed; ``import slideid`` does not.
"""

import argparse
import contextlib
import csv
import itertools
import json
import os
import re
import signal
import sys
import time
import warnings

import distributed

from . import _core
from ._identify import identify_file
from ._journal import JsonLines, read_done, write_atomically
from ._results import ROW_FIELDS, log_files, result_row, rows_fitted

#: The most logs in one task by default: tasks of well under a minute even for long logs,
#: and progress that moves.
MAX_BATCH_SIZE = 50
#: Tasks per worker thread by default, at least: enough for the last tasks to balance.
TASKS_PER_THREAD = 8
#: Tasks out at once per worker thread: one running, one waiting to start.
PENDING_PER_THREAD = 2
#: Tasks out at once at least (while workers join, a cluster may have none).
MIN_PENDING = 4


def _paths(paths):
    if isinstance(paths, (str, os.PathLike)):
        return log_files(paths)
    return [os.fspath(path) for path in paths]


def _identify_batch(paths, options):
    """A task, on a worker: identify_file on each of a few logs. Options were checked
    before the tasks went out; anything else a file raises is that file's error."""
    entries = []
    for path in paths:
        try:
            entries.append(identify_file(path, **options))
        except Exception as error:  # noqa: BLE001: one file's failure, never the batch's
            entries.append({"file": path, "ok": False, "error": f"{path}: {error}",
                            "error_type": type(error).__name__})
    return entries


def _task_failed(paths, error):
    """The entries of a task that failed as a whole (its worker died, it was cancelled)."""
    why = f"the task that fitted it failed ({type(error).__name__}: {error})"
    return [{"file": path, "ok": False, "error": f"{path}: {why}",
             "error_type": type(error).__name__} for path in paths]


def _threads(client):
    return sum(client.nthreads().values())


def default_batch_size(logs, threads):
    """Logs per task: about TASKS_PER_THREAD tasks per worker thread, at most
    MAX_BATCH_SIZE logs each, at least one."""
    per_task = -(-logs // (TASKS_PER_THREAD * max(threads, 1)))  # ceiling division
    return max(1, min(MAX_BATCH_SIZE, per_task))


@contextlib.contextmanager
def local_client(workers=None):
    """A Dask client of a cluster of `workers` worker processes (one thread each; default:
    one per core) on this machine, on the loopback interface, without a dashboard; closed
    on exit."""
    workers = workers or os.cpu_count() or 1
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield client


@contextlib.contextmanager
def _client_or_local(client):
    """The client given, else the current one, else that of a local cluster (local_client)
    for as long as the context lasts."""
    if client is None:
        try:
            client = distributed.get_client()
        except ValueError:  # none
            client = None
    if client is not None:
        yield client
        return
    with local_client() as local:
        yield local


def _tasks(paths, client, batch_size, max_pending, options):
    """(index in paths of its first log, its entries) of each task as it completes; the
    tasks out at once are kept to max_pending (default: PENDING_PER_THREAD per worker
    thread, at least MIN_PENDING), refilled as they complete."""
    def limit():
        return max_pending or max(MIN_PENDING, PENDING_PER_THREAD * _threads(client))

    batches = ((start, paths[start:start + batch_size])
               for start in range(0, len(paths), batch_size))
    first = list(itertools.islice(batches, limit()))
    futures = client.map(_identify_batch, [batch for _, batch in first], options=options,
                         pure=False)
    out = {future.key: work for future, work in zip(futures, first)}
    pending = distributed.as_completed(futures)
    try:
        for future in pending:
            start, batch = out.pop(future.key)
            try:
                entries = future.result()
            except Exception as error:  # noqa: BLE001: the worker died, or the task was lost
                entries = _task_failed(batch, error)
            future.release()
            for work in itertools.islice(batches, max(0, limit() - len(out))):
                more = client.submit(_identify_batch, work[1], options=options, pure=False)
                out[more.key] = work
                pending.add(more)
            yield start, entries
    finally:
        if out:  # the caller stopped early: take back what is still out
            client.cancel(list(pending.futures))


def _check(paths, batch_size, max_pending, options):
    """The paths, once the arguments are checked (options as identify checks them)."""
    _core.check_identify_options(**options)
    for name, value in (("batch_size", batch_size), ("max_pending", max_pending)):
        if value is not None and (not isinstance(value, int) or value < 1):
            raise ValueError(f"{name} must be a whole number of at least 1, not {value!r}")
    return _paths(paths)


def _run(paths, client, batch_size, max_pending, options):
    """_tasks on the client given, the current one or a local cluster."""
    if not paths:
        return
    with _client_or_local(client) as active:
        size = batch_size or default_batch_size(len(paths), _threads(active))
        yield from _tasks(paths, active, size, max_pending, options)


def map_identify(paths, client=None, *, batch_size=None, max_pending=None, **options):
    """identify_file(path, **options) of every log, on the Dask cluster of `client`,
    yielded as each task completes (not in the order of `paths`).

    paths: a list of log files, or a directory or glob (log_files). client: a
    distributed.Client; None takes the current one, or else starts a cluster of worker
    processes on this machine (local_client) for as long as the iteration runs.
    batch_size: logs per task (default_batch_size). max_pending: tasks out at once
    (default: PENDING_PER_THREAD per worker thread of the cluster, at least MIN_PENDING).
    options: identify's (slideid.identify), checked before any task goes out: TypeError
    for an unknown one, slideid.OptionError for a bad value. A log that fails gives its
    dict with its error ({"ok": False, "error", "error_type"}), as identify_file does; a
    task that fails as a whole (its worker died) gives such a dict for each of its logs.
    """
    paths = _check(paths, batch_size, max_pending, options)
    for _, entries in _run(paths, client, batch_size, max_pending, options):
        yield from entries


class _Counter:
    """Counts logs as their tasks complete, and reports to progress(done, failed, total,
    seconds) after each task."""

    def __init__(self, total, progress):
        self.total, self.progress = total, progress
        self.ok = self.failed = self.rows = 0
        self.start = time.monotonic()

    def add(self, entries):
        for entry in entries:
            if entry["ok"]:
                self.ok += 1
                self.rows += rows_fitted(entry)
            else:
                self.failed += 1
        if self.progress is not None:
            self.progress(self.ok + self.failed, self.failed, self.total, self.seconds())

    def seconds(self):
        return time.monotonic() - self.start

    def summary(self):
        return {"total": self.total, "ok": self.ok, "failed": self.failed, "rows": self.rows,
                "seconds": self.seconds()}


def _resumed(paths, out, resume):
    """(the logs still to fit, {file: entry} of those `out` already holds) for a batch
    written to `out` (JSON lines) and resumed or not."""
    if resume and out is None:
        raise ValueError("resume=True needs out, the JSON-lines file of the earlier run")
    if resume and output_kind(out) != "jsonl":
        raise ValueError(f"{os.fspath(out)}: a resumable results file is JSON lines, not CSV")
    if not resume:
        return paths, {}
    with _naming(out):
        done = read_done(out, paths)
    return [path for path in paths if path not in done], done


def identify_many(paths, client=None, *, batch_size=None, max_pending=None, progress=None,
                  out=None, resume=False, **options):
    """The table of many logs identified on a Dask cluster: one row per log, in the order
    of `paths`, each a dict of ROW_FIELDS (slideid.result_row: file, ok, status, method,
    rows, seconds, each parameter's estimate, stderr, 95% interval and verdict, warnings,
    error, error_type); ``pandas.DataFrame(rows)`` makes it a data frame. Arguments as
    map_identify's; progress, when given, is called as progress(done, failed, total,
    seconds) after each task. Holds every row: for more logs than that, write_results.

    out: a JSON-lines file each log's dict is also appended to as its task completes (as
    identify --batch writes it: whole lines, fsync'ed at least once a second), so that an
    interrupted run can be resumed. resume: keep what `out` holds (a log known by its path
    and SHA-256: a changed log is fitted again; a torn last line is dropped with a
    SlideidWarning), fit only the other logs, and return the whole table. A worker that
    dies has its tasks retried on the others by the scheduler."""
    paths = _check(paths, batch_size, max_pending, options)
    if out is not None and output_kind(out) != "jsonl":
        raise ValueError(f"{os.fspath(out)}: out is a JSON-lines file, not CSV")
    todo, done = _resumed(paths, out, resume)
    rows = {path: result_row(entry) for path, entry in done.items()}
    counter = _Counter(len(todo), progress)
    with contextlib.ExitStack() as stack:
        journal = None
        if out is not None:
            with _naming(out):
                journal = stack.enter_context(JsonLines(out, truncate=not resume))
        for start, entries in _run(todo, client, batch_size, max_pending, options):
            for offset, entry in enumerate(entries):
                rows[todo[start + offset]] = result_row(entry)
            if journal is not None:
                with _naming(out):
                    for entry in entries:
                        journal.append(entry)
            counter.add(entries)
    return [rows[path] for path in paths]


def output_kind(out):
    """"csv" for a path ending in .csv, else "jsonl" (JSON lines)."""
    return "csv" if os.fspath(out).lower().endswith(".csv") else "jsonl"


def write_results(paths, out, client=None, *, batch_size=None, max_pending=None,
                  progress=None, resume=False, **options):
    """Identifies many logs on a Dask cluster (as map_identify) and writes each log's result
    to `out` as its task completes, holding none: JSON lines (each line the dict
    identify_file returns, as identify --batch writes them, in the order of completion:
    one whole line per write, fsync'ed at least once a second) or, for a path ending in
    .csv, one result_row per line under a header of ROW_FIELDS (written to a temporary
    beside `out`, renamed into place at the end: complete or absent). Returns the summary
    {"total", "ok", "failed", "rows" (of the logs identified), "seconds", "skipped"}.
    progress as identify_many's. resume (JSON lines only): keep the logs `out` already
    holds, as identify_many's resume. Raises OSError if `out` cannot be written (before any
    task goes out, if it cannot be opened)."""
    paths = _check(paths, batch_size, max_pending, options)
    todo, done = _resumed(paths, out, resume)
    counter = _Counter(len(todo), progress)
    if output_kind(out) == "csv":
        def write_table(stream):
            table = csv.DictWriter(stream, fieldnames=ROW_FIELDS, lineterminator="\n")
            table.writeheader()
            for _, entries in _run(todo, client, batch_size, max_pending, options):
                with _naming(out):
                    table.writerows(result_row(entry) for entry in entries)
                counter.add(entries)
        write_atomically(out, write_table)
    else:
        with _naming(out):
            journal = JsonLines(out, truncate=not resume)
        with journal:
            for _, entries in _run(todo, client, batch_size, max_pending, options):
                with _naming(out):
                    for entry in entries:
                        journal.append(entry)
                counter.add(entries)
    summary = counter.summary()
    summary["skipped"] = len(paths) - len(todo)
    for entry in (done[path] for path in paths if path in done):
        summary["ok" if entry["ok"] else "failed"] += 1
    summary["total"] = len(paths)
    return summary


@contextlib.contextmanager
def _naming(out):
    """Errors of writing `out` as OSErrors whose filename is `out`."""
    try:
        yield
    except OSError as error:
        if getattr(error, "filename", None) is not None:
            raise
        raise OSError(error.errno, error.strerror or str(error), os.fspath(out)) from error


# ---- the command line: python3 -m slideid.dask ----

USAGE = """python3 -m slideid.dask --batch DIR|GLOB --out RESULTS.jsonl|RESULTS.csv
                         [--scheduler ADDRESS | --scheduler-file FILE | --local-workers N]
                         [--batch-size N]
                         [identify's options: --segment 20 --fit-force-bias ...]"""

DESCRIPTION = """Identifies every log of a directory (or a quoted glob) on its own, on a Dask
cluster, and writes one result per log to --out as it completes: JSON lines as identify
--batch writes them, or a CSV table for a path ending in .csv. A log that fails gives a line
with its error and does not stop the others. Options not listed below are identify's
(identify --help), given to every fit. Progress goes to a terminal only.
--resume keeps the logs a JSON-lines --out already holds (known by path and SHA-256) and
fits the others. Exit codes: 0 ok; 1 a log failed (its line says why), or the cluster could
not be reached or was lost; 2 usage; 4 the output cannot be written; 130 / 143 stopped by
SIGINT / SIGTERM (every line written is whole: --resume finishes the batch)."""


class _Stopped(Exception):
    """SIGTERM, raised between two lines as KeyboardInterrupt is for SIGINT."""


def _on_sigterm(number, _frame):
    raise _Stopped(number)


def _identify_keywords(tokens):
    """identify's options on the command line (--name VALUE, --name=VALUE, --switch) as the
    keyword arguments of identify: --fit-force-bias gives fit_force_bias=True."""
    keywords = {}
    k = 0
    while k < len(tokens):
        token = tokens[k]
        if not token.startswith("--") or token == "--":
            raise argparse.ArgumentTypeError(f"unexpected argument '{token}'")
        name, has_value, value = token[2:].partition("=")
        if not has_value:
            follows = k + 1 < len(tokens) and not tokens[k + 1].startswith("--")
            value = tokens[k + 1] if follows else True
            k += follows
        key = name.replace("-", "_")
        keywords[key] = [*keywords[key], value] if key in keywords else value
        k += 1
    return keywords


def _print_warning(message, *_):
    """A warning (of a resume: a line dropped) as one line of the command's stderr."""
    sys.stderr.write(f"slideid.dask: warning: {message}\n")


def _print_progress(done, failed, total, seconds):
    rate = done / max(seconds, 1e-9)
    left = (total - done) / max(rate, 1e-9)
    sys.stderr.write(f"\rslideid.dask: {done}/{total} logs, {failed} failed, {rate:.1f} logs/s, "
                     f"{left:.0f} s left   ")
    sys.stderr.flush()


def main(argv=None):
    """The command line (USAGE); returns the exit code."""
    parser = argparse.ArgumentParser(prog="python3 -m slideid.dask", usage=USAGE,
                                     description=DESCRIPTION, allow_abbrev=False,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--batch", required=True, metavar="DIR|GLOB",
                        help="the logs: a directory's *.csv (without truth.csv and "
                             "import_report.csv) or a quoted glob")
    parser.add_argument("--out", required=True, metavar="RESULTS",
                        help="where the results go: JSON lines, or CSV if it ends in .csv")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--scheduler-file", metavar="FILE",
                       help="the file a running scheduler wrote its address to (dask "
                            "scheduler --scheduler-file FILE)")
    where.add_argument("--local-workers", type=int, metavar="N",
                       help="start N worker processes on this machine (default: one per "
                            "core), loopback only")
    parser.add_argument("--batch-size", type=int, metavar="N",
                        help=f"logs per task (default: about {TASKS_PER_THREAD} tasks per "
                             f"worker thread, at most {MAX_BATCH_SIZE} logs each)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the logs a JSON-lines --out already holds (same path and "
                             "SHA-256) and fit only the others")
    parser.add_argument("--version", action="version", version=f"slideid {_core.__version__}")
    args, rest = parser.parse_known_args(argv)
    try:
        options = _identify_keywords(rest)
        _core.check_identify_options(**options)
        if args.batch_size is not None and args.batch_size < 1:
            raise ValueError(f"--batch-size must be at least 1, not {args.batch_size}")
        if args.local_workers is not None and args.local_workers < 1:
            raise ValueError(f"--local-workers must be at least 1, not {args.local_workers}")
        paths = log_files(args.batch)
    except (argparse.ArgumentTypeError, TypeError, ValueError) as error:
        parser.print_usage(sys.stderr)
        message = re.sub(r"identify\(\) got an unexpected keyword argument '(\w+)'",
                         lambda m: f"unknown option '--{m[1].replace('_', '-')}'",
                         getattr(error, "cli_message", str(error)))  # a command line's words
        sys.stderr.write(f"slideid.dask: usage: {message}\n")
        return 2
    progress = _print_progress if sys.stderr.isatty() else None
    with contextlib.ExitStack() as stack:
        try:
            if args.scheduler:
                client = stack.enter_context(distributed.Client(args.scheduler))
            elif args.scheduler_file:
                client = stack.enter_context(
                    distributed.Client(scheduler_file=args.scheduler_file))
            else:
                client = stack.enter_context(local_client(args.local_workers))
        except (OSError, TimeoutError) as error:
            where = args.scheduler or args.scheduler_file or "a local cluster"
            sys.stderr.write(f"slideid.dask: error: cannot reach {where}: {error}\n")
            return 1
        try:
            previous = signal.signal(signal.SIGTERM, _on_sigterm)
            try:
                with warnings.catch_warnings():
                    warnings.showwarning = _print_warning
                    summary = write_results(paths, args.out, client,
                                            batch_size=args.batch_size, progress=progress,
                                            resume=args.resume, **options)
            finally:
                signal.signal(signal.SIGTERM, previous)
        except (KeyboardInterrupt, _Stopped) as stop:
            name = "SIGTERM" if isinstance(stop, _Stopped) else "SIGINT"
            sys.stderr.write(f"\nslideid.dask: stopped by {name}: every line in {args.out} is "
                             "whole; run again with --resume to finish\n")
            return 128 + (signal.SIGTERM if isinstance(stop, _Stopped) else signal.SIGINT)
        except OSError as error:
            if progress:
                sys.stderr.write("\n")
            if getattr(error, "filename", None) == os.fspath(args.out):
                sys.stderr.write(f"slideid.dask: error: {args.out}: cannot write the results "
                                 f"({error.strerror or error})\n")
                return 4
            sys.stderr.write(f"slideid.dask: error: lost the cluster: {error}\n")
            return 1
    if progress:
        sys.stderr.write("\n")
    if summary["failed"]:
        sys.stderr.write(f"slideid.dask: {summary['failed']} of {summary['total']} logs failed "
                         f"(their lines in {args.out} say why)\n")
        return 1
    return 0


if __name__ == "__main__":
    # Run as a script (python3 -m slideid.dask), this file is __main__; the tasks must name
    # the functions of slideid.dask, which the workers import, so call main from there.
    from slideid.dask import main as _main
    sys.exit(_main())
