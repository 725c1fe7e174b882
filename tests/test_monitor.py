"""The calibrated LF monitor model against the HF twin, and its calibration file."""

import dataclasses
import json

import numpy as np
import pytest

import emaphm
from emaphm import InputError, MonitorEma
from emaphm.calibration import (
    SURROGATE,
    Calibration,
    Coefficients,
    default_calibration,
    load_calibration,
    params_hash,
)
from emaphm.calibration.fit_monitor import calibrate
from emaphm.calibration.scenarios import (
    CALIBRATION_COMMANDS,
    CHECK_SCENARIOS,
    FIT_SCENARIOS,
    PAPER_CHECK_SCENARIOS,
    PAPER_FIT_SCENARIOS,
)
from emaphm.commands import make_command
from emaphm.identification import Comparison
from tests.helpers import faults

# DESIGN §4 target for the calibrated LF model against the HF twin (filtered i_q, noise off), on
# scenarios the calibration never saw: 5 % on the fitted commands (measured 0.7-2.9 %, the Table 1
# vector 2.7 %). The chirp run on to 2 s and the chirp with a hold are held out altogether; there
# the twin itself is chaotic (HF against HF with k1 + 1e-5: 1.7-4.4 %) and its own loop error
# larger (its demand against its current: 3.3-8.6 %), and the monitor measured 3.2-14.5 %
# (docs/theory/monitor-model.md §4): the bound there guards against a regression, no more.
NRMSE_TARGET = {"chirp": 0.05, "steps": 0.05, "chirp-2s": 0.16, "chirp-hold": 0.16}


def test_held_out_scenarios_are_not_fitted():
    for fit, check in ((FIT_SCENARIOS, CHECK_SCENARIOS), (PAPER_FIT_SCENARIOS, PAPER_CHECK_SCENARIOS)):
        fitted = {(s.faults, s.command) for s in fit}
        assert len(check) >= 8 and not any((s.faults, s.command) in fitted for s in check)
    # the default monitor is fitted on the chirp and the steps, and checked on every command
    assert {s.command for s in FIT_SCENARIOS} == {"chirp", "steps"}
    assert {s.command for s in CHECK_SCENARIOS} == set(CALIBRATION_COMMANDS)


def test_the_paper_monitor_is_the_same_model_without_its_loop_surrogate():
    paper = MonitorEma(monitor="paper")
    c = paper.calibration.coefficients
    assert paper.monitor == "paper" and all(getattr(c, n) == 0.0 for n in SURROGATE)
    assert MonitorEma().monitor == "default" and MonitorEma().calibration.coefficients.delta_0 > 0
    assert paper.calibration.record["settings"]["fitted"] == [
        "k_FS",
        "k_E",
        "k_t_eq",
        "k_e_eq",
        "J_eq",
        "tau_i",
    ]
    # and it gives another current than the default monitor on a multi-fault actuator
    k = faults(k1=0.2, k3=0.2, k4=0.3)
    assert not np.allclose(paper.simulate(k).i_q, MonitorEma().simulate(k).i_q)
    # the surrogate switched off in the default coefficients is the paper's structure, bit for bit
    coeffs = dataclasses.replace(c, V_H=0.02)
    np.testing.assert_array_equal(
        MonitorEma(calibration=Calibration(coeffs)).simulate(k).i_q, paper.simulate(k).i_q
    )


def test_the_monitors_rows_are_monitor_rows_and_follow_a_replaced_calibration():
    # MonitorEma.rows keeps the fields the faults do not set in one row per actuator and calibration
    from emaphm.models.lf import monitor_rows

    rng = np.random.default_rng(3)
    monitor, paper = MonitorEma(), MonitorEma(monitor="paper")

    def rows_of(m, K):
        cal = m.calibration
        return monitor_rows(K, m.params, [cal.coefficients], cal.n_lf, cal.monitor)

    for m in range(1, 12):
        K = rng.uniform(size=(m, 8))
        assert np.array_equal(monitor.rows(K), rows_of(monitor, K))
    K = rng.uniform(size=(3, 8))
    before = monitor.rows(K)
    monitor.calibration = paper.calibration
    assert np.array_equal(monitor.rows(K), rows_of(paper, K)) and not np.array_equal(monitor.rows(K), before)


