"""numba imported lean (`emaphm._lean_numba`): without scipy, yaml and importlib.metadata, which
stay importable, its config file still read and its extensions still loaded where one is declared."""

import subprocess
import sys

from emaphm._lean_numba import extensions_declared
from emaphm._versions import _dist_info_version

LEAN_NUMBA = """
import sys
from emaphm._lean_numba import import_numba
import_numba()
import numba
loaded = [name for name in ("scipy", "yaml", "importlib.metadata") if name in sys.modules]

@numba.njit
def f(x):
    return x + 1

f(1)  # the first call of a compiled function: where numba loads its extensions
import scipy, yaml, importlib.metadata  # importable afterwards
print(loaded, numba.config.NUMBA_NUM_THREADS, sys.modules.get("fake_numba_ext_loaded", "no-extension"))
"""

EXTENSION = "import sys, types\ndef init():\n    sys.modules['fake_numba_ext_loaded'] = 'extension-loaded'\n"


def run(cwd, env_path=None):
    import os

    env = dict(os.environ)
    if env_path is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(env_path), env.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, "-c", LEAN_NUMBA], capture_output=True, text=True, cwd=cwd, env=env)
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


def test_numba_imports_without_scipy_yaml_and_metadata_which_stay_importable(tmp_path):
    loaded, _, extension = run(tmp_path)
    assert (loaded, extension) == ("[]", "no-extension")


def test_numba_still_reads_its_config_file_in_the_working_folder(tmp_path):
    (tmp_path / ".numba_config.yaml").write_text("num_threads: 1\n")
    assert run(tmp_path)[:2] == ["['yaml']", "1"]


def test_a_declared_numba_extension_is_still_loaded(tmp_path):
    site = tmp_path / "site"
    (site / "fake_numba_ext-1.0.dist-info").mkdir(parents=True)
    (site / "fake_numba_ext-1.0.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-numba-ext\nVersion: 1.0\n")
    (site / "fake_numba_ext-1.0.dist-info" / "entry_points.txt").write_text("[numba_extensions]\ninit = fake_numba_ext:init\n")
    (site / "fake_numba_ext.py").write_text(EXTENSION)
    assert extensions_declared([str(site)])
    assert run(tmp_path, site)[-1] == "extension-loaded"


def test_extensions_are_told_from_the_distributions_entry_points(tmp_path):
    (tmp_path / "a-1.0.dist-info").mkdir()
    (tmp_path / "a-1.0.dist-info" / "entry_points.txt").write_text("[console_scripts]\na = a:main\n")
    (tmp_path / "b-2.0.egg-info").mkdir()
    assert not extensions_declared([str(tmp_path), str(tmp_path / "missing")])
    (tmp_path / "b-2.0.egg-info" / "entry_points.txt").write_text("[numba_extensions]\ninit = b:init\n")
    assert extensions_declared([str(tmp_path)])
    (tmp_path / "archive.zip").write_bytes(b"")
    assert extensions_declared([str(tmp_path / "archive.zip")])  # a zip: left to numba's own scan


def test_an_installed_version_is_read_from_its_dist_info_folder(tmp_path, monkeypatch):
    import importlib.metadata

    for name in ("scipy", "numpy", "numba"):
        assert _dist_info_version(name) == importlib.metadata.version(name)
    (tmp_path / "Some_Pkg-3.2.1.dist-info").mkdir()
    monkeypatch.setattr(sys, "path", [str(tmp_path / "missing"), str(tmp_path)])
    assert _dist_info_version("some-pkg") == "3.2.1"
    (tmp_path / "some_pkg-3.3.dist-info").mkdir()
    assert _dist_info_version("some-pkg") is None  # two: left to importlib.metadata
    assert _dist_info_version("other") is None
