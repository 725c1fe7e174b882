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