def test_a_monitor_choice_that_does_not_match_the_calibration_is_refused(tmp_path):
    with pytest.raises(InputError, match="unknown monitor"):
        MonitorEma(monitor="three-phase")
    path = default_calibration("paper").save(tmp_path / "paper.json")
    assert MonitorEma(calibration=path).monitor == "paper"
    with pytest.raises(InputError, match="for the 'paper' monitor, not 'default'"):
        MonitorEma(calibration=path, monitor="default")
    with pytest.raises(InputError, match="monitor model only"):
        emaphm.simulate(emaphm.HEALTHY, monitor="paper", duration=0.01)


@pytest.mark.parametrize("scenario", CHECK_SCENARIOS, ids=lambda s: s.name)
def test_calibrated_lf_matches_hf_on_held_out_scenarios(scenario):
    command = CALIBRATION_COMMANDS[scenario.command]
    hf = emaphm.simulate(scenario.faults, noise=False, command=command)
    lf = emaphm.simulate(scenario.faults, model="lf", noise=False, command=command)
    np.testing.assert_array_equal(lf.t, hf.t)
    ref = Comparison.from_signal(hf.t, hf.i_q, 1e4)
    assert ref.nrmse(lf.i_q) < NRMSE_TARGET[scenario.command]


def test_uncalibrated_lf_is_worse_on_shorts():
    # the calibration is what makes the short-circuit shape function fit (k_FS: 1 -> ~80);
    # measured NRMSE 2.5 % calibrated against 4.7 % with the first-guess coefficients
    k = faults(k3=0.3)
    hf = emaphm.simulate(k, noise=False)
    ref = Comparison.from_signal(hf.t, hf.i_q, 1e4)
    calibrated = ref.nrmse(MonitorEma().simulate(k).i_q)
    first_guess = ref.nrmse(MonitorEma(calibration=Calibration(Coefficients())).simulate(k).i_q)
    assert calibrated < 0.85 * first_guess


def test_lf_result_has_the_hf_signal_names():
    r = emaphm.simulate(faults(k1=0.2), model="lf", noise=False, duration=0.1)
    for name in ("t", "theta_cmd", "theta_u", "i_q"):
        assert r[name].shape == r.t.shape
    assert r.metadata["model"] == "lf"
    assert r.metadata["calibration"]["coefficients"]["k_FS"] == default_calibration().coefficients.k_FS
    assert np.max(np.abs(r.i_q)) > 0.05


def test_lf_noise_is_seeded():
    a = emaphm.simulate(emaphm.HEALTHY, model="lf", noise=True, seed=1, duration=0.1)
    b = emaphm.simulate(emaphm.HEALTHY, model="lf", noise=True, seed=1, duration=0.1)
    c = emaphm.simulate(emaphm.HEALTHY, model="lf", noise=True, seed=2, duration=0.1)
    np.testing.assert_array_equal(a.i_q, b.i_q)
    assert not np.array_equal(a.i_q, c.i_q)


def test_fault_matrix_validation():
    with pytest.raises(InputError, match="row 1"):
        MonitorEma().simulate_many([[0.0] * 8, [0.0] * 7 + [2.0]])
    with pytest.raises(InputError, match="shape"):
        MonitorEma().simulate_many(np.zeros((3, 7)))


# ---- the calibration file ---------------------------------------------------------------------


def test_packaged_calibration_is_complete():
    # schema only: the LF-vs-HF figures are checked live above, not read from this file
    for monitor, fit, check in (
        ("default", FIT_SCENARIOS, CHECK_SCENARIOS),
        ("paper", PAPER_FIT_SCENARIOS, PAPER_CHECK_SCENARIOS),
    ):
        cal = default_calibration(monitor)
        for key in ("seed", "package_version", "fit_scenarios", "check_scenarios", "settings", "versions"):
            assert key in cal.record
        assert cal.monitor == monitor
        assert [(s["name"], s["command"]) for s in cal.record["fit_scenarios"]] == [
            (s.name, s.command) for s in fit
        ]
        assert [(s["name"], s["command"]) for s in cal.record["check_scenarios"]] == [
            (s.name, s.command) for s in check
        ]
        assert all(isinstance(s["nrmse"], float) for s in cal.record["check_scenarios"])
        assert cal.params_hash == params_hash(emaphm.EmaParams())


