"""Many logs without Dask: identify --batch writes, line by line, the dicts identify_file
gives; its shards, run as the Slurm recipe runs them (examples/slurm_identify.sbatch), cover
every log once; the lines read back into a table."""

import json
import os
import subprocess

import pytest

import slideid
from conftest import BIN_DIR, SOURCE_DIR, without_times

SEGMENT = 12  # not the default (20 for these logs): it must reach the tool


def expected(path):
    entry = without_times(slideid.identify_file(path, segment=SEGMENT))
    entry.pop("error_type", None)  # the tool's lines have none
    return entry


def test_identify_batch_writes_the_dicts_of_identify_file(batch_logs, tmp_path):
    folder, paths, bad, line = batch_logs
    out = tmp_path / "batch.jsonl"
    done = subprocess.run([str(BIN_DIR / "identify"), "--batch", str(folder), "--out", str(out),
                           "--segment", str(SEGMENT), "--jobs", "2"],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 1, done.stderr  # a log failed
    assert "identify: 6 logs, 5 identified, 1 failed, " in done.stderr
    lines = list(slideid.read_results(out))
    assert sorted(entry["file"] for entry in lines) == paths
    for entry in lines:
        assert without_times(entry) == expected(entry["file"])
    rows = {row["file"]: row for row in map(slideid.result_row, lines)}
    assert rows[bad]["ok"] is False and f"{bad}:{line}" in rows[bad]["error"]
    assert rows[bad]["error_type"] is None  # only Python names the exception
    assert all(rows[path]["ok"] and rows[path]["rows"] > 0 for path in paths if path != bad)


def test_slurm_array_shards_cover_every_log_once(batch_logs, tmp_path):
    folder, paths, bad, _ = batch_logs
    script = SOURCE_DIR / "examples" / "slurm_identify.sbatch"
    tasks = 4
    for task in range(tasks):  # as Slurm runs the array's tasks, each in the directory
        env = dict(os.environ, SLURM_ARRAY_TASK_ID=str(task), SLURM_ARRAY_TASK_COUNT=str(tasks),
                   SLURM_CPUS_PER_TASK="1", IDENTIFY=str(BIN_DIR / "identify"))
        done = subprocess.run(["bash", str(script), str(folder)], cwd=tmp_path,
                              env=env, capture_output=True, text=True, check=False)
        assert done.returncode == 0, done.stderr  # a failed log is in its line, not the code
    shards = sorted(tmp_path.glob("results_*.jsonl"))
    assert [p.name for p in shards] == [f"results_{t}.jsonl" for t in range(tasks)]
    whole = tmp_path / "results.jsonl"
    whole.write_text("".join(p.read_text() for p in shards))  # cat results_*.jsonl
    files = [entry["file"] for entry in slideid.read_results(whole)]
    assert sorted(files) == paths  # every log, once
    # Shard t takes the logs whose index in the sorted list is t modulo 4.
    assert [e["file"] for e in slideid.read_results(tmp_path / "results_1.jsonl")] \
        == paths[1::tasks]


def test_read_results_names_the_line_that_is_not_a_result(tmp_path):
    results = tmp_path / "r.jsonl"
    results.write_text('{"file": "a.csv", "ok": false, "error": "a.csv: bad"}\n\n[1, 2]\n')
    with pytest.raises(ValueError, match=r"r.jsonl:3: not a result line"):
        list(slideid.read_results(results))
    results.write_text('{"file": "a.csv", "ok": fals}\n')
    with pytest.raises(ValueError, match=r"r.jsonl:1: not JSON"):
        list(slideid.read_results(results))


def test_rows_have_the_columns_of_the_table_whatever_the_line():
    failed = slideid.result_row({"file": "a.csv", "ok": False, "error": "a.csv:3: bad"})
    assert tuple(failed) == slideid.ROW_FIELDS
    assert failed["error"] == "a.csv:3: bad" and failed["status"] is None
    json.dumps(failed)


def test_log_files_are_the_sorted_logs_without_the_manifests(batch_logs):
    folder, paths, bad, _ = batch_logs
    assert (folder / "truth.csv").exists()
    assert paths == sorted(str(p) for p in folder.glob("log_*.csv"))
    assert slideid.log_files(f"{folder}/log_000[01].csv") == paths[:2]
    with pytest.raises(ValueError, match="names no .csv"):
        slideid.log_files(folder / "nothing_here")
