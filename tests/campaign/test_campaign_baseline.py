"""A campaign actuator with its own baseline folder (issue 33, item 2)."""

from __future__ import annotations

import json

import pytest

import emaphm
from emaphm.baseline import baseline
from emaphm.campaign import ResultStore, load_campaign, run_campaign
from emaphm.errors import InputError

SPEC = """[campaign]
name = "b"
seeds = [1]

[identify]
pop_size = 6
generations = 2
polish = false
uncertainty = "none"

[[actuator]]
id = "A7"
reference = "rec.h5"
{baseline}
"""


@pytest.mark.slow  # a baseline (two healthy recordings) and one identification, ~10 s
def test_an_actuators_baseline_is_used_and_enters_its_job_key(tmp_path):
    healthy = []
    for s in range(2):
        healthy.append(tmp_path / f"h{s}.h5")
        emaphm.write_trace(emaphm.simulate(emaphm.HEALTHY, seed=40 + s), healthy[-1])
    folder = baseline(healthy, tmp_path / "A7-baseline")
    emaphm.write_trace(emaphm.simulate([0.2, 0, 0, 0.3, 0, 0, 0, 0.5], seed=9), tmp_path / "rec.h5")
    spec = tmp_path / "c.toml"
    spec.write_text(SPEC.format(baseline='baseline = "A7-baseline"'))
    (job,) = load_campaign(spec).jobs()
    run_campaign(spec, tmp_path / "store", scheduler="serial")
    (row,) = ResultStore(tmp_path / "store").read().to_pylist()
    assert json.loads(row["settings"])["baseline"] == str(folder.resolve())
    alone = emaphm.identify(reference=tmp_path / "rec.h5", seed=1, baseline=folder, pop_size=6, generations=2,
                            polish=False, uncertainty="none")  # fmt: skip
    assert [row[f"k{i}"] for i in range(1, 9)] == alone.estimate.tolist()
    # another baseline of the actuator (one recording fewer) is another job
    baseline(healthy[:1], tmp_path / "A7-baseline")
    (again,) = load_campaign(spec).jobs()
    assert again.key != job.key
    # without one, the nameplate: yet another
    spec.write_text(SPEC.format(baseline=""))
    assert load_campaign(spec).jobs()[0].key not in (job.key, again.key)


def test_a_missing_baseline_folder_is_refused_naming_the_actuator(tmp_path):
    emaphm.write_trace(emaphm.simulate(emaphm.HEALTHY, seed=1, duration=0.3), tmp_path / "rec.h5")
    spec = tmp_path / "c.toml"
    spec.write_text(SPEC.format(baseline='baseline = "nowhere"'))
    with pytest.raises(InputError, match=r"A7.*nowhere: no such folder"):
        load_campaign(spec)


HEALTHY_SPEC = SPEC.replace("{baseline}", "{healthy}")


def _healthy(tmp_path, seeds=(40, 41), duration=None):
    paths = []
    for s in seeds:
        paths.append(tmp_path / f"h{s}.h5")
        kw = {} if duration is None else {"duration": duration}
        emaphm.write_trace(emaphm.simulate(emaphm.HEALTHY, seed=s, **kw), paths[-1])
    return paths


def test_an_actuator_with_healthy_recordings_waits_for_its_baseline(tmp_path):
    _healthy(tmp_path, duration=0.3)
    emaphm.write_trace(emaphm.simulate(emaphm.HEALTHY, seed=1, duration=0.3), tmp_path / "rec.h5")
    spec = tmp_path / "c.toml"
    spec.write_text(HEALTHY_SPEC.format(healthy='healthy = ["h40.h5", "h41.h5"]'))
    campaign = load_campaign(spec)
    assert campaign.jobs(tmp_path / "store") == [] and campaign.waiting(tmp_path / "store") == ["A7"]
    status = emaphm.campaign.campaign_status(spec, tmp_path / "store")
    assert status["waiting_for_baseline"] == ["A7"] and status["jobs"] == 0
    for bad, message in (('healthy = []', "non-empty list"), ('healthy = ["h40.h5"]\nbaseline = "x"', "not both"),
                         ('healthy = ["nope.h5"]', "no such file")):  # fmt: skip
        spec.write_text(HEALTHY_SPEC.format(healthy=bad))
        with pytest.raises(InputError, match=message):
            load_campaign(spec)


@pytest.mark.slow  # two baselines (~10 s each) and two identifications
def test_the_campaign_makes_the_baseline_once_and_identifies_with_it(tmp_path):
    healthy = _healthy(tmp_path)
    emaphm.write_trace(emaphm.simulate([0.2, 0, 0, 0.3, 0, 0, 0, 0.5], seed=9), tmp_path / "rec.h5")
    spec = tmp_path / "c.toml"
    spec.write_text(HEALTHY_SPEC.format(healthy='healthy = ["h40.h5", "h41.h5"]'))
    first = run_campaign(spec, tmp_path / "store", scheduler="serial")
    assert (first.baselines, first.done, first.failed, first.waiting) == (1, 1, 0, ())
    folder = tmp_path / "store" / "baselines" / "b" / "A7"
    (row,) = ResultStore(tmp_path / "store").read().to_pylist()
    assert json.loads(row["settings"])["baseline"] == str(folder)
    # the same as a baseline made by hand and identify --baseline
    by_hand = baseline(healthy, tmp_path / "by-hand")
    alone = emaphm.identify(reference=tmp_path / "rec.h5", seed=1, baseline=by_hand, pop_size=6, generations=2,
                            polish=False, uncertainty="none")  # fmt: skip
    assert [row[f"k{i}"] for i in range(1, 9)] == alone.estimate.tolist()
    again = run_campaign(spec, tmp_path / "store", scheduler="serial")
    assert (again.baselines, again.submitted) == (0, 0)
    # a healthy recording that is not: refused with its reason, the actuator waits
    emaphm.write_trace(emaphm.simulate([0.6, 0.3, 0, 0.5, 0, 0, 0, 0.3], seed=41), healthy[1])
    refused = run_campaign(spec, tmp_path / "store", scheduler="serial")
    assert refused.failed == 1 and refused.waiting == ("A7",) and refused.failures[0].startswith("baseline of actuator A7")
    assert folder.is_dir()  # the older baseline stays until a new one is made
