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


@pytest.fixture
def default_log_path():
    return DEFAULT_LOG