def test_calibration_round_trip(tmp_path):
    cal = Calibration(Coefficients(k_FS=12.5, tau_i=5e-5), 2, {"seed": 3, "note": "x"})
    back = load_calibration(cal.save(tmp_path / "c.json"))
    assert back == cal


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ("{not json", "corrupt"),
        ('{"format": "other"}', "not an emaphm"),
        ('{"format": "emaphm-lf-calibration", "format_version": 99}', "format version"),
        ('{"format": "emaphm-lf-calibration", "format_version": 2}', "older emaphm.*calibrate again"),
    ],
)
def test_bad_calibration_files(tmp_path, content, match):
    (tmp_path / "c.json").write_text(content)
    with pytest.raises(InputError, match=match):
        load_calibration(tmp_path / "c.json")


def test_older_calibration_formats_read_as_the_monitor_without_what_they_lack(tmp_path):
    # version 3 files predate i_R and i_D, version 4 files i_D: the same model with those at 0,
    # so they keep giving their results
    data = Calibration(Coefficients(k_FS=12.5), 1).to_json()
    del data["coefficients"]["i_R"], data["coefficients"]["i_D"]
    (tmp_path / "c.json").write_text(json.dumps({**data, "format_version": 3}))
    assert load_calibration(tmp_path / "c.json").coefficients == Coefficients(k_FS=12.5, i_R=0.0, i_D=0.0)
    data = Calibration(Coefficients(k_FS=12.5, i_R=0.05), 1).to_json()
    del data["coefficients"]["i_D"]
    (tmp_path / "c.json").write_text(json.dumps({**data, "format_version": 4}))
    assert load_calibration(tmp_path / "c.json").coefficients == Coefficients(k_FS=12.5, i_R=0.05, i_D=0.0)
    # the current version must name them
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="coefficients must be"):
        load_calibration(tmp_path / "c.json")


def test_calibration_with_bad_coefficients(tmp_path):
    data = Calibration().to_json()
    data["coefficients"]["k_t_eq"] = 5.0
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="k_t_eq"):
        load_calibration(tmp_path / "c.json")
    del data["coefficients"]["k_E"]
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="coefficients must be"):
        load_calibration(tmp_path / "c.json")


def test_missing_calibration_file(tmp_path):
    with pytest.raises(InputError, match="no such calibration file"):
        load_calibration(tmp_path / "none.json")


def test_small_calibration_is_seeded_and_recorded():
    a = calibrate(seed=4, pop_size=6, generations=2, fit=FIT_SCENARIOS[:2], check=CHECK_SCENARIOS[:1])
    b = calibrate(seed=4, pop_size=6, generations=2, fit=FIT_SCENARIOS[:2], check=CHECK_SCENARIOS[:1])
    assert a.coefficients == b.coefficients
    assert a.record["seed"] == 4 and a.record["settings"]["evaluations"] == 12
    assert [s["name"] for s in a.record["check_scenarios"]] == [CHECK_SCENARIOS[0].name]
    assert a.record["ga_history"][-1] <= a.record["ga_history"][0]


def test_a_paper_calibration_fits_only_the_papers_coefficients():
    cal = calibrate(
        monitor="paper",
        seed=4,
        pop_size=6,
        generations=1,
        fit=PAPER_FIT_SCENARIOS[:1],
        check=PAPER_CHECK_SCENARIOS[:1],
    )
    c = cal.coefficients
    assert cal.monitor == "paper" and all(getattr(c, n) == 0.0 for n in SURROGATE)
    with pytest.raises(InputError, match="unknown monitor"):
        calibrate(monitor="other", pop_size=6, generations=1)


