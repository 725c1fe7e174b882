"""The figures leave the user's matplotlib alone (review L6): no backend switch, no pyplot."""

import subprocess
import sys

import emaphm.plots

# a fresh interpreter: whether pyplot is loaded is the process's state, and other tests may load it
# (cma does). A "module://" backend name is accepted without importing it, so no display is needed.
CHECK = """
import sys, tempfile
from pathlib import Path
import matplotlib
matplotlib.use("module://an_interactive_backend")
from emaphm.plots import plot_convergence
with tempfile.TemporaryDirectory() as d:
    plot_convergence({"run": [3.0, 2.0, 1.0]}, Path(d) / "c.png")
    size = (Path(d) / "c.png").stat().st_size
print(matplotlib.rcParams["backend"], "matplotlib.pyplot" in sys.modules, size > 1000)
"""


def test_a_plot_keeps_the_users_backend_and_does_not_load_pyplot():
    res = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, check=True)
    assert res.stdout.split() == ["module://an_interactive_backend", "False", "True"]


def test_every_public_plot_function_is_in_all():
    public = {n for n in vars(emaphm.plots) if n.startswith("plot_")}
    assert public == set(emaphm.plots.__all__)
