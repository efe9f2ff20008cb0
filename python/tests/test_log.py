"""Logs in Python: arrays and metadata read from files, logs made from arrays, written,
simulated, pickled; datasets and imports as the tools make them."""

import json
import pickle
import warnings

import numpy as np
import pytest

import slideid
from conftest import CORPUS, DEFAULT_LOG, SCENES, SOURCE_DIR, run_tool


def test_read_log_gives_the_columns_and_metadata_of_the_file():
    log = slideid.read_log(DEFAULT_LOG)
    assert log.rows == len(log) == 601
    assert list(log.columns) == ["t", "x", "y", "theta", "fx", "fy", "px", "py", "pz"]
    assert log.vx is None and log.mode is None  # poses only, as recorded
    assert log.t[0] == 0.0 and log.t[1] == pytest.approx(0.01)
    assert log.mass == 0.8 and log.com_height == 0.04 and log.gravity == 9.81
    assert log.patch == "rectangle 0.12 0.080000000000000002"  # as the file has it
    assert log.truth == {"mu": 0.4, "e_t": 1.0, "e_o": 1.3, "e_r": 0.03}
    assert log.source == "default_push.csv"
    assert log.extra["noise_seed"] == "2024"
    with pytest.raises(ValueError):  # read-only: a Log does not change under its results
        log.x[0] = 1.0
    # The first data row of the file, to the last bit.
    lines = [l for l in DEFAULT_LOG.read_text().splitlines() if not l.startswith("#")]
    first = [float(v) for v in lines[1].split(",")]
    assert [log.columns[name][0] for name in log.columns] == first


def test_a_log_made_from_its_own_arrays_is_the_same_log():
    log = slideid.read_log(DEFAULT_LOG)
    again = slideid.make_log(**log.columns, mass=log.mass, inertia=log.inertia,
                             com_height=log.com_height, gravity=log.gravity, patch=log.patch,
                             truth=log.truth, extra=log.extra, source=log.source)
    assert again.to_csv() == log.to_csv()
    assert log.replace().to_csv() == log.to_csv()
    heavier = log.replace(mass=0.9)
    assert heavier.mass == 0.9 and np.array_equal(heavier.x, log.x)


def test_make_log_reads_arrays_as_the_file_they_make():
    t = np.arange(5) * 0.01
    x = np.array([0.0, 0.001, 0.003, 0.004, 0.0045])
    log = slideid.make_log(t=t, x=x, y=np.zeros(5), theta=np.zeros(5), fx=np.ones(5),
                           fy=np.zeros(5), mass=1, inertia=1e-3, com_height=0.02)
    assert log.truth is None and log.source == "arrays"
    assert "velocities computed from poses (backward Euler)" in log.notes
    assert np.array_equal(log.x, x) and np.array_equal(log.t, t)
    # Lists and integers are numbers too.
    listed = slideid.make_log(t=list(t), vx=[1, 1, 1, 1, 1], vy=[0] * 5, wz=[0] * 5, mass=1,
                              inertia=1e-3, com_height=0)
    assert listed.vx.dtype == np.float64 and list(listed.columns) == ["t", "vx", "vy", "wz"]


def test_written_log_reads_back_bit_for_bit(tmp_path):
    log = slideid.simulate(SCENES / "example3_pushed_square.ini")
    path = tmp_path / "pushed.csv"
    slideid.write_log(log, path)
    back = slideid.read_log(path)
    assert back.to_csv() == log.to_csv() == path.read_text()
    for name, values in log.columns.items():
        assert np.array_equal(np.asarray(back.columns[name]), np.asarray(values)), name