def test_a_calibration_file_must_say_a_known_monitor_and_a_paper_one_has_no_surrogate(tmp_path):
    data = default_calibration("paper").to_json()
    for bad, match in (([1], "unknown monitor"), ("three-phase", "unknown monitor")):
        (tmp_path / "c.json").write_text(json.dumps({**data, "monitor": bad}))
        with pytest.raises(InputError, match=match):
            load_calibration(tmp_path / "c.json")
    data["coefficients"]["delta_0"] = 0.01
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="has no loop surrogate"):
        load_calibration(tmp_path / "c.json")


def test_a_calibration_can_name_its_own_commands():
    from emaphm.calibration.scenarios import Scenario
    from emaphm.commands import Sine

    rig = {"rig": Sine(amplitude=0.01, frequency=3.0, duration=0.3)}
    fit = [Scenario("healthy on the rig", emaphm.HEALTHY, "rig")]
    cal = calibrate(seed=2, pop_size=4, generations=1, fit=fit, check=fit, commands=rig)
    assert list(cal.commands()) == ["rig"] and cal.commands()["rig"] == rig["rig"]
    with pytest.raises(InputError, match="unknown command 'rig'"):
        calibrate(pop_size=4, generations=1, fit=fit, check=[])
    with pytest.raises(InputError, match="at least one fitting scenario"):
        calibrate(pop_size=4, generations=1, fit=[], check=[], commands=rig)


@pytest.mark.parametrize(("amplitude", "dead"), [(0.0004, True), (0.0015, False)])
def test_the_loop_rests_at_standstill_while_the_demand_stays_inside_its_band(amplitude, dead):
    # the twin's comparators: a stuck motor (no back-EMF) whose demand lies inside every phase's
    # band h carries no current at all (a zero vector); a demand outside it is followed. The
    # monitor's dead zone (i_D = h/2, the twin's half-band) does the same; without it the monitor
    # carries the demand
    cmd = make_command("step", amplitude=amplitude, t_0=0.002, duration=0.03)
    k = np.array([0.5, 0, 0, 0, 0, 0, 0.5, 0.5])  # friction high enough to hold the motor
    hf = emaphm.HighFidelityEma(None, cmd).simulate(k, noise=False)
    late = hf.t > 0.01
    assert np.all(hf.omega_m == 0.0)
    demand = np.mean(np.abs(hf.i_q_ref[late]))
    assert 0.015 < demand < 0.12
    cal = default_calibration()
    with_zone, without = (
        MonitorEma(
            None, cmd, dataclasses.replace(cal, coefficients=dataclasses.replace(cal.coefficients, i_D=i_D))
        )
        .simulate(k)
        .i_q[late]
        for i_D in (0.5 * emaphm.EmaParams().inverter.h, 0.0)
    )
    assert np.mean(np.abs(without)) > 0.7 * demand
    if dead:
        assert np.max(np.abs(hf.i_q[late])) < 0.002
        assert np.max(np.abs(with_zone)) < 0.002
    else:
        assert np.mean(np.abs(hf.i_q[late])) > 0.7 * demand
        assert np.mean(np.abs(with_zone)) > 0.7 * demand


def _locked_rotor_rests(I, theta_e, legs, h, span=0.005, dt=1e-7):
    """The twin's comparators (`hf_twin._comparators`) on a locked rotor from rest (currents 0) with
    every leg on `legs` (±1): whether the loop is still at rest after `span` s (currents within 1 mA)."""
    import math

    from emaphm.kernels.hf_twin import _comparators
    from emaphm.kernels.transforms import phase_directions

    p = emaphm.EmaParams()
    R, L, V = p.motor.R_s, p.motor.L_s, p.inverter.V_dc
    r = [I * u for u in phase_directions(math.sin(theta_e), math.cos(theta_e))]
    i_a = i_b = i_c = 0.0
    s = (legs, legs, legs)
    for _ in range(int(span / dt)):
        *s, _sw = _comparators(i_a, i_b, i_c, *s, *(x - h / 2 for x in r), *(x + h / 2 for x in r))
        v_n = V / 2 * sum(s) / 3
        i_a += dt * (V / 2 * s[0] - v_n - R * i_a) / L
        i_b += dt * (V / 2 * s[1] - v_n - R * i_b) / L
        i_c = -(i_a + i_b)
    return max(abs(i_a), abs(i_b), abs(i_c)) < 1e-3


