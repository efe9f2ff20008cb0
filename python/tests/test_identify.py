"""identify from Python: known parameters recovered from arrays, and results equal to the
identify tool's JSON on the same logs and options."""

import concurrent.futures
import hashlib
import json
import pickle

import numpy as np
import pytest

import slideid
from conftest import CORPUS, DEFAULT_LOG, SOURCE_DIR, cli_json, run_tool, without_seconds

TRUTH = {"e_t_mu": 0.35, "e_o_over_e_t": 1.25, "e_r_over_e_t": 0.035}


def pushed_box(noise):
    """A 0.6 kg box pushed three times from three edges (a, b and c all excited), logged at
    100 Hz: poses, force and push point. Noiseless, it is simulated at the log's 10 ms (the
    log is then the model itself); with motion-capture noise, at 1 ms (as real motion is
    finer than its log)."""
    a, b, c = TRUTH.values()
    scene = {
        "slider": {"mass": 0.6, "inertia": 0.6 * (0.1**2 + 0.08**2) / 12, "com_height": 0.03},
        "friction": {"mu": a, "e_t": 1.0, "e_o": b, "e_r": c},
        "patch": {"shape": "rectangle", "width": 0.1, "length": 0.08},
        "initial": {"x": 0, "y": 0, "theta": 0},
        "push.1": {"point": (-0.05, -0.006), "direction": (1, 0), "height": 0.015,
                   "force": 3.2, "start": 0.1, "stop": 0.5},
        "push.2": {"point": (0.006, -0.04), "direction": (-0.1, 1), "height": 0.02,
                   "force": 3.4, "amplitude": 0.6, "period": 0.3, "start": 1.0, "stop": 1.4},
        "push.3": {"point": (0.05, 0.005), "direction": (-1, 0.05), "height": 0.015,
                   "force": 3.0, "start": 2.0, "stop": 2.4},
        "sim": {"dt": 1e-3, "duration": 2.9, "log_every": 10} if noise else
               {"dt": 0.01, "duration": 2.9},
        "log": {"write": "poses", "push": "point"},
    }
    if noise:
        scene["noise"] = {"pose": 3e-4, "angle": 3e-3, "seed": 7}
    return slideid.simulate(scene)


def from_arrays(log):
    """The log rebuilt from plain numpy arrays and numbers, as a user's own data would be."""
    arrays = {name: np.array(log.columns[name]) for name in
              ("t", "x", "y", "theta", "fx", "fy", "px", "py", "pz")}
    return slideid.make_log(**arrays, mass=float(log.mass), inertia=float(log.inertia),
                            com_height=float(log.com_height))


def test_arrays_to_log_to_identify_recovers_noiseless_truth():
    log = from_arrays(pushed_box(noise=False))
    result = slideid.identify(log)
    assert result.status == "converged"
    # A noiseless log of the model itself: only the solvers' tolerances stand between the
    # estimate and the truth (about 1e-6 here).
    for name, truth in TRUTH.items():
        estimate = result.parameters[name]
        assert estimate.verdict == "ok"
        assert estimate.value == pytest.approx(truth, rel=1e-4), name


def test_arrays_to_log_to_identify_covers_truth_with_noise():
    log = from_arrays(pushed_box(noise=True))
    assert log.truth is None  # rebuilt from arrays: the estimate cannot have peeked
    result = slideid.identify(log, substeps=4)
    assert result.converged
    for name, truth in TRUTH.items():
        estimate = result.parameters[name]
        assert estimate.identifiable, name
        lo, hi = estimate.ci95
        assert lo <= truth <= hi, (name, estimate.to_dict())
        # 0.3 mm and 3 mrad of noise on a 3 s log: errors of about 0.4% (measured); 2%
        # would be five times that.
        assert estimate.value == pytest.approx(truth, rel=0.02), name


