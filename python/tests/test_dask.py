"""slideid.dask: many logs identified on a Dask cluster of worker processes on this machine
(loopback only) give, log by log, what identify_file gives (but for "seconds", the run
time); a log that fails gives its row with its error."""

import csv
import json
import subprocess
import sys

import pytest

import slideid

distributed = pytest.importorskip("distributed")
import slideid.dask  # noqa: E402  (needs distributed)

from conftest import without_times  # noqa: E402

# Debian's tornado warns as distributed starts its event loop; nothing of ours.
pytestmark = pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")
SEGMENT = 12  # not the default (20 for these logs): it must reach the workers


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as dask_client:
        yield dask_client


def expected(path):
    """identify_file's dict, without its times."""
    return without_times(slideid.identify_file(path, segment=SEGMENT))


def expected_row(path):
    """The table row of identify_file's dict, without its time."""
    return row_without_time(slideid.result_row(slideid.identify_file(path, segment=SEGMENT)))


def row_without_time(row):
    return {k: v for k, v in row.items() if k != "seconds"}


def test_the_table_equals_identify_file_log_by_log_and_a_bad_log_gives_its_error(client,
                                                                                  batch_logs):
    _, paths, bad, line = batch_logs
    seen = []
    rows = slideid.dask.identify_many(paths, client, batch_size=2, max_pending=1,
                                      progress=lambda *p: seen.append(p), segment=SEGMENT)
    assert [row["file"] for row in rows] == paths  # in the order given
    for path, row in zip(paths, rows):
        assert row_without_time(row) == expected_row(path)
        assert list(row) == list(slideid.ROW_FIELDS)
    failed = rows[paths.index(bad)]
    assert failed["ok"] is False and failed["error_type"] == "ValueError"
    assert f"{bad}:{line}" in failed["error"] and "'x'" in failed["error"], failed["error"]
    assert failed["e_t_mu"] is None and failed["rows"] is None
    good = [row for row in rows if row["ok"]]
    assert len(good) == 5
    assert all(row["e_t_mu_lo"] <= row["e_t_mu"] <= row["e_t_mu_hi"] for row in good)
    assert all(60 <= row["rows"] <= 300 for row in good)
    # Three tasks of two batch_logs, one out at a time: progress after each.
    assert [p[0] for p in seen] == [2, 4, 6] and seen[-1][1:3] == (1, 6)


def test_the_map_yields_identify_file_dicts_as_tasks_complete(client, batch_logs):
    _, paths, _, _ = batch_logs
    entries = list(slideid.dask.map_identify(paths, client, segment=SEGMENT))
    assert sorted(entry["file"] for entry in entries) == paths
    for entry in entries:
        assert without_times(entry) == expected(entry["file"])
        json.dumps(entry)
    # The option reached the workers: without it, the fits differ.
    default = {e["file"]: e for e in slideid.dask.map_identify(paths, client)}
    assert all(default[e["file"]]["steps_used"] != e["steps_used"] for e in entries if e["ok"])


def test_results_written_as_json_lines_or_csv_equal_identify_file(client, batch_logs, tmp_path):
    _, paths, bad, _ = batch_logs
    out = tmp_path / "results.jsonl"
    summary = slideid.dask.write_results(paths, out, client, batch_size=4, segment=SEGMENT)
    entries = list(slideid.read_results(out))
    assert sorted(entry["file"] for entry in entries) == paths
    for entry in entries:
        assert without_times(entry) == expected(entry["file"])
    rows = [slideid.result_row(entry) for entry in entries]
    assert summary["total"] == 6 and summary["ok"] == 5 and summary["failed"] == 1
    assert summary["rows"] == sum(row["rows"] for row in rows if row["ok"])

    table = tmp_path / "results.csv"
    slideid.dask.write_results(paths, table, client, segment=SEGMENT)
    with open(table, newline="") as stream:
        read = list(csv.DictReader(stream))
    assert tuple(read[0]) == slideid.ROW_FIELDS
    by_file = {row["file"]: row for row in read}
    assert sorted(by_file) == paths
    for path in paths:
        for key, value in expected_row(path).items():
            text = by_file[path][key]
            assert text == ("" if value is None else str(value)), (path, key)


def test_a_failed_fit_gives_the_result_beside_the_error(client, batch_logs):
    _, paths, _, _ = batch_logs
    rows = slideid.dask.identify_many(paths[:1], client, max_iterations=1)
    assert rows[0]["ok"] is False and rows[0]["error_type"] == "NumericalError"
    assert rows[0]["status"] is not None and "did not converge" in rows[0]["error"]


def test_bad_arguments_raise_before_any_task(client, batch_logs):
    _, paths, _, _ = batch_logs
    with pytest.raises(slideid.OptionError, match="^segment"):
        slideid.dask.identify_many(paths, client, segment=1)
    with pytest.raises(TypeError, match="segmnt"):
        slideid.dask.identify_many(paths, client, segmnt=20)
    with pytest.raises(slideid.OptionError):
        next(slideid.dask.map_identify(paths, client, loss="square"))
    with pytest.raises(ValueError, match="batch_size"):
        slideid.dask.identify_many(paths, client, batch_size=0)
    with pytest.raises(ValueError, match="names no .csv"):
        slideid.dask.identify_many("/nonexistent/folder", client)
    assert slideid.dask.identify_many([], client) == []


def test_default_tasks_balance_the_threads_and_stay_small():
    assert slideid.dask.default_batch_size(10, 2) == 1
    assert slideid.dask.default_batch_size(160, 2) == 10
    assert slideid.dask.default_batch_size(10**6, 2) == slideid.dask.MAX_BATCH_SIZE
    assert slideid.dask.default_batch_size(5, 0) == 1


