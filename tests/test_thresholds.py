"""Failure thresholds from the HF twin and requirements (emaphm.prognostics.thresholds, 'emaphm thresholds')."""

import json
import math
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from emaphm import ControllerParams, EmaParams, InputError, TransmissionParams, apply_faults, simulate
from emaphm.actuator import load_thresholds, params_template
from emaphm.faults import HEALTHY
from emaphm.prognostics import (
    PLACEHOLDER_THRESHOLDS,
    Requirement,
    derive_thresholds,
    parse_requirement,
    thresholds_toml,
)
from emaphm.prognostics.threshold_search import check_monotone
from tests.helpers import run_cli

DEG = math.pi / 180.0
RESOLUTION = 0.01  # coarser than the default 0.005: fewer bisection steps, the same checks


@cache
def derived(requirements: tuple[str, ...], faults: tuple[str, ...]) -> dict:
    return derive_thresholds(list(requirements), faults=list(faults), resolution=RESOLUTION)


def tracking_error(fault: str, d: float) -> float:
    """max |θ_u − θ_cmd| on the chirp, the fault `fault` at distance d (k8 below 0.5 for kp_drift)."""
    k = np.array(HEALTHY)
    if fault == "kp_drift":
        k[7] = 0.5 - d
    else:
        k[{"friction": 0, "backlash": 1}[fault]] = d
    r = simulate(k, noise=False)
    return float(np.max(np.abs(r.theta_u_true - r.theta_cmd)))


