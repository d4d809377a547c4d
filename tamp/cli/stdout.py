"""``--json``: stdout holds only the document.

Native code writes on file descriptor 1 behind Python's back (pybullet's EGL renderer prints
``Loaded EGL 1.5 after reload.``, ``GL_VENDOR=...``). While a ``--json`` command works,
`document_only` points descriptor 1 at stderr and gives Python's ``sys.stdout`` a descriptor of
its own onto the real stdout, so what the command prints (the document) is all stdout gets;
both are restored afterwards.
"""

from __future__ import annotations

import io
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def document_only(enabled: bool) -> Iterator[None]:
    """While the block runs (``enabled``): native writes on descriptor 1 go to stderr, and
    ``sys.stdout`` still reaches the real stdout. A no-op when ``sys.stdout`` is not a file
    descriptor's stream (e.g. captured by a test)."""
    try:
        fd = sys.stdout.fileno() if enabled else None
    except (AttributeError, OSError, ValueError):  # io.UnsupportedOperation: a stream in memory
        fd = None
    if fd is None:
        yield
        return
    stdout = sys.stdout
    stdout.flush()
    saved = os.dup(fd)  # the real stdout
    os.dup2(sys.stderr.fileno(), fd)
    sys.stdout = io.TextIOWrapper(
        io.FileIO(saved, "w", closefd=False), encoding=stdout.encoding, line_buffering=True
    )
    try:
        yield
    finally:
        try:
            sys.stdout.flush()
        finally:
            sys.stdout = stdout
            os.dup2(saved, fd)
            os.close(saved)