def test_the_command_line_writes_every_line_and_says_what_failed(client, batch_logs, tmp_path):
    folder, paths, bad, _ = batch_logs
    out = tmp_path / "cli.jsonl"
    done = subprocess.run([sys.executable, "-m", "slideid.dask", "--batch", str(folder),
                           "--out", str(out), "--scheduler", client.scheduler.address,
                           "--segment", str(SEGMENT), "--batch-size", "2"],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 1, done.stderr
    assert "1 of 6 logs failed" in done.stderr
    entries = list(slideid.read_results(out))
    assert sorted(entry["file"] for entry in entries) == paths
    for entry in entries:
        assert without_times(entry) == expected(entry["file"])


def test_the_command_line_exit_codes(client, batch_logs, tmp_path, capsys):
    folder, paths, _, _ = batch_logs
    main = slideid.dask.main
    out = tmp_path / "cli.csv"
    scheduler = ["--scheduler", client.scheduler.address]
    assert main(["--batch", f"{folder}/log_000[01].csv", "--out", str(out), *scheduler,
                 "--segment", str(SEGMENT)]) == 0
    with open(out, newline="") as stream:
        assert sorted(row["file"] for row in csv.DictReader(stream)) == paths[:2]
    for args, fragment in [(["--segmnt", "20"], "unknown option '--segmnt'"),
                           (["--segment", "1"], "--segment"),
                           (["--jobs", "2"], "unknown option '--jobs'"),
                           (["--fit-delay", "sometimes"], "sometimes"),
                           (["--batch-size", "0"], "--batch-size")]:
        assert main(["--batch", str(folder), "--out", str(out), *args]) == 2, args
        assert fragment in capsys.readouterr().err, args
    assert main(["--batch", "/nonexistent/folder", "--out", str(out)]) == 2
    assert "names no .csv" in capsys.readouterr().err
    assert main(["--batch", str(folder), "--out", str(tmp_path / "no" / "r.jsonl"),
                 *scheduler]) == 4
    assert "cannot write the results" in capsys.readouterr().err


def test_without_a_client_it_starts_a_local_cluster_for_the_call(batch_logs, tmp_path):
    # In a process of its own: here the module's client is the current one.
    folder, paths, _, _ = batch_logs
    script = tmp_path / "no_client.py"
    script.write_text(
        "import json, sys, distributed, slideid.dask\n"
        "if __name__ == '__main__':\n"
        f"    rows = slideid.dask.identify_many(sys.argv[1], segment={SEGMENT})\n"
        "    try:\n"
        "        distributed.get_client()\n"
        "        print('a client is left')\n"
        "    except ValueError:\n"
        "        print(json.dumps(rows))\n")
    done = subprocess.run([sys.executable, str(script), str(folder)], capture_output=True,
                          text=True, check=False)
    assert done.returncode == 0, done.stderr
    rows = json.loads(done.stdout)
    assert [row_without_time(row) for row in rows] == [expected_row(path) for path in paths]


def test_a_worker_killed_mid_run_has_its_tasks_retried_and_the_table_is_whole(fifty_logs):
    """SIGKILL to a worker process with tasks running: the scheduler gives them to the
    other worker (the nanny restarts the dead one), and the table equals an undisturbed
    run's, nothing missing, nothing twice."""
    import os
    import signal
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as dask_client:
        undisturbed = slideid.dask.identify_many(fifty_logs, dask_client, batch_size=2,
                                                 method="equation-error")
        killed = []

        def kill_a_busy_worker(*_):
            if killed:
                return
            busy = [worker for worker, keys in dask_client.processing().items() if keys]
            pids = dask_client.run(os.getpid, workers=busy[:1])
            for worker, pid in pids.items():
                os.kill(pid, signal.SIGKILL)
                killed.append(worker)

        disturbed = slideid.dask.identify_many(fifty_logs, dask_client, batch_size=2,
                                               method="equation-error",
                                               progress=kill_a_busy_worker)
    assert killed, "no worker was killed"
    assert [row["file"] for row in disturbed] == fifty_logs
    assert [row_without_time(row) for row in disturbed] == \
        [row_without_time(row) for row in undisturbed]
    assert not any("the task that fitted it failed" in (row["error"] or "") for row in disturbed)


def test_identify_many_resumes_from_its_results_file(client, fifty_logs, tmp_path):
    """resume=True keeps the lines already in `out` (a torn last one dropped with a
    warning), fits the rest, and returns the whole table; the file ends with one line per
    log, as the uninterrupted run's."""
    paths = fifty_logs[:12]
    out = tmp_path / "results.jsonl"
    whole = slideid.dask.identify_many(paths, client, out=out, segment=SEGMENT)
    lines = out.read_bytes().splitlines(keepends=True)
    assert len(lines) == len(paths)
    out.write_bytes(b"".join(lines[:5]) + lines[5][:40])  # killed while writing line 6
    with pytest.warns(slideid.SlideidWarning, match=r"results.jsonl:6: a torn last line"):
        resumed = slideid.dask.identify_many(paths, client, out=out, resume=True,
                                             segment=SEGMENT)
    assert [row_without_time(r) for r in resumed] == [row_without_time(r) for r in whole]
    entries = list(slideid.read_results(out))
    assert sorted(entry["file"] for entry in entries) == sorted(paths)
    kept = [json.loads(line) for line in lines[:5]]
    assert entries[:5] == kept  # the earlier lines untouched
    # Nothing left to do: nothing fitted again.
    seen = []
    slideid.dask.identify_many(paths, client, out=out, resume=True, segment=SEGMENT,
                               progress=lambda *p: seen.append(p))
    assert seen == [] and len(list(slideid.read_results(out))) == len(paths)
    with pytest.raises(ValueError, match="resume=True needs out"):
        slideid.dask.identify_many(paths, client, resume=True)