def test_result_has_the_fields_of_the_json_and_the_residuals():
    result = slideid.identify(DEFAULT_LOG)
    data = result.to_dict()
    assert list(data)[:3] == ["e_t_mu", "e_o_over_e_t", "e_r_over_e_t"]
    assert result.e_t_mu.value == data["e_t_mu"]["value"]
    assert result.e_t_mu["ci95"] == data["e_t_mu"]["ci95"]
    assert result.method == "trajectory" and result.converged is True
    assert result.truth == pytest.approx({"e_t_mu": 0.4, "e_o_over_e_t": 1.3,
                                          "e_r_over_e_t": 0.03})
    rows = len(result.residuals["t"])
    assert rows > 500
    assert set(result.residuals) >= {"log", "row", "t", "used"}
    assert all(len(v) == rows for v in result.residuals.values())
    # to_dict is a copy: changing it changes nothing.
    data["e_t_mu"]["value"] = -1
    assert result.e_t_mu.value > 0
    # Results pickle (to travel from a worker process).
    again = pickle.loads(pickle.dumps(result))
    assert again.to_dict() == result.to_dict() and again.truth == result.truth


@pytest.fixture(scope="session")
def noise_free_log(tmp_path_factory):
    """The bundled log's scene simulated without noise: the cheap methods identify nothing on
    the bundled log's noisy poses, and the tool then exits 1 without its JSON."""
    path = tmp_path_factory.mktemp("noise_free") / "default_push_noise_free.csv"
    code, _, err = run_tool("simulate", "--scene", SOURCE_DIR / "datasets" / "scenes" /
                            "default_push.ini", "--noise-pose", "0", "--noise-angle", "0",
                            "--noise-force", "0", "--noise-force-relative", "0", "--out", path)
    assert code == 0, err
    return path


@pytest.mark.parametrize("options,cli", [
    ({}, []),
    ({"method": "closed-form"}, ["--method", "closed-form"]),
    ({"method": "equation-error", "loss": "cauchy"},
     ["--method", "equation-error", "--loss", "cauchy"]),
    ({"segment": 25, "substeps": 2, "loss": "none"},
     ["--segment", "25", "--substeps", "2", "--loss", "none"]),
    ({"fit_force_bias": True, "max_iterations": 60},
     ["--fit-force-bias", "--max-iterations", "60"]),
    ({"fit_delay": True}, ["--fit-delay"]),
    ({"mass": 0.82, "inertia": 1.4e-3, "com_height": 0.05, "gravity": 9.8},
     ["--mass", "0.82", "--inertia", "1.4e-3", "--com-height", "0.05", "--gravity", "9.8"]),
])
def test_result_equals_the_cli_json(options, cli, noise_free_log):
    log = noise_free_log if options.get("method") in ("closed-form", "equation-error") \
        else DEFAULT_LOG
    expected = cli_json("--log", log, *cli)
    from_path = slideid.identify(log, **options)
    assert without_seconds(from_path.to_dict()) == expected
    # The same log read first, then identified: the same result.
    from_log = slideid.identify(slideid.read_log(log), **options)
    assert without_seconds(from_log.to_dict()) == expected


def test_pooled_logs_equal_the_cli_with_per_log_results_and_heterogeneity(tmp_path):
    entries = slideid.make_dataset(count=3, seed=5, out=tmp_path, pushes=3, noise_pose=3e-4,
                                   noise_angle=3e-3, mass_range=(0.8, 0.8),
                                   mu_range=(0.3, 0.3), e_t_range=(1, 1), e_o_range=(1.2, 1.2),
                                   e_r_range=(0.03, 0.03), patch="rectangle 0.1 0.08",
                                   com_height_range=(0.03, 0.03))
    paths = [entry["path"] for entry in entries]
    cli = ["--fit-delay", "per-log", "--fit-force-bias"]
    expected = cli_json(*[a for p in paths for a in ("--log", p)], *cli)
    result = slideid.identify(paths, fit_delay="per-log", fit_force_bias=True)
    assert without_seconds(result.to_dict()) == expected
    assert [entry.name for entry in result.logs] == [f"log_000{i}.csv" for i in range(3)]
    assert set(result.heterogeneity) == {"e_t_mu", "e_o_over_e_t", "e_r_over_e_t"}
    assert result.heterogeneity["e_t_mu"].tested is True
    assert {"force_bias_x_n", "force_bias_y_n", "delay_s"} <= set(result.nuisance)
    assert result.nuisance["delay_s"][0].log == "log_0000.csv"
    logs = [slideid.read_log(p) for p in paths]
    from_logs = slideid.identify(logs, fit_delay="per-log", fit_force_bias=True)
    assert without_seconds(from_logs.to_dict()) == expected


