"""slideid.predict and slideid.validate give what the tools print with --json."""

import json

import pytest

import slideid
from conftest import run_tool


def pushed_square(angle_x, angle_y, offset):
    """A 90 mm square pushed 50 mm by a round tip, logged at 100 Hz with noise."""
    return {
        "slider": {"mass": 0.837, "inertia": 1.13e-3, "com_height": 0.0065},
        "friction": {"mu": 0.3, "e_t": 1, "e_o": 1.2, "e_r": 0.035},
        "patch": {"shape": "rectangle", "width": 0.09, "length": 0.09},
        "initial": {"x": 0, "y": 0, "theta": 0},
        "pusher": {"point": f"-0.045 {offset}", "direction": f"{angle_x} {angle_y}",
                   "distance": 0.05, "speed": 0.05, "mu": 0.3},
        "sim": {"dt": 0.001, "log_every": 10},
    }


@pytest.fixture(scope="module")
def push_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pushes")
    paths = []
    for k, (ax, ay, offset) in enumerate([(1, 0.2, -0.02), (1, 1.2, 0.0), (1, -0.5, 0.015),
                                          (1, 0.8, -0.01)]):
        log = slideid.simulate(pushed_square(ax, ay, offset), write="poses", noise_pose=2e-4,
                               noise_angle=2e-3, noise_force_relative=0.02, seed=k + 1)
        path = folder / f"push{k}.csv"
        slideid.write_log(log, path)
        paths.append(path)
    return folder, paths


def test_predict_equals_the_tools_json(push_files):
    _, paths = push_files
    args = ["--mu", "0.3", "--b", "1.2", "--c", "0.035", "--mu-pusher", "0.3", "--substeps", "10"]
    code, out, err = run_tool("predict", "--log", paths[0], "--json", *args)
    assert code == 0, err
    result = slideid.predict(paths[0], mu=0.3, b=1.2, c=0.035, mu_pusher=0.3, substeps=10)
    predicted = result.pop("predicted")
    assert result == json.loads(out)
    assert result["drive"] == "pusher"
    assert result["final_position_m"] < 1e-3
    assert predicted.rows == result["rows_predicted"]
    # A Log in memory predicts as its file does.
    again = slideid.predict(slideid.read_log(paths[0]), mu=0.3, b=1.2, c=0.035, mu_pusher=0.3,
                            substeps=10)
    again.pop("predicted")
    assert again == result


def test_predict_errors_name_what_is_missing(push_files):
    _, paths = push_files
    with pytest.raises(ValueError, match="mu_p"):
        slideid.predict(paths[0], mu=0.3, b=1.2, c=0.035)
    with pytest.raises(slideid.OptionError, match="drive"):
        slideid.predict(paths[0], mu=0.3, b=1.2, c=0.035, mu_pusher=0.3, drive="sideways")
    with pytest.raises(TypeError, match="colour"):
        slideid.predict(paths[0], colour="red")


def test_validate_equals_the_tools_json(push_files):
    folder, _ = push_files
    code, out, err = run_tool("validate", "--logs", folder, "--folds", "2", "--json",
                              folder / "v.json")
    assert code == 0, err
    cli = json.loads((folder / "v.json").read_text())
    result = slideid.validate(folder, folds=2)
    for data in (cli, result):
        data.pop("seconds")
    assert result == cli
    assert result["folds"] == 2
    methods = {m["method"]: m for m in result["methods"]}
    assert set(methods) == {"folds", "quasi-static", "own fit", "textbook"}
    assert methods["folds"]["failed"] == 0
