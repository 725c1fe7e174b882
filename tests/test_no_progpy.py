"""The core without ProgPy (issue 12): ``import emaphm`` never loads it, the trend RUL works
without it, and ``--estimator ukf`` asks for the extra in one line. Not skipped where ProgPy is
missing: that is where it matters."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from emaphm.campaign.store import ResultStore
from tests.test_prognostics import _rows


def test_import_emaphm_does_not_import_progpy():
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    script = (
        "import sys, emaphm, emaphm.prognostics, emaphm.cli, emaphm.campaign\nprint('progpy' in sys.modules)"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 0 and done.stdout.strip() == "False"


def test_the_core_works_without_progpy(tmp_path):
    # progpy made unimportable: emaphm and its trend RUL run; the UKF asks for the extra in one line
    flights = np.arange(1, 11)
    ResultStore(tmp_path / "s").write("results", _rows("A1", flights, 0.05 + 0.02 * flights, 0.005, 1))
    script = (
        "import sys; sys.modules['progpy'] = None\n"
        "import emaphm, emaphm.prognostics, emaphm.cli\n"
        "from emaphm.cli import main\n"
        "main(sys.argv[1:])\n"
    )
    base = [sys.executable, "-c", script, "rul", str(tmp_path / "s"), "--actuator", "A1", "--json"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    ok = subprocess.run(base, capture_output=True, text=True, env=env, timeout=120)
    assert ok.returncode == 0 and json.loads(ok.stdout)["faults"]["friction"]["status"] == "tracked"
    bad = subprocess.run([*base, "--estimator", "ukf"], capture_output=True, text=True, env=env, timeout=120)
    assert bad.returncode == 2 and "emaphm[progpy]" in bad.stderr and bad.stderr.count("\n") == 1
    # with nothing tracked the UKF would not be reached: the extra is still asked for
    ResultStore(tmp_path / "h").write("results", _rows("A2", flights, np.zeros(10), 0.005, 99))
    healthy = [
        sys.executable,
        "-c",
        script,
        "rul",
        str(tmp_path / "h"),
        "--actuator",
        "A2",
        "--estimator",
        "ukf",
    ]
    bad = subprocess.run(healthy, capture_output=True, text=True, env=env, timeout=120)
    assert bad.returncode == 2 and "emaphm[progpy]" in bad.stderr
