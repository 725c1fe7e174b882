"""Atomic writes: a file is either the old one or the complete new one, never half-written.

`atomic_path` yields a temporary path beside the target (``.NAME.emaphm-PID-XXXX.tmp``) that
replaces the target only once the block succeeds. Ctrl-C during the block is held until it ends,
then the temporary file is removed and the interruption goes on. Temporaries left by a killed
process (``kill -9``) are removed by the next write to the same target. Files are created with
the permissions the umask allows, like any other tool's. `emaphm.io` writes traces through it
(and re-exports it).
"""

from __future__ import annotations

import os
import signal
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["atomic_path", "replace_folder"]

_TMP_TAG = "emaphm"


def _remove_stale_temporaries(target: Path) -> None:
    """Delete temporaries of `target` left by emaphm processes that no longer run (kill -9)."""
    for tmp in target.parent.glob(f".{target.name}.{_TMP_TAG}-*.tmp"):
        try:
            pid = int(tmp.name[len(f".{target.name}.{_TMP_TAG}-") :].split("-", 1)[0])
        except ValueError:
            continue
        if pid == os.getpid():
            continue
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            tmp.unlink(missing_ok=True)
        except OSError:  # alive under another user: not ours to remove
            continue


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def _sigint_deferred() -> Iterator[list[bool]]:
    """Hold Ctrl-C (SIGINT) for the block; the yielded flag tells whether one arrived."""
    caught = [False]
    if threading.current_thread() is not threading.main_thread():
        yield caught
        return

    def hold(signum: int, frame: object) -> None:
        caught[0] = True

    previous = signal.signal(signal.SIGINT, hold)
    try:
        yield caught
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def atomic_path(target: Path) -> Iterator[Path]:
    """Yield a temporary path beside `target`; it replaces `target` only if the block succeeds.

    Ctrl-C inside the block is held until the block ends; the temporary is then removed and
    `KeyboardInterrupt` raised, so the target is either the old file or the complete new one.
    """
    target = Path(target)
    _remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.name}.{_TMP_TAG}-{os.getpid()}-", suffix=".tmp", dir=target.parent
    )
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())
    try:
        with _sigint_deferred() as interrupted:
            yield Path(tmp)
            if interrupted[0]:
                raise KeyboardInterrupt
            os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def replace_folder(new: Path, target: Path) -> None:
    """Put the complete folder `new` (a sibling of `target`, on its file system) at `target`,
    replacing an older one whole: a reader sees the old folder or the new, never a mix."""
    import shutil

    if target.exists():
        old = target.with_name(f".{target.name}-old-{os.getpid()}")
        os.replace(target, old)
        os.replace(new, target)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(new, target)
