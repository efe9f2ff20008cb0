"""slideid.advise_push gives what advise-push prints with --json."""

import json

import pytest

import slideid
from conftest import run_tool

SMALL = {"patch": "rectangle 0.09 0.09", "mass": 0.8, "contact_points": 4,
         "cone_fractions": "-0.5,0.5", "lengths": "0.05", "candidates": 3}


def test_advise_push_equals_the_tools_json():
    advice = slideid.advise_push(**SMALL)
    code, out, err = run_tool("advise-push", "--patch", "rectangle 0.09 0.09", "--mass", "0.8",
                              "--contact-points", "4", "--cone-fractions", "-0.5,0.5",
                              "--lengths", "0.05", "--candidates", "3", "--json")
    assert code == 0, err
    assert advice == json.loads(out)
    assert advice["candidates"] == 8
    assert len(advice["ranking"]) == 3
    scores = [c["score"] for c in advice["ranking"]]
    assert scores == sorted(scores)
    known = advice["known"]["e_t_mu"]
    assert known["from"] == "prior"
    assert advice["ranking"][0]["relative_stderr_after"][0] < known["relative_stderr"]


def test_advise_push_reads_a_result(tmp_path):
    result = {name: {"identifiable": True, "value": value, "stderr": stderr}
              for name, value, stderr in [("e_t_mu", 0.4, 0.004), ("e_o_over_e_t", 1.3, 0.05),
                                          ("e_r_over_e_t", 0.03, 0.003)]}
    path = tmp_path / "result.json"
    path.write_text(json.dumps(result))
    advice = slideid.advise_push(friction=path, criterion="d-optimal", **SMALL)
    assert advice["criterion"] == "d-optimal"
    assert advice["known"]["e_r_over_e_t"]["from"] == "estimate"
    assert advice["known"]["e_r_over_e_t"]["relative_stderr"] == pytest.approx(0.1)


def test_advise_push_bad_options_name_the_keyword():
    with pytest.raises(slideid.OptionError, match="criterion"):
        slideid.advise_push(patch="disk 0.05", criterion="best")
    with pytest.raises(slideid.OptionError, match="patch"):
        slideid.advise_push(mass=1.0)
    with pytest.raises(TypeError, match="advise_push"):
        slideid.advise_push(patch="disk 0.05", colour="red")
