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
