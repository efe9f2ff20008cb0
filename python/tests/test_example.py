"""The example a user copies (examples/fit_and_plot.py) runs and writes what it says."""

import json
import os
import subprocess
import sys

from conftest import BIN_DIR, DEFAULT_LOG, SOURCE_DIR, cli_json, without_seconds


def test_fit_and_plot_writes_the_result_residuals_and_figure(tmp_path):
    env = dict(os.environ, PATH=f"{BIN_DIR}{os.pathsep}{os.environ.get('PATH', '')}")
    done = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "fit_and_plot.py"),
                           str(DEFAULT_LOG), "--out", str(tmp_path)],
                          capture_output=True, text=True, env=env, check=False)
    assert done.returncode == 0, done.stderr
    assert "e_t_mu" in done.stdout and "from the truth" in done.stdout
    result = json.loads((tmp_path / "result.json").read_text())
    assert without_seconds(result) == cli_json("--log", DEFAULT_LOG, "--substeps", "4")
    header, *rows = (tmp_path / "residuals.csv").read_text().splitlines()
    assert header.startswith("t,") and header.endswith(",used") and len(rows) > 500
    assert (tmp_path / "fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