@pytest.mark.parametrize("theta_e", [0.3, 1.4, 2.9, 4.0, 5.5])
@pytest.mark.parametrize("demand", [-0.09, -0.055, 0.045, 0.07, 0.1])
def test_the_monitors_dead_zone_follows_which_zero_vectors_the_twins_comparators_keep(theta_e, demand):
    # sign conventions and sides of the band against the twin's own comparators: the monitor rests
    # where a loop at rest on either zero vector stays there, carries half the demand where only
    # one of them keeps it (even odds of sitting on it) and all of it where neither does
    import math

    from emaphm.kernels.monitor import MAY_REST_CARRY, standstill_dead_zone

    h = emaphm.EmaParams().inverter.h
    held = [_locked_rotor_rests(demand, theta_e, legs, h) for legs in (1.0, -1.0)]
    carry = standstill_dead_zone(demand, 0.0, math.sin(theta_e), math.cos(theta_e), h / 2)
    assert carry == {2: 0.0, 1: MAY_REST_CARRY, 0: 1.0}[sum(held)], (held, carry)


def test_the_loop_carries_the_demand_by_how_many_zero_vectors_hold():
    import math

    from emaphm.kernels.monitor import MAY_REST_CARRY, standstill_dead_zone

    i_D = 0.05
    # θ_e = π/6: u = (−1/2, 1, −1/2); a positive demand I gives i_x,ref = (−I/2, I, −I/2): all legs
    # up hold while I/2 < i_D, all legs down while I < i_D
    s, c = math.sin(math.pi / 6), math.cos(math.pi / 6)
    assert standstill_dead_zone(0.03, 0.0, s, c, i_D) == 0.0  # both hold: at rest
    assert standstill_dead_zone(-0.03, 0.0, s, c, i_D) == 0.0
    assert standstill_dead_zone(0.03, 0.2, s, c, i_D) == 1.0  # moving: the loop runs
    assert standstill_dead_zone(0.08, 0.0, s, c, i_D) == MAY_REST_CARRY  # only all legs up hold
    assert standstill_dead_zone(-0.08, 0.0, s, c, i_D) == MAY_REST_CARRY  # only all legs down hold
    assert standstill_dead_zone(0.12, 0.0, s, c, i_D) == 1.0  # neither holds
    assert standstill_dead_zone(0.01, 0.0, s, c, 0.0) == 1.0  # no dead zone (i_D = 0)
    assert 0.0 < MAY_REST_CARRY < 1.0


def test_a_stuck_monitor_carries_half_the_demand_in_the_ring():
    """Inside `simulate_lf`: with the loop-error surrogate off (the motor carries the loop state),
    a motor stuck where only one zero vector holds carries `MAY_REST_CARRY` of the demand."""

    from emaphm.commands import Steps
    from emaphm.faults import random_faults
    from emaphm.kernels.monitor import IDX, MAY_REST_CARRY, N_AUX, simulate_lf, standstill_dead_zone

    cal = default_calibration()
    plain = dataclasses.replace(
        cal.coefficients, k_H=0.0, delta_0=0.0, delta_1=0.0, delta_u=0.0, delta_2=0.0, i_R=0.0
    )
    monitor = MonitorEma(command=Steps(dwell=0.2), calibration=dataclasses.replace(cal, coefficients=plain))
    # a random actuator whose motor sticks in the ring at the ends of dwells (bench_multifault's case 15)
    row = monitor.rows(random_faults(20, 2611)[15][None, :])[0]
    _, theta = monitor.sample_grid(None)
    i_out, aux = np.zeros(len(theta)), np.zeros((len(theta), N_AUX))
    simulate_lf(theta, row, i_out, aux)
    omega, theta_e, demand = aux[:, 2], aux[:, 3], aux[:, 4]
    carry = np.array(
        [
            standstill_dead_zone(d, w, np.sin(e), np.cos(e), row[IDX["i_D"]])
            for d, w, e in zip(demand, omega, theta_e, strict=True)
        ]
    )
    # samples a few loop time constants into a stretch of the ring
    ring = np.array([k >= 5 and np.all(carry[k - 5 : k + 1] == MAY_REST_CARRY) for k in range(len(carry))])
    assert ring.sum() > 100 and np.all(omega[ring] == 0.0)
    np.testing.assert_allclose(i_out[ring], MAY_REST_CARRY * demand[ring], rtol=0, atol=1e-3)
    assert np.min(np.abs(demand[ring])) > 0.04  # so neither the whole demand nor none would pass


