"""Shared fixtures of the Python module's tests: where the tools and the repository's data
are (ctest sets SLIDEID_BIN_DIR and SLIDEID_SOURCE_DIR; by hand they default to the build
tree beside this checkout), and running a tool to compare with."""

import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("SLIDEID_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
BIN_DIR = pathlib.Path(os.environ.get("SLIDEID_BIN_DIR", SOURCE_DIR / "build" / "bin"))
DEFAULT_LOG = SOURCE_DIR / "datasets" / "logs" / "default_push.csv"
SCENES = SOURCE_DIR / "datasets" / "scenes"
CORPUS = SOURCE_DIR / "fuzz" / "corpus"


def run_tool(tool, *args):
    """Runs build/bin/<tool> with args; returns (exit code, stdout, stderr)."""
    done = subprocess.run([str(BIN_DIR / tool), *map(str, args)], capture_output=True,
                          text=True, check=False)
    return done.returncode, done.stdout, done.stderr


def cli_json(*args):
    """identify --json on args: the object it prints, without "seconds" (the run time)."""
    code, out, err = run_tool("identify", "--json", *args)
    assert code == 0, err
    data = json.loads(out)
    data.pop("seconds")
    return data


def without_seconds(data):
    data = dict(data)
    data.pop("seconds")
    return data


def cli_error(tool, *args):
    """The exit code and the message of a failing tool run ("tool: error: " taken off)."""
    code, _, err = run_tool(tool, *args)
    assert code != 0
    line = err.strip().splitlines()[-1]
    for prefix in (f"{tool}: error: ", f"{tool}: usage: ", f"{tool}: "):
        if line.startswith(prefix):
            return code, line[len(prefix):]
    return code, line


def without_times(entry):
    """A batch line or an identify_file dict without its run times ("seconds", also of the
    "result" of a failed fit)."""
    entry = dict(entry)
    entry.pop("seconds", None)
    if "result" in entry:
        entry["result"] = without_times(entry["result"])
    return entry


@pytest.fixture
def default_log_path():
    return DEFAULT_LOG


@pytest.fixture(scope="session")
def batch_logs(tmp_path_factory):
    """Many logs, for batches: a directory of five short simulated logs (make_dataset, 2
    pushes, motion-capture noise) and, sorted between them, one with a word for a number.
    Returns (directory, the sorted logs, the bad log, the bad log's line)."""
    import slideid
    folder = tmp_path_factory.mktemp("batch_logs")
    slideid.make_dataset(count=5, seed=11, out=folder, pushes=2, noise_pose=3e-4,
                         noise_angle=3e-3)
    lines = (folder / "log_0001.csv").read_text().splitlines()
    row = next(k for k, line in enumerate(lines) if line and line[0].isdigit()) + 3
    fields = lines[row].split(",")
    fields[1] = "abc"  # column x
    lines[row] = ",".join(fields)
    bad = folder / "log_0002_bad.csv"
    bad.write_text("\n".join(lines) + "\n")
    return folder, slideid.log_files(folder), str(bad), row + 1


@pytest.fixture(scope="session")
def fifty_logs(tmp_path_factory):
    """Fifty short simulated logs (make_dataset, 2 pushes, motion-capture noise), sorted:
    for the concurrency and fault tests."""
    import slideid
    folder = tmp_path_factory.mktemp("fifty_logs")
    slideid.make_dataset(count=50, seed=22, out=folder, pushes=2, noise_pose=3e-4,
                         noise_angle=3e-3)
    return slideid.log_files(folder)
