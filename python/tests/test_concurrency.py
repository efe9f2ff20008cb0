"""Thread and process safety (issue 22): 8 Python threads and 4 processes fitting the same
50 logs at once give results identical, bit for bit, to one thread's. identify releases the
GIL while it fits, so the threads' fits really run at once. (tests/thread_safety_test.cc
runs the same under ThreadSanitizer: scripts/tsan.sh.)"""

import concurrent.futures
import json
import multiprocessing

import slideid
from conftest import without_times

#: The equation-error method (Ceres, the step equations, the noise-bias correction's
#: replicates) keeps 650 fits to seconds; the trajectory fit runs threaded in
#: tests/tsan/thread_safety_test.cc, under ThreadSanitizer.
OPTIONS = {"method": "equation-error"}


def fitted(paths):
    """Each log's identify_file dict as exact text (every float in its shortest
    round-trip form), without the run times."""
    return [json.dumps(without_times(slideid.identify_file(path, **OPTIONS)), sort_keys=True)
            for path in paths]


def rotated(paths, k):
    """The logs in another order for each worker, so that different logs run side by side."""
    shift = (k * 7) % len(paths)
    return paths[shift:] + paths[:shift]


def test_eight_threads_and_four_processes_give_one_threads_results_bit_for_bit(fifty_logs):
    one = dict(zip(fifty_logs, fitted(fifty_logs)))
    assert sum('"ok": true' in text for text in one.values()) > 25  # most logs identified
    with concurrent.futures.ThreadPoolExecutor(8) as threads:
        runs = list(threads.map(lambda k: fitted(rotated(fifty_logs, k)), range(8)))
    context = multiprocessing.get_context("spawn")  # fresh interpreters
    with concurrent.futures.ProcessPoolExecutor(4, mp_context=context) as processes:
        runs += list(processes.map(fitted, [rotated(fifty_logs, k) for k in range(4)]))
    for k, results in enumerate(runs):
        got = dict(zip(rotated(fifty_logs, k % 8 if k < 8 else k - 8), results))
        for path in fifty_logs:
            assert got[path] == one[path], (k, path)