def test_simulate_writes_what_the_simulate_tool_writes(tmp_path, monkeypatch):
    monkeypatch.chdir(SOURCE_DIR)  # the log's metadata names the scene as it was given
    scene = "datasets/scenes/default_push.ini"
    code, _, err = run_tool("simulate", "--scene", scene, "--out", tmp_path / "default.csv")
    assert code == 0, err
    log = slideid.simulate(scene)
    assert log.to_csv() == (tmp_path / "default.csv").read_text()
    assert log.simulation["steps"] == 60000 and log.simulation["ecp_margin"] > 0
    out = tmp_path / "ex1.csv"
    code, _, err = run_tool("simulate", "--scene", SCENES / "example1_square.ini", "--out",
                            out, "--dt", "0.005", "--write", "velocities", "--noise-velocity",
                            "0.001", "--seed", "3")
    assert code == 0, err
    log = slideid.simulate(SCENES / "example1_square.ini", dt=0.005, write="velocities",
                           noise_velocity=0.001, seed=3)
    assert log.to_csv() == out.read_text()


def test_simulate_a_scene_given_as_a_dict_equals_its_file():
    scene = {
        "slider": {"mass": 0.5, "inertia": 2.0833333333333333e-4, "com_height": 0.08,
                   "gravity": 9.8},
        "friction": {"mu": 0.31, "e_t": 1, "e_o": 1, "e_r": 0.01},
        "patch": {"shape": "rectangle", "width": 0.05, "length": 0.05},
        "initial": {"x": 0, "y": 0, "theta": 0, "vx": 0.7, "vy": 0.9, "wz": 10},
        "sim": {"dt": 0.01, "duration": 0.45},
    }
    from_dict = slideid.simulate(scene)
    from_file = slideid.simulate(SCENES / "example1_square.ini")
    for name, values in from_file.columns.items():
        assert np.array_equal(np.asarray(from_dict.columns[name]), np.asarray(values)), name


def test_logs_pickle_exactly():
    log = slideid.simulate(SCENES / "example2_ring.ini")
    again = pickle.loads(pickle.dumps(log))
    assert again.to_csv() == log.to_csv()
    assert again.source == log.source and again.simulation == log.simulation


def test_make_dataset_in_memory_equals_the_files(tmp_path):
    options = {"count": 2, "seed": 11, "pushes": 2, "noise_pose": 3e-4,
               "mass_range": (0.5, 0.9)}
    in_memory = slideid.make_dataset(**options)
    on_disk = slideid.make_dataset(out=tmp_path / "ds", **options)
    code, _, err = run_tool("make-dataset", "--count", 2, "--seed", 11, "--pushes", 2,
                            "--noise-pose", "3e-4", "--mass-range", "0.5:0.9", "--out",
                            tmp_path / "cli", "--quiet")
    assert code == 0, err
    for memory, disk in zip(in_memory, on_disk):
        assert memory["file"] == disk["file"]
        text = (tmp_path / "cli" / disk["file"]).read_text()
        assert memory["log"].to_csv() == text
        assert open(disk["path"]).read() == text
        assert 0.5 <= memory["mass"] <= 0.9
        assert memory["e_t_mu"] == pytest.approx(memory["e_t"] * memory["mu"])
    assert (tmp_path / "ds" / "truth.csv").read_text() == (tmp_path / "cli" / "truth.csv").read_text()


def test_import_log_writes_what_import_log_writes(tmp_path):
    files = [CORPUS / "mit_push" / "valid_push.json", CORPUS / "mit_push" / "bad_truncated.json"]
    object_options = ["--mass", "0.835", "--inertia", "1.13e-3", "--com-height", "0.0065",
                      "--patch", "rectangle 0.09 0.09"]
    code, _, _ = run_tool("import-log", "--format", "mit-push", *object_options, "--out",
                          tmp_path / "cli", *files)
    assert code == 1  # one file rejected
    summary = slideid.import_log("mit-push", files, tmp_path / "py", mass=0.835,
                                 inertia=1.13e-3, com_height=0.0065,
                                 patch="rectangle 0.09 0.09")
    assert summary["files"] == 2 and summary["accepted"] == 1
    assert len(summary["rejections"]) == 1 and "bad_truncated.json" in summary["rejections"][0]
    for name in ("valid_push.csv", "import_report.csv"):
        assert (tmp_path / "py" / name).read_text().replace(str(tmp_path / "py"), "") == \
            (tmp_path / "cli" / name).read_text().replace(str(tmp_path / "cli"), "")
    slideid.read_log(tmp_path / "py" / "valid_push.csv")


