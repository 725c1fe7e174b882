"""identification/warm.py: the search's kernels loaded while the twin measures (issue 36)."""

import subprocess
import sys
import threading

import numpy as np
import pytest

from emaphm import MonitorEma
from emaphm.errors import SimulationError
from emaphm.identification.recording import measurement
from emaphm.identification.warm import meanwhile
from emaphm.params import EmaParams

TABLE1 = [0.2383, 0.5003, 0.0, 0.4503, 0.0404, 0.0028, 0.2785, 0.5]

# the search's kernels: their overloads after the warm-up, then after a diagnosis from a trace
# (no warm-up on that path): a kernel the warm-up missed, or called with another type, gains one
SIGNATURES = """
from emaphm import HighFidelityEma, MonitorEma
from emaphm.identification.api import identify
from emaphm.identification.warm import load_search_kernels
from emaphm.kernels import fitness, monitor
kernels = [fitness.fitness_lf_kernel, fitness.residuals_lf_kernel, fitness.sosfiltfilt_one_kernel,
           fitness.sosfiltfilt_many_kernel, monitor.simulate_lf, monitor.simulate_lf_many_kernel]
load_search_kernels(MonitorEma())
print(*[len(k.signatures) for k in kernels])
trace = HighFidelityEma().simulate([0.1, 0.1, 0, 0.1, 0, 0, 0, 0.5], seed=3)
identify(reference=trace, seed=1, generations=1, pop_size=4, start="random")
print(*[len(k.signatures) for k in kernels])
"""


def test_the_warm_up_calls_every_kernel_the_search_calls_and_with_the_same_types():
    out = subprocess.run([sys.executable, "-c", SIGNATURES], capture_output=True, text=True, check=True)
    after_warm, after_search = out.stdout.strip().splitlines()
    assert after_warm == after_search == "1 1 1 1 1 1", out.stdout


def test_the_measurement_is_the_same_with_the_kernels_loaded_meanwhile():
    params = EmaParams()
    alone = measurement(TABLE1, None, None, params, 1234)
    beside = measurement(TABLE1, None, None, params, 1234, MonitorEma(params))
    for name in alone.trace.names:
        assert np.array_equal(alone.trace[name], beside.trace[name]), name


def test_meanwhile_runs_the_work_on_another_thread_and_raises_its_error_after_the_other():
    seen: list[str] = []

    def work() -> int:
        seen.append(threading.current_thread().name)
        return 7

    assert meanwhile(work, lambda: seen.append("other")) == 7
    assert seen[0].startswith("emaphm-measure") or seen[1].startswith("emaphm-measure")
    assert "other" in seen

    def fails() -> None:
        raise SimulationError("the twin diverged")

    done: list[bool] = []
    with pytest.raises(SimulationError, match="diverged"):
        meanwhile(fails, lambda: done.append(True))
    assert done == [True]  # the other work ran to its end first
