"""One settings object for every way an identification is asked for (issue 31, item 2)."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from emaphm.choices import LAST_STAGES, OPTIMIZERS, UQ_METHODS
from emaphm.errors import InputError
from emaphm.identification.settings import IdentifySettings


def test_defaults_are_the_papers_method_with_our_stages():
    s = IdentifySettings()
    assert (s.optimizer, s.seed, s.polish, s.second_search, s.last_stage, s.uncertainty) == (
        "ga",
        0,
        True,
        True,
        "auto",
        "laplace",
    )
    assert s.error_corner == "auto" and s.monitor is None and s.pop_size is None


@pytest.mark.parametrize(
    ("change", "says"),
    [
        ({"optimizer": "sgd"}, "unknown optimizer 'sgd'"),
        ({"last_stage": "fast"}, "unknown last_stage 'fast'"),
        ({"uncertainty": "bootstrap"}, "unknown uncertainty"),
        ({"monitor": "ours"}, "unknown monitor"),
        ({"slope_unit": "min"}, "unknown slope_unit"),
        ({"seed": -1}, "seed must be a whole number"),
        ({"seed": 1.5}, "seed must be a whole number"),
        ({"seed": True}, "seed must be a whole number"),
        ({"pop_size": 3}, "pop_size must be at least 4"),
        ({"generations": 0}, "generations must be at least 1"),
        ({"polish": "yes"}, "polish must be true or false"),
        ({"error_corner": -2.0}, "error_corner must be"),
        ({"error_corner": "fast"}, "error_corner must be"),
        ({"rtol": 2.0}, "rtol must be"),
        ({"workers": -1}, "workers must be"),
    ],
)
def test_a_bad_setting_is_refused_in_one_line(change, says):
    with pytest.raises(InputError, match=says) as info:
        IdentifySettings(**change)
    assert "\n" not in str(info.value)


def test_the_choices_are_the_choice_lists():
    for name, choices in (
        ("optimizer", OPTIMIZERS),
        ("last_stage", LAST_STAGES),
        ("uncertainty", UQ_METHODS),
    ):
        field = next(f for f in dataclasses.fields(IdentifySettings) if f.name == name)
        assert field.metadata["choices"] is choices
        for value in choices:
            assert getattr(IdentifySettings(**{name: value}), name) == value


def test_error_corner_text_and_off_read_as_on_the_command_line():
    assert IdentifySettings(error_corner="off").error_corner is None
    assert IdentifySettings(error_corner="3.5").error_corner == 3.5
    assert IdentifySettings(error_corner=2).error_corner == 2.0
    assert IdentifySettings(error_corner=None).error_corner is None


def test_mapping_toml_and_json_round_trip(tmp_path):
    s = IdentifySettings(optimizer="de", seed=7, pop_size=16, polish=False, error_corner="off")
    assert IdentifySettings.from_mapping(s.to_json()) == s
    fields = s.to_json()
    assert {k: fields[k] for k in ("optimizer", "seed", "pop_size", "polish", "error_corner")} == {
        "optimizer": "de",
        "seed": 7,
        "pop_size": 16,
        "polish": False,
        "error_corner": None,
    }
    assert fields["generations"] is None and fields["last_stage"] == "auto"  # the rest their defaults
    path = tmp_path / "s.toml"
    path.write_text(
        '[identify]\noptimizer = "de"\nseed = 7\npop_size = 16\npolish = false\nerror_corner = "off"\n'
    )
    assert IdentifySettings.from_toml(path) == s
    with pytest.raises(InputError, match=r"unknown key.*speed.*known: optimizer"):
        IdentifySettings.from_mapping({"speed": 2}, where="c.toml [identify]")
    path.write_text("[identify]\npopsize = 16\n")
    with pytest.raises(InputError, match=r"s\.toml: unknown key\(s\) popsize"):
        IdentifySettings.from_toml(path)


def test_options_over_settings_and_frozen():
    base = IdentifySettings(seed=3, optimizer="pso")
    s = IdentifySettings.resolve(base, {"seed": 4})
    assert (s.seed, s.optimizer, base.seed) == (4, "pso", 3)
    assert IdentifySettings.resolve(None, {}) == IdentifySettings()
    with pytest.raises(InputError, match=r"unknown key.*local_polish"):
        IdentifySettings.resolve(None, {"local_polish": False})
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.seed = 5  # type: ignore[misc]


def test_the_settings_module_loads_without_numpy():
    code = "import sys, emaphm.identification.settings; print('numpy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_a_result_records_its_settings_its_constants_and_each_stage(monkeypatch):
    from emaphm import identify
    from emaphm.identification import limits

    monkeypatch.setattr(limits, "POLISH_BUDGET", (8, 2))
    monkeypatch.setattr(limits, "SWITCHING_ITERATIONS", 1)  # the last stage runs, at its least cost
    res = identify([0.2, 0, 0, 0, 0, 0, 0, 0.5], seed=2, pop_size=8, generations=2, uncertainty="none")
    record = res.settings
    assert record["limits"]["SWITCHING_ITERATIONS"] == 1 and res.stage("last_stage")["switching"] is not None
    assert (
        record["identify"]
        == IdentifySettings(seed=2, pop_size=8, generations=2, uncertainty="none").to_json()
    )
    assert (
        record["limits"]["POLISH_BUDGET"] == [8, 2]
        and record["limits"]["FIT_NRMSE_LIMIT"] == limits.FIT_NRMSE_LIMIT
    )
    names = [r["stage"] for r in record["stages"]]
    assert names == [
        "search",
        "polish",
        "final_checks",
        "least_squares",
        "fit",
        "second_search",
        "last_stage",
    ]
    assert res.stage("search")["evaluations"] <= res.evaluations
    # the final fit is the switching model's when the last stage ran, the search's measured fit otherwise
    switching = res.stage("last_stage")["switching"]
    ran = switching is not None and "error" not in switching
    assert res.fit_nrmse == pytest.approx(
        switching["fit_nrmse"] if ran else res.stage("fit")["fit_nrmse"], abs=1e-6
    )
    # the same with the settings object instead of keywords
    again = identify([0.2, 0, 0, 0, 0, 0, 0, 0.5], settings=IdentifySettings(seed=2, pop_size=8, generations=2,
                                                                            uncertainty="none"))  # fmt: skip
    np.testing.assert_array_equal(again.estimate, res.estimate)


def test_a_time_axis_that_does_not_increase_is_refused_everywhere():
    # review L1: ten samples in reverse order were accepted and the reference moved by 6 mA
    import emaphm
    from emaphm.identification.identifier import FaultIdentifier
    from emaphm.results import SimResult

    trace = emaphm.simulate([0.1, 0, 0, 0, 0, 0, 0, 0.5], duration=0.3)
    t = trace.t.copy()
    t[100:110] = t[100:110][::-1]
    with pytest.raises(InputError, match=r"time axis must increase strictly; sample 10[0-9]"):
        FaultIdentifier(pop_size=8, generations=1).fit(t, trace.i_q)
    with pytest.raises(InputError, match="time axis must increase strictly"):
        SimResult(t, dict(trace.signals))
    t[100] = t[99]  # a repeated time
    with pytest.raises(InputError, match="sample 100 is at or before"):
        FaultIdentifier(pop_size=8, generations=1).fit(t, trace.i_q)


def test_fault_identifier_takes_the_monitor_by_name_or_as_a_model():
    # docs/conventions.md: `monitor` is which monitor model, by name or as a MonitorEma
    from emaphm.identification.identifier import FaultIdentifier
    from emaphm.models import MonitorEma

    assert FaultIdentifier(monitor="paper").settings.monitor == "paper"
    assert FaultIdentifier(IdentifySettings(monitor="paper")).monitor is None  # built from the name
    with pytest.raises(InputError, match="monitor 'paper' was asked for, the MonitorEma given is 'default'"):
        FaultIdentifier(IdentifySettings(monitor="paper"), monitor=MonitorEma())


def test_the_budget_and_the_progress_in_words():
    from emaphm.identification.settings import budget_text, search_progress_label

    assert budget_text("ga", None, None) == "96 × 40 generations"  # the optimiser's default
    assert budget_text("ga", 16, 3) == "16 × 3 generations"
    assert budget_text("multistart", None, 4) == "a sample of 256 points, 4 least-squares descents"
    assert search_progress_label("multistart") == "least-squares descents"
    assert search_progress_label("de") == "DE generations"