def load_thresholds_of(result: dict) -> dict:
    """The thresholds `load_thresholds` reads from an actuator file with the result's table pasted in."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "actuator.toml"
        path.write_text(params_template() + "\n" + thresholds_toml(result), encoding="utf-8")
        return load_thresholds(path)


def test_requirements_are_parsed_with_their_units():
    assert parse_requirement("tracking=0.5deg").limit == pytest.approx(0.5 * DEG)
    assert parse_requirement("tracking = 2 mrad").limit == pytest.approx(2e-3)
    assert parse_requirement("tracking_rms=0.004").limit == 0.004  # a bare number is SI
    assert parse_requirement("free_play=30 arcmin").limit == pytest.approx(0.5 * DEG)
    assert parse_requirement("current=8000 mA").limit == pytest.approx(8.0)
    assert parse_requirement("current=I_max").limit == 10.0
    small = EmaParams(controller=ControllerParams(I_max=4.0))
    assert parse_requirement("current=0.9 I_max", params=small).limit == pytest.approx(3.6)
    req = parse_requirement("tracking=1.5deg")
    assert req.show(req.limit) == "1.5 deg" and req.text == "1.5deg"


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("speed=1", "unknown requirement 'speed'"),
        ("tracking=1 A", "unit 'A' is not one for tracking"),
        ("tracking=-0.5deg", "number > 0"),
        ("current=0", "number > 0"),
        ("tracking", "KIND=LIMIT"),
        ("tracking=I_max", "I_max is a current"),
        ("current=12 A", "above I_max"),
        ("current=1.5 I_max", "above I_max"),
    ],
)
def test_bad_requirements_are_refused(text, reason):
    with pytest.raises(InputError, match=reason):
        parse_requirement(text, params=EmaParams())


def test_free_play_maps_to_backlash_in_closed_form_without_a_simulation():
    params = EmaParams(transmission=TransmissionParams(B0=3e-4))
    result = derive_thresholds(["free_play=1.5 mrad"], params=params, faults=["backlash", "friction"])
    assert result["simulations"] == 0
    backlash = result["faults"]["backlash"]
    assert backlash["threshold"] == pytest.approx((1.5e-3 / 3e-4 - 1.0) / 99.0, rel=1e-12)
    assert backlash["limited_by"] == "free_play" and backlash["status"] == "derived"
    k = np.array(HEALTHY)
    k[1] = backlash["threshold"]
    assert apply_faults(k, params).B == pytest.approx(1.5e-3, rel=1e-12)  # the mapping, inverted
    friction = result["faults"]["friction"]
    assert friction["threshold"] is None and "no requirement" in friction["status"]
    assert friction["rul_placeholder"] == PLACEHOLDER_THRESHOLDS["friction"]
    json.dumps(result)  # JSON-ready

    beyond = derive_thresholds(["free_play=0.1 rad"], faults=["backlash"])["faults"]["backlash"]
    assert beyond["threshold"] is None and "end of its range" in beyond["status"]
    with pytest.raises(
        InputError, match=r"free_play = 0.1 mrad: the healthy actuator already reaches 0.2 mrad"
    ):
        derive_thresholds(["free_play=0.1 mrad"], faults=["backlash"])


def test_a_tracking_threshold_agrees_with_the_twin_either_side():
    limit = 1.55 * DEG
    result = derived(("tracking=1.55deg",), ("backlash",))
    f = result["faults"]["backlash"]
    d = f["threshold"]
    assert f["status"] == "derived" and f["limited_by"] == "tracking" and 0.05 < d < 0.5
    assert f["at_threshold"]["tracking"] >= limit > f["healthy"]["tracking"]
    assert d - RESOLUTION <= f["met_below"] < d
    assert tracking_error("backlash", d - RESOLUTION) < limit  # met just below
    assert tracking_error("backlash", d) >= limit
    assert tracking_error("backlash", d + RESOLUTION) >= limit  # broken just above
    assert f["monotone"] == {"tracking": True} and result["warnings"] == []


@pytest.mark.parametrize("fault", ["backlash", "kp_drift"])
def test_a_looser_requirement_gives_a_larger_or_equal_threshold(fault):
    strict = derived(("tracking=1.55deg",), (fault,))["faults"][fault]["threshold"]
    loose = derived(("tracking=1.65deg",), (fault,))["faults"][fault]["threshold"]
    assert strict is not None and loose is not None
    assert loose >= strict + RESOLUTION  # measurably later, not only "not earlier"


def test_the_gain_drift_takes_its_worse_direction_per_requirement():
    low = derived(("tracking=1.55deg",), ("kp_drift",))["faults"]["kp_drift"]
    assert low["case"] == "k8 = 0.5 - d"  # a sagging gain tracks worse
    assert tracking_error("kp_drift", low["threshold"]) >= 1.55 * DEG
    high = derived(("current=0.6 A",), ("kp_drift",))["faults"]["kp_drift"]
    assert high["case"] == "k8 = 0.5 + d"  # a higher gain demands more current
    assert 0 < high["threshold"] <= 0.5


def test_a_fault_that_reaches_no_limit_has_no_threshold():
    result = derive_thresholds(["current=I_max"], faults=["friction"], resolution=0.05)
    f = result["faults"]["friction"]
    assert f["threshold"] is None and f["limited_by"] is None
    assert f["status"] == "no requirement reached up to k1 = 1, the end of its range"
    assert len(f["grid"]["distance"]) == 10 and max(f["grid"]["current"]) < 10.0
    assert "friction" not in load_thresholds_of(result)


def test_a_healthy_actuator_that_breaks_a_requirement_is_refused():
    with pytest.raises(
        InputError, match=r"tracking = 0.5 deg: the healthy actuator already reaches 1.4\d* deg"
    ):
        derive_thresholds(["tracking=0.5 deg"], faults=["friction"])
    with pytest.raises(InputError, match="given twice"):
        derive_thresholds(["tracking=2deg", Requirement("tracking", 0.05)])
    with pytest.raises(InputError, match="at least one requirement"):
        derive_thresholds([])
    with pytest.raises(InputError, match="unknown fault"):
        derive_thresholds(["tracking=2deg"], faults=["eccentricity_phase"])


def test_the_toml_table_reads_back_through_load_thresholds():
    result = derived(("tracking=1.55deg",), ("backlash",))
    free_play = derive_thresholds(["free_play=1.5mrad"], faults=["backlash", "short_a"])
    text = thresholds_toml(free_play)
    assert "[thresholds]" in text and "# limited by free_play < 1.5mrad (1.5 mrad there)" in text
    assert "no threshold derived" in text and "short_a" in text.splitlines()[3]  # left out, named
    for res in (result, free_play):
        read = load_thresholds_of(res)
        assert set(read) == {"backlash"}
        d = res["faults"]["backlash"]["threshold"]
        assert d - res["resolution"] <= read["backlash"] <= d  # rounded down to the resolution's decimals


def test_a_fall_of_a_metric_on_the_grid_is_a_warning():
    req = Requirement("tracking", 0.1)
    warnings: list[str] = []
    flags = check_monotone(
        "eccentricity", [0.0, 0.5, 1.0], [req], {"tracking": [0.02, 0.03, 0.025]}, warnings
    )
    assert flags == {"tracking": False} and "eccentricity: tracking is not monotone" in warnings[0]
    assert check_monotone("friction", [0.0, 0.5], [req], {"tracking": [0.02, 0.01999]}, []) == {
        "tracking": True
    }


def test_cli_thresholds_writes_a_table_and_refuses_bad_input(tmp_path, capsys):
    out = tmp_path / "thresholds.toml"
    args = ["thresholds", "--require", "free_play=1.5mrad", "--fault", "backlash"]
    code, stdout, _ = run_cli([*args, "--json", "-o", str(out)], capsys)
    assert code == 0
    data = json.loads(stdout)
    assert data["faults"]["backlash"]["limited_by"] == "free_play"
    (tmp_path / "a.toml").write_text(params_template() + "\n" + out.read_text(encoding="utf-8"))
    assert load_thresholds(tmp_path / "a.toml") == {"backlash": 0.065}  # (7.5 - 1)/99 = 0.06566, down
    code, stdout, _ = run_cli(args, capsys)
    assert code == 0 and "backlash" in stdout and "free_play" in stdout

    for bad, reason in [
        ([], "give at least one --require"),
        (["--require", "speed=2"], "unknown requirement"),
        (["--require", "tracking=2 furlong"], "unit 'furlong'"),
        (["--require", "tracking=-2deg"], "number > 0"),
        (["--require", "tracking=0.5deg", "--fault", "friction"], "healthy actuator already reaches"),
        (["--require", "tracking=2deg", "-o", str(tmp_path / "t.txt")], "unsupported file type"),
    ]:
        output = [] if "-o" in bad else ["-o", str(tmp_path / "new.toml")]
        code, _, err = run_cli(["thresholds", *bad, *output], capsys)
        assert code == 2 and reason in err and len(err.strip().splitlines()) == 1, (bad, err)
        assert not (tmp_path / "new.toml").exists()  # nothing written on error