def test_import_log_reads_mcap_files_with_the_topic_keywords(tmp_path):
    # The fuzz seeds are short pushes (12 rows per stream): read, then rejected by the import.
    files = [CORPUS / "mcap" / "push_zstd_crc.mcap", CORPUS / "mcap" / "push_lz4.mcap"]
    topics = dict(object_topic="/object", tip_topic="/tf", tip_frame="tip", force_topic="/ft")
    summary = slideid.import_log("mcap", files, tmp_path, mass=0.835, inertia=1.13e-3,
                                 com_height=0.0065, patch="rectangle 0.09 0.09", **topics)
    assert summary["files"] == 2 and summary["accepted"] == 0
    assert all(line.startswith("rejected: ") for line in summary["rejections"])
    report = (tmp_path / "import_report.csv").read_text()
    assert "tip topic /tf: 2 of 12 messages have a zero header stamp" in report
    topics["tip_frame"] = "nothing"
    summary = slideid.import_log("mcap", files[:1], tmp_path / "b", mass=0.835, inertia=1.13e-3,
                                 com_height=0.0065, patch="rectangle 0.09 0.09", **topics)
    assert "topic '/tf' (the tip stream) has no transform with child frame 'nothing'" in \
        summary["rejections"][0]


def test_import_log_reads_stream_csvs_and_h5_files(tmp_path):
    # The MIT JSON push written as three CSVs (repr: exact doubles), each with its own
    # column names: the same log as from the JSON, but for its source line.
    good = CORPUS / "mit_push" / "valid_push.json"
    streams = json.loads(good.read_text())
    (tmp_path / "in").mkdir()
    for name, header in (("object_pose", "stamp,px,py,yaw"), ("tip_pose", "time,x,y,theta"),
                         ("ft_wrench", "t,fx,fy,tz")):
        rows = "".join(",".join(repr(v) for v in row) + "\n" for row in streams[name])
        (tmp_path / "in" / (name + ".csv")).write_text(header + "\n" + rows)
    obj = dict(mass=0.835, inertia=1.13e-3, com_height=0.0065, patch="rectangle 0.09 0.09")
    json_run = slideid.import_log("mit-push", [good], tmp_path / "json", **obj)
    csv_run = slideid.import_log(
        "streams", [], tmp_path / "csv", pose=f"{tmp_path}/in/object_pose.csv:t=stamp,x=px,y=py,theta=yaw",
        tip=f"{tmp_path}/in/tip_pose.csv:t=time", force=f"{tmp_path}/in/ft_wrench.csv:tz", **obj)
    assert json_run["accepted"] == 1 and csv_run["accepted"] == 1
    def body(path):
        return [line for line in path.read_text().splitlines() if not line.startswith("# source = ")]
    assert body(tmp_path / "csv" / "object_pose.csv") == body(tmp_path / "json" / "valid_push.csv")
    # An .h5 file (the fuzz seed: a 12-row push, read and then rejected as too short) and a
    # JSON file given as HDF5 (unreadable, named).
    h5_run = slideid.import_log("mit-push-h5", [CORPUS / "mit_push_h5" / "push.h5", good],
                                tmp_path / "h5", **obj)
    assert h5_run["files"] == 2 and h5_run["accepted"] == 0
    assert h5_run["rejections"][0].startswith("rejected: ")
    assert "valid_push.json: not an HDF5 file" in h5_run["rejections"][1]


