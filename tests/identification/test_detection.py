import numpy as np

from emaphm.faults import HEALTHY
from emaphm.identification.detection import DETECTABLE, detect, load_thresholds


def test_shipped_thresholds_are_measured_and_complete():
    data = load_thresholds()
    assert set(data["thresholds"]) == set(DETECTABLE) and "eccentricity_phase" not in DETECTABLE
    assert all(0 < v < 0.3 for v in data["thresholds"].values())
    assert data["runs"] >= 20 and data["false_alarm_runs"] <= 1  # the DESIGN §9 target
    assert len(data["healthy_estimates_check_set"]) == data["runs"]


def test_detection_rule():
    thresholds = {name: 0.05 for name in DETECTABLE}
    assert detect(HEALTHY, thresholds) == []
    k = np.array(HEALTHY)
    k[[0, 3]] = 0.2, 0.06
    k[6] = 0.9  # a phase alone is never a fault
    k[7] = 0.44  # gain drift counts either way from 0.5
    assert detect(k, thresholds) == ["friction", "short_b", "kp_drift"]
