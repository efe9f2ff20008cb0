"""slideid.OnlineIdentifier: the friction row by row, equal to identify --follow on the same
log, the truth inside its intervals at the end, the GIL released in update_many."""

import threading
import time

import numpy as np
import pytest

import slideid
from conftest import DEFAULT_LOG, run_tool

COLUMNS = ("t", "x", "y", "theta", "fx", "fy", "px", "py", "pz")


def rows_of(log):
    return np.column_stack([getattr(log, name) for name in COLUMNS])


def follow_lines(path):
    """identify --follow on the file piped in: its JSON lines, as dicts."""
    import json
    import subprocess

    from conftest import BIN_DIR
    with open(path, "rb") as stdin:
        done = subprocess.run([str(BIN_DIR / "identify"), "--follow"], stdin=stdin,
                              capture_output=True, check=True)
    return [json.loads(line) for line in done.stdout.decode().splitlines()]


def test_update_many_recovers_the_bundled_logs_truth_within_its_intervals():
    log = slideid.read_log(DEFAULT_LOG)
    online = slideid.OnlineIdentifier(log, columns=COLUMNS)
    results = online.update_many(rows_of(log))
    assert len(results) == len(log.t)
    assert not results[0]["started"] and results[0]["e_t_mu"]["value"] is None
    last = results[-1]
    assert last["row"] == len(log.t) - 1 and last["changes"] == 0
    assert last["confirmed_changes"] == 0 and last["withdrawn_changes"] == 0
    truth = {"e_t_mu": 0.4, "e_o_over_e_t": 1.3, "e_r_over_e_t": 0.03}
    for name, value in truth.items():
        lo, hi = last[name]["ci95"]
        assert last[name]["verdict"] == "ok"
        assert lo <= value <= hi, (name, last[name])


def test_results_equal_identify_follow_on_the_same_log():
    log = slideid.read_log(DEFAULT_LOG)
    rows = rows_of(log)
    online = slideid.OnlineIdentifier(log, columns=COLUMNS)
    # Rows one at a time, as dicts, then the rest in one array: the same as the tool.
    first = [online.update(dict(zip(COLUMNS, row))) for row in rows[:40]]
    rest = online.update_many(rows[40:])
    assert first + rest == follow_lines(DEFAULT_LOG)


def test_batch_check_rows_sets_the_identifiers_batch_check():
    log = slideid.read_log(DEFAULT_LOG)
    rows = rows_of(log)
    checked = slideid.OnlineIdentifier(log, columns=COLUMNS).update_many(rows)[-1]
    alone = slideid.OnlineIdentifier(log, columns=COLUMNS, batch_check_rows=0).update_many(rows)[-1]
    assert checked["batch_checks"] >= 1 and alone["batch_checks"] == 0
    assert alone["batch_takeovers"] == 0
    with pytest.raises(ValueError, match="batch_check_rows must be >= 0"):
        slideid.OnlineIdentifier(log, columns=COLUMNS, batch_check_rows=-1)
    with pytest.raises(TypeError, match="batch_check_rows"):
        slideid.OnlineIdentifier(log, columns=COLUMNS, batch_check_rows=1.5)


def test_metadata_as_a_dict_and_bad_rows_are_named():
    online = slideid.OnlineIdentifier({"mass": 0.8, "inertia": 1.3866666666666667e-3,
                                       "com_height": 0.04})
    assert online.columns == ("t", "x", "y", "theta", "fx", "fy")
    online.update([0.0, 0, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="row 1"):
        online.update([0.0, 0, 0, 0, 0, 0])  # not after the previous row
    with pytest.raises(ValueError, match="shape"):
        online.update_many(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="lacks"):
        online.update({"t": 1.0})
    with pytest.raises(ValueError, match="com_height"):
        slideid.OnlineIdentifier({"mass": 1.0, "inertia": 1e-3})


def test_update_many_releases_the_gil():
    log = slideid.read_log(DEFAULT_LOG)
    rows = np.tile(rows_of(log), (8, 1))
    rows[:, 0] = np.arange(len(rows)) * 0.01  # times strictly increasing
    online = slideid.OnlineIdentifier(log, columns=COLUMNS)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    start = time.perf_counter()
    online.update_many(rows)
    end = time.perf_counter()
    stop.set()
    counter.join()
    # While update_many ran, the other thread kept running: the GIL was free. (With the GIL
    # held, it gets the interpreter only at update_many's end.)
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.02, "too short to tell"
    assert len(during) >= 5, (len(during), end - start)


def test_mu_pusher_where_the_rows_carry_the_tip(tmp_path):
    code, _, err = run_tool("make-dataset", "--count", 1, "--seed", 1, "--out", tmp_path,
                            "--drive", "pusher", "--log-every", 10, "-q")
    assert code == 0, err
    path = tmp_path / "log_0000.csv"
    log = slideid.read_log(path)
    assert log.metadata["tip_radius"] == pytest.approx(0.00475)
    columns = ("t", "x", "y", "theta", "fx", "fy", "px", "py", "pz", "tip_x", "tip_y")
    header, *lines = [line for line in path.read_text().splitlines()
                      if not line.startswith("#")]
    names = header.split(",")
    rows = np.array([[float(line.split(",")[names.index(c)]) for c in columns]
                     for line in lines])
    online = slideid.OnlineIdentifier(log, columns=columns)
    results = online.update_many(rows)
    assert results == follow_lines(path)
    mu = results[-1]["mu_pusher"]
    assert mu["sliding_rows"] > 0 and mu["contact_rows"] >= mu["sliding_rows"]
    assert mu["verdict"] in ("ok", "suspect") and mu["value"] > 0
    # Without the tip's radius, or without its path, mu_p is not examined.
    metadata = {key: log.metadata[key] for key in ("mass", "inertia", "com_height", "patch")}
    plain = slideid.OnlineIdentifier(metadata, columns=columns).update_many(rows[:30])
    assert "mu_pusher" not in plain[-1]
