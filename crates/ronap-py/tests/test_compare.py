"""ronap.compare: the same figures as ``ronap compare``, from Python."""

import json
import pathlib

import pytest

import ronap
from helpers import toward_goal


def test_compare_returns_policies_pairs_and_writes_the_report(tmp_path):
    out = tmp_path / "cmp"
    result = ronap.compare(["apf", "geodesic"], range(12), out=str(out), by_difficulty=True)
    assert "10 px" in result["success_rule"]
    apf, geodesic = result["policies"]
    assert (apf["label"], geodesic["label"]) == ("apf", "geodesic")
    assert geodesic["summary"]["success_rate"] == 1.0
    (pair,) = result["pairs"]
    assert pair["a_only"] == 0 and pair["b_only"] == 12 - apf["summary"]["successes"]
    assert 0.0 <= pair["mcnemar_p"] <= 1.0
    assert len(result["by_difficulty"]) == 3
    # The dict holds what compare.json holds.
    on_disk = json.loads((out / "compare.json").read_text())
    assert on_disk["pairs"] == result["pairs"]
    for name in ["report.md", "report.html", "compare.png", "outcomes.png", "seeds.csv"]:
        assert (out / name).is_file(), name
    assert (out / "runs" / "apf" / "episodes.csv").is_file()


def test_a_python_policy_against_a_builtin_and_identical_twins():
    result = ronap.compare([toward_goal, "apf", "apf"], range(10), thread_safe=True)
    labels = [p["label"] for p in result["policies"]]
    assert labels == ["toward_goal", "apf", "apf-2"]
    twins = result["pairs"][2]
    assert (twins["a"], twins["b"]) == ("apf", "apf-2")
    assert twins["mcnemar_p"] == 1.0 and twins["spl_diff"] == 0.0


def test_dataframes_when_pandas_is_installed():
    pandas = pytest.importorskip("pandas")
    result = ronap.compare(["apf", "geodesic"], range(6))
    frame = result["frame"]
    assert isinstance(frame, pandas.DataFrame)
    assert list(frame.index) == ["apf", "geodesic"]
    assert frame.loc["geodesic", "success_rate"] == 1.0
    assert "success_ci95_low" in frame.columns
    assert len(result["pairs_frame"]) == 1


def test_bad_input_is_a_ronap_error(tmp_path):
    with pytest.raises(ronap.ConfigError, match="at least two"):
        ronap.compare(["apf"], range(3))
    with pytest.raises(ronap.ConfigError, match="nope"):
        ronap.compare(["apf", "nope"], range(3))
    with pytest.raises(ronap.RonapError, match="no_such_run"):
        ronap.compare(["apf", "geodesic"], range(3), runs=[str(tmp_path / "no_such_run")])


def test_repeated_seeds_and_too_few_resamples_are_refused():
    with pytest.raises(ronap.ConfigError, match="seed 1 is given twice"):
        ronap.compare(["apf", "geodesic"], [1, 2, 1])
    with pytest.raises(ronap.ConfigError, match="resamples = 0"):
        ronap.compare(["apf", "geodesic"], range(3), resamples=0)
