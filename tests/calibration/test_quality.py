"""`calibration.quality.judge`: a calibration's held-out NRMSE judged, and the outliers named."""

import pytest

from emaphm.calibration.quality import GOOD, POOR, UNEXPLAINED, judge, summary_lines


def record(*nrmse):
    return {"check_scenarios": [{"name": f"s{i}", "nrmse": v} for i, v in enumerate(nrmse)]}


@pytest.mark.parametrize(
    "values, verdict",
    [((0.01, 0.02, 0.03), "good"), ((0.02, 0.04, 0.05), "usable"), ((0.04, 0.06, 0.2), "poor")],
)
def test_the_median_held_out_nrmse_sets_the_verdict(values, verdict):
    q = judge(record(*values))
    assert q["verdict"] == verdict and q["median_nrmse"] == pytest.approx(sorted(values)[1])
    assert q["limits"] == {"good": GOOD, "poor": POOR, "unexplained": UNEXPLAINED}
    assert ("is poor" in summary_lines(q)[0]) == (verdict == "poor")


def test_outliers_are_named_without_moving_a_good_median():
    q = judge(record(0.01, 0.02, 0.02, 0.59, 0.11))
    assert q["verdict"] == "good"
    assert [u["name"] for u in q["unexplained"]] == ["s3", "s4"]
    lines = summary_lines(q)
    assert len(lines) == 2 and "s3 (59 %)" in lines[1] and "s4 (11 %)" in lines[1]


def test_a_record_without_held_out_scenarios_is_unknown():
    assert judge({})["verdict"] == "unknown" and summary_lines(judge({})) == ["quality: unknown (no held-out scenarios)"]
