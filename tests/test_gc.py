"""The collector while a command's process starts (emaphm/_gc.py, issue 36)."""

import gc
import subprocess
import sys

from emaphm import _gc


def test_quiet_start_raises_the_threshold_and_settled_freezes_and_restores_it():
    before, frozen = gc.get_threshold(), gc.get_freeze_count()
    try:
        _gc.settled()  # without quiet_start: nothing (a library caller keeps its settings)
        assert gc.get_threshold() == before and gc.get_freeze_count() == frozen
        _gc.quiet_start()
        _gc.quiet_start()  # once only: the saved thresholds stay the interpreter's
        assert gc.get_threshold() == (max(_gc.STARTUP_THRESHOLD, before[0]), *before[1:])
        assert gc.isenabled()  # raised, never off
        _gc.settled()
        assert gc.get_threshold() == before
        assert gc.get_freeze_count() > frozen
        _gc.settled()
        assert gc.get_threshold() == before
    finally:
        gc.set_threshold(*before)
        gc.unfreeze()


def test_an_identify_process_freezes_its_imports_and_ends_with_the_usual_thresholds():
    # the process's entry (cli.main without argv) raises the threshold, `identify` settles it once
    # its imports are done; the report is taken at the process's end (os._exit, `cli._process_exit`)
    code = (
        "import gc, os, sys\n"
        "start = gc.get_threshold()\n"
        "end = os._exit\n"
        "def report(status):\n"
        "    sys.stderr.write(f'gc {start == gc.get_threshold()} {gc.get_freeze_count()}\\n')\n"
        "    end(status)\n"
        "os._exit = report\n"
        "sys.argv = ['emaphm', 'identify', '--true-faults', '0.1,0.1,0,0.1,0,0,0,0.5', '--seed', '1', '--json',\n"
        "            '--generations', '1', '--pop-size', '4', '--no-polish', '--last-stage', 'none', '--uncertainty', 'none']\n"
        "from emaphm.cli import main\n"
        "main()\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert out.returncode in (0, 4), out.stderr
    _, same, frozen = out.stderr.strip().splitlines()[-1].split()
    assert same == "True"  # the thresholds back to the process's start's
    assert int(frozen) > 10_000  # the imports' objects frozen