def test_skip_bad_lists_the_unreadable_log_as_the_cli_does(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("# mass = 1\nt,x\n0,1\n")
    expected = cli_json("--log", DEFAULT_LOG, "--log", bad, "--skip-bad")
    result = slideid.identify([DEFAULT_LOG, bad], skip_bad=True)
    assert without_seconds(result.to_dict()) == expected
    assert result.logs[-1].skipped is True and "bad.csv" in result.logs[-1].skip_reason


def test_quasi_static_pairs_equal_the_cli():
    pairs = CORPUS / "pairs" / "valid_pairs.csv"
    expected = cli_json("--method", "quasi-static", "--log", pairs)
    result = slideid.identify(pairs, method="quasi-static")
    assert without_seconds(result.to_dict()) == expected


def test_identify_file_gives_one_plain_dict_per_file(tmp_path):
    entry = slideid.identify_file(DEFAULT_LOG, segment=30)
    assert entry["file"] == str(DEFAULT_LOG) and entry["ok"] is True
    assert without_seconds({k: v for k, v in entry.items()
                            if k not in ("file", "sha256", "ok", "warnings")}) \
        == cli_json("--log", DEFAULT_LOG, "--segment", "30")
    assert entry["sha256"] == hashlib.sha256(DEFAULT_LOG.read_bytes()).hexdigest()
    json.dumps(entry)  # plain data: a line of a JSON-lines file
    missing = slideid.identify_file(tmp_path / "missing.csv")
    assert missing["error_type"] == "ValueError" and missing["ok"] is False
    assert "missing.csv" in missing["error"] and "cannot read" in missing["error"]
    failed = slideid.identify_file(DEFAULT_LOG, max_iterations=1)
    assert failed["error_type"] == "NumericalError"
    assert failed["result"]["converged"] is False
    with pytest.raises(slideid.OptionError):  # an option error fails every file: raised
        slideid.identify_file(DEFAULT_LOG, segment=1)
    with pytest.raises(TypeError):
        slideid.identify_file(DEFAULT_LOG, segmnt=20)


def test_fits_in_threads_give_the_results_of_fits_one_after_the_other(tmp_path):
    # The GIL is released during a fit, so fits run at once in threads; they must not
    # disturb each other.
    entries = slideid.make_dataset(count=4, seed=3, pushes=2, noise_pose=3e-4)
    logs = [entry["log"] for entry in entries]
    one_by_one = [without_seconds(slideid.identify(log).to_dict()) for log in logs]
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        at_once = list(pool.map(lambda log: without_seconds(slideid.identify(log).to_dict()),
                                logs))
    assert at_once == one_by_one


def test_the_version_is_the_tools_version():
    code, out, _ = run_tool("identify", "--version")
    assert code == 0 and out == f"identify (slideid) {slideid.__version__}\n"



def test_check_equals_the_cli_and_fits_nothing():
    code, out, err = run_tool("identify", "--check", "--json", "--log", DEFAULT_LOG)
    assert code == 0, err
    assert slideid.check(DEFAULT_LOG) == json.loads(out)
    log = slideid.read_log(DEFAULT_LOG)
    both = slideid.check([log, log])
    assert isinstance(both, list) and len(both) == 2 and both[0] == both[1]
    checked = both[0]
    for name in ("e_t_mu", "e_o_over_e_t", "e_r_over_e_t"):
        assert checked[name]["identifiable"] is True
        assert 0 < checked[name]["relative_stderr"] < 0.1
    assert checked["condition_number"] >= 1
    assert checked["advice"] == []
    with pytest.raises(slideid.OptionError, match="method"):
        slideid.check(DEFAULT_LOG, method="closed-form")
    with pytest.raises(TypeError, match="unexpected keyword argument 'check'"):
        slideid.identify(DEFAULT_LOG, check=True)


def test_identify_writes_the_html_report_when_asked(tmp_path):
    """report=PATH writes identify --report's page, for a path and for a Log object."""
    for name, logs in (("from_path.html", str(DEFAULT_LOG)),
                       ("from_log.html", slideid.read_log(str(DEFAULT_LOG)))):
        path = tmp_path / name
        result = slideid.identify(logs, report=str(path))
        assert result.e_t_mu.verdict == "ok"
        html = path.read_text(encoding="utf-8")
        for section in ("estimates", "check", "correlation", "trace", "logs", "run"):
            assert f'<section id="{section}">' in html
        assert "default_push.csv" in html
        assert "://" not in html and "<script" not in html
