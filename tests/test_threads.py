"""emaphm._threads: numba's pool sized as asked, BLAS on one thread inside, both restored after."""

import numba
import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from emaphm._threads import numba_threads
from emaphm.errors import InputError


def blas_threads():
    return sorted({p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"})


def test_inside_numba_has_the_workers_and_blas_one_thread_restored_after():
    np.linalg.svd(np.ones((50, 8)))  # BLAS loaded
    available = int(numba.config.NUMBA_NUM_THREADS)
    with threadpool_limits(limits=2, user_api="blas"):  # a known state before, whatever the machine
        before_blas = blas_threads()
        before_numba = numba.get_num_threads()
        assert before_blas  # numpy's BLAS is visible to threadpoolctl
        with numba_threads(1):
            assert numba.get_num_threads() == 1
            assert blas_threads() == [1]
        with numba_threads(0):
            assert numba.get_num_threads() == available
            assert blas_threads() == [1]
        assert blas_threads() == before_blas
        assert numba.get_num_threads() == before_numba


def test_the_limits_are_restored_after_an_error():
    np.linalg.svd(np.ones((50, 8)))
    with threadpool_limits(limits=2, user_api="blas"):  # not 1 before, or the test could not fail
        before = blas_threads()
        with pytest.raises(RuntimeError), numba_threads(1):
            assert blas_threads() == [1]
            raise RuntimeError("boom")
        assert blas_threads() == before


def test_too_many_workers_is_refused_in_one_line():
    with pytest.raises(InputError, match=r"--workers must be 0\.\."):
        with numba_threads(10_000, name="--workers"):
            pass


def _fresh(code: str) -> list[str]:
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout.split()


def _fresh_loaded(code: str) -> list[str]:
    """`_fresh`'s output of `code` in a second process: on a cold cache (a fresh machine) the
    first compiles the kernels, so that the second loads them, as a diagnosis usually does."""
    _fresh(code)
    return _fresh(code)


def test_a_blas_loaded_inside_the_block_gets_one_thread_only_when_said():
    # a fresh process: scipy's own BLAS is not loaded until scipy.optimize is imported
    code = (
        "import sys; from threadpoolctl import threadpool_info as info, threadpool_limits\n"
        "from emaphm._threads import numba_threads, blas_loaded\n"
        "scipys = lambda: sorted(p['num_threads'] for p in info() if 'scipy_openblas-' in p['filepath'])\n"
        "with threadpool_limits(limits=2, user_api='blas'):\n"
        "    assert 'scipy.linalg' not in sys.modules\n"
        "    with numba_threads(1):\n"
        "        import scipy.optimize\n"
        "        print(scipys())\n"  # loaded inside the block: the block's limit did not reach it
        "        blas_loaded(); print(scipys())\n"
        "    print(scipys())\n"  # restored with the block
        "blas_loaded(); print(scipys())\n"  # outside a block: nothing
    )
    before, said, after, outside = _fresh(code)
    assert said == "[1]" and before != "[1]"
    assert after == outside == before


def test_a_diagnosis_loads_its_kernels_without_numbas_compiler_registries():
    # kernels/_jit.QuickLoadCache: a cached kernel loads without importing numba's lowering
    # registries (numba.np.linalg is one); a compilation afterwards still works (it refreshes).
    # And no kernel a diagnosis loads allocates or uses array expressions, whose loads import
    # numba's array and ufunc modules (kernels/fitness.py, STACK_SIZE's note): a whole diagnosis
    # (polish, last stage, intervals) runs without them
    code = (
        "import sys, numpy as np\n"
        "from emaphm.identification.api import identify\n"
        "identify(true_faults=[0.1, 0.1, 0, 0.1, 0, 0, 0, 0.5], seed=1, generations=1, pop_size=4)\n"
        "print('numba.np.linalg' in sys.modules, [m for m in ('scipy.ndimage', 'scipy.spatial', 'scipy.optimize', 'numba.np.arrayobj', 'numba.np.npyimpl') if m in sys.modules])\n"
        "from emaphm.kernels.fitness import fitness_lf_kernel as fitness_lf_many\n"
        "print(sum(fitness_lf_many.stats.cache_hits.values()) > 0, sum(fitness_lf_many.stats.cache_misses.values()))\n"
        "import numba\n"
        "print(numba.njit(lambda a: np.linalg.det(a))(np.eye(3)))\n"
    )
    out = _fresh_loaded(code)
    assert out[0] == "False" and out[1] == "[]", out
    assert out[2:4] == ["True", "0"], out  # loaded from the cache, not compiled
    assert out[4] == "1.0"


def test_a_kernel_load_fires_no_llvm_lock_events_and_a_compilation_still_does():
    # kernels/_jit._llvm_lock_events_off: numba's callbacks on llvmlite's lock are off while a
    # cached kernel loads and back, in their order, afterwards; a compilation still fires them
    code = (
        "import numpy as np\n"
        "from llvmlite.binding import ffi\n"
        "from emaphm.kernels.transforms import clarke\n"
        "calls = []\n"
        "ffi.register_lock_callback(lambda: calls.append(1), lambda: None)\n"
        "before = list(ffi.lib._lock._cblist)\n"
        "clarke(np.zeros(4), np.zeros(4), np.zeros(4))\n"
        "print(len(calls), list(ffi.lib._lock._cblist) == before)\n"
        "print(clarke.stats.cache_hits and sum(clarke.stats.cache_hits.values()) > 0)\n"
        "import numba\n"
        "numba.njit(lambda a: a + 1)(1.0)\n"
        "print(len(calls) > 0)\n"
    )
    out = _fresh_loaded(code)
    assert out == ["0", "True", "True", "True"], out


def test_thread_map_starts_the_costliest_first_and_returns_in_the_items_order():
    import threading
    import time

    from emaphm._threads import thread_map

    started: list[str] = []
    lock = threading.Lock()

    def run(item: str) -> str:
        with lock:
            started.append(item)
        time.sleep(0.01)
        return item.upper()

    items = ["a", "b", "c"]
    assert thread_map(run, items, 2, costs=[2.0, 2.5, 4.0]) == ["A", "B", "C"]
    assert sorted(started) == items and started[-1] == "a"  # the cheapest waits for a free thread
    started.clear()
    assert thread_map(run, items, 2) == ["A", "B", "C"] and started[-1] == "c"  # no costs: in order
    with pytest.raises(InputError, match="costs has 2 values for 3 items"):
        thread_map(run, items, 2, costs=[1.0, 2.0])


RUNTIME = """
from numba.core.runtime import rtsys
from emaphm._threads import runtime_meanwhile
before = rtsys._init
thread = runtime_meanwhile()
thread.join()
from emaphm import MonitorEma
current = MonitorEma().simulate([0.1] * 7 + [0.5], duration=0.05).i_q
print(before, rtsys._init, thread.name, bool(abs(current).max() > 0))
"""


def test_the_runtime_is_initialised_on_its_thread_and_kernels_then_run():
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", RUNTIME], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True", "emaphm-runtime", "True"], out.stdout + out.stderr