def test_import_tripod_logs_into_pairs_as_import_log_does(tmp_path):
    files = [CORPUS / "tripod" / "valid_two_pushes.txt"]
    code, _, err = run_tool("import-log", "--format", "zhou-tripod", "--out", tmp_path / "cli",
                            *files)
    assert code == 0, err
    summary = slideid.import_log("zhou-tripod", files, tmp_path / "py")
    assert summary["accepted"] == 1 and summary["rejections"] == []
    for path in sorted((tmp_path / "cli").iterdir()):
        assert (tmp_path / "py" / path.name).read_text() == path.read_text(), path.name


def test_reader_warnings_are_issued_once_and_kept_in_the_result(tmp_path):
    log = slideid.read_log(DEFAULT_LOG)
    t = np.array(log.t)
    t[300:] += 0.04  # a gap of 5 intervals: a warning (an error from 10)
    with pytest.warns(slideid.SlideidWarning, match="intervals longer than 3 times") as record:
        gappy = log.replace(t=t)
    assert len(record) == 1
    assert str(record[0].message).startswith("default_push.csv row 300: column 't': ")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = slideid.identify(gappy)
    assert not [w for w in caught if "intervals longer" in str(w.message)]
    assert [w for w in result.warnings if "intervals longer" in w]
    # From a file, the warning is identify's, as the tool prints it.
    path = tmp_path / "gappy.csv"
    slideid.write_log(gappy, path)
    _, _, err = run_tool("identify", "--log", path)
    cli_warnings = [line[len("identify: warning: "):] for line in err.splitlines()
                    if line.startswith("identify: warning: ")]
    with pytest.warns(slideid.SlideidWarning, match="intervals longer"):
        result = slideid.identify(path)
    assert result.warnings == cli_warnings != []


def test_times_stamped_on_arrival_are_warned_of_and_put_back_on_a_grid(tmp_path):
    # The bundled log with each row stamped up to 3 ms off its sampling time (in order).
    text = DEFAULT_LOG.read_text().splitlines()
    meta = [l for l in text if l.startswith("#")]
    rows = [l.split(",") for l in text[len(meta) + 1:]]
    rng = np.random.default_rng(5)
    previous = 0.0
    for k, row in enumerate(rows[1:], start=1):
        t = max(float(row[0]) + rng.normal(0.0, 0.003), previous + 1e-4)
        row[0] = repr(t)
        previous = t
    path = tmp_path / "stamped.csv"
    path.write_text("\n".join(meta + [text[len(meta)]] + [",".join(r) for r in rows]) + "\n")
    with pytest.warns(slideid.SlideidWarning, match="--regular-times"):
        jittered = slideid.read_log(path)
    assert np.std(np.diff(jittered.t)) > 0.002
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        regular = slideid.read_log(path, regular_times=True)
    assert np.ptp(np.diff(regular.t)) < 1e-9
    reference = slideid.identify(DEFAULT_LOG)
    result = slideid.identify(path, regular_times=True)
    assert result.e_t_mu.value == pytest.approx(reference.e_t_mu.value, rel=1e-3)


def test_dropouts_are_errors_or_gaps_when_asked_for(tmp_path):
    text = DEFAULT_LOG.read_text().splitlines()
    meta = [l for l in text if l.startswith("#")]
    rows = [l.split(",") for l in text[len(meta) + 1:]]
    for k in (100, 101, 300):
        rows[k][1:4] = ["nan", "nan", "nan"]
    path = tmp_path / "dropouts.csv"
    path.write_text("\n".join(meta + [text[len(meta)]] + [",".join(r) for r in rows]) + "\n")
    with pytest.raises(slideid.InputError, match="missing-as-gaps"):
        slideid.read_log(path)
    log = slideid.read_log(path, missing_as_gaps=True)
    assert log.rows == 598
    assert list(log.mode).count("start") == 3
    result = slideid.identify(path, missing_as_gaps=True)
    assert result.e_t_mu.value == pytest.approx(0.4, rel=0.01)