def test_no_zero_vector_holds_beyond_the_ring_edge_at_any_angle():
    import math

    from emaphm.kernels.monitor import MAY_REST_CARRY, RING_OUTER, standstill_dead_zone

    i_D = 0.05
    edge = RING_OUTER * i_D
    angles = np.linspace(0.0, 2 * math.pi, 721)
    for sign in (1.0, -1.0):
        beyond = [
            standstill_dead_zone(sign * edge * 1.001, 0.0, math.sin(a), math.cos(a), i_D) for a in angles
        ]
        assert all(c == 1.0 for c in beyond)
        # and the edge is tight: where one phase direction is ±1 the ring reaches it
        within = [
            standstill_dead_zone(sign * edge * 0.999, 0.0, math.sin(a), math.cos(a), i_D) for a in angles
        ]
        assert MAY_REST_CARRY in within


def test_a_calibration_can_fit_a_subset_and_hold_the_rest_at_a_given_calibration():
    from emaphm.calibration.scenarios import Scenario
    from emaphm.commands import Sine

    rig = {"rig": Sine(amplitude=0.002, frequency=3.0, duration=0.3)}
    fit = [Scenario("a short on the rig", faults(k4=0.3), "rig")]
    start = default_calibration()
    cal = calibrate(
        seed=2, pop_size=6, generations=2, fit=fit, check=[], commands=rig, free=["i_D"], start=start
    )
    new, old = dataclasses.asdict(cal.coefficients), dataclasses.asdict(start.coefficients)
    assert {n for n in new if new[n] != old[n]} <= {"i_D"}
    assert cal.record["settings"]["fitted"] == ["i_D"]
    assert cal.record["settings"]["held_from"].startswith("given calibration made")
    assert cal.record["before_calibration"]["coefficients"] == old
    lo, hi = cal.record["settings"]["bounds"]["i_D"]
    assert lo <= cal.coefficients.i_D <= hi
    # the start is in the first population: the fit ends no worse than where it began
    before = [sc["nrmse"] for sc in cal.record["before_calibration"]["scenarios"]]
    assert cal.record["fit_scenarios"][0]["nrmse"] <= before[0] + 1e-12
    with pytest.raises(InputError, match="cannot fit 'i_D' for the 'paper' monitor"):
        calibrate(monitor="paper", pop_size=4, generations=1, fit=fit, check=[], commands=rig, free=["i_D"])
    with pytest.raises(InputError, match="at least one coefficient"):
        calibrate(pop_size=4, generations=1, fit=fit, check=[], commands=rig, free=[])
    with pytest.raises(InputError, match="needs the coefficients to fit"):
        calibrate(pop_size=4, generations=1, fit=fit, check=[], commands=rig, start=start)
    with pytest.raises(InputError, match="made with n_lf = 1, this one uses 2"):
        calibrate(
            pop_size=4, generations=1, n_lf=2, fit=fit, check=[], commands=rig, free=["i_D"], start=start
        )
    other = emaphm.EmaParams(motor=dataclasses.replace(emaphm.EmaParams().motor, R_s=0.6))
    with pytest.raises(InputError, match="its own calibration to start from"):
        calibrate(pop_size=4, generations=1, params=other, fit=fit, check=[], commands=rig, free=["i_D"])
