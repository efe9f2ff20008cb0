"""Fit a push log with slideid and plot it: a script to copy.

    PYTHONPATH=build/python /usr/bin/python3 examples/fit_and_plot.py [LOG.csv] [--out DIR]

(Debian's /usr/bin/python3: the interpreter slideid is built for; docs/python.md.) Without
LOG.csv it fits the bundled datasets/logs/default_push.csv. It prints the estimates, then
writes to DIR (default fit_output/):
  result.json    the result, exactly as `identify --json` prints it
  residuals.csv  the fit's per-step residuals (t, the method's channels, used)
  fit.png        the log with the fitted trajectory replayed over it, drawn by the
                 plot-log tool (gnuplot); with matplotlib installed, also residuals.png
"""

import argparse
import json
import pathlib
import shutil
import subprocess
import sys

import numpy as np

import slideid

ROOT = pathlib.Path(__file__).resolve().parents[1]


def fit(log_path, out_dir):
    log = slideid.read_log(log_path)
    print(f"{log.source}: {log.rows} rows, m = {log.mass} kg, columns {', '.join(log.columns)}")

    # Options are identify's (docs/identify.md): substeps=4 simulates at 4x the log rate.
    result = slideid.identify(log, substeps=4)
    print(result)
    if result.truth:  # simulated logs record the friction they were made with
        for name, truth in result.truth.items():
            estimate = getattr(result, name)
            if estimate.value is not None:
                print(f"  {name}: {100 * (estimate.value / truth - 1):+.2f}% from the truth")

    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "result.json").write_text(json.dumps(result.to_dict()) + "\n")
    residuals = result.residuals
    channels = [name for name in residuals if name not in ("log", "row", "t", "used")]
    np.savetxt(out_dir / "residuals.csv",
               np.column_stack([residuals["t"]] + [residuals[c] for c in channels] +
                               [residuals["used"]]),
               delimiter=",", header=",".join(["t"] + channels + ["used"]), comments="")
    return result, channels


def plot(log_path, result, channels, out_dir):
    """The log and the replayed fit with plot-log; the residuals with matplotlib, if present."""
    plot_log = shutil.which("plot-log") or ROOT / "build" / "bin" / "plot-log"
    if pathlib.Path(plot_log).exists():
        subprocess.run([str(plot_log), str(log_path), "--fit", str(out_dir / "result.json"),
                        "--substeps", "4", "--out", str(out_dir / "fit.png")], check=True)
        print(f"wrote {out_dir / 'fit.png'}")
    else:
        print("plot-log not found (build slideid, or put its bin/ on PATH): no fit.png")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: residuals are in residuals.csv only")
        return
    figure, axes = plt.subplots(len(channels), 1, sharex=True, figsize=(8, 6))
    for axis, channel in zip(np.atleast_1d(axes), channels):
        axis.plot(result.residuals["t"], result.residuals[channel], ".", markersize=2)
        axis.set_ylabel(channel)
    np.atleast_1d(axes)[-1].set_xlabel("t [s]")
    figure.savefig(out_dir / "residuals.png", dpi=120)
    print(f"wrote {out_dir / 'residuals.png'}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", nargs="?", default=ROOT / "datasets" / "logs" / "default_push.csv")
    parser.add_argument("--out", default="fit_output", type=pathlib.Path)
    args = parser.parse_args()
    try:
        result, channels = fit(args.log, args.out)
    except (ValueError, slideid.NumericalError) as error:
        sys.exit(f"fit_and_plot: {error}")
    plot(args.log, result, channels, args.out)


if __name__ == "__main__":
    main()
