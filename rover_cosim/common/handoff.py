"""A worker process's result handed to its parent without copying its arrays through the pipe.

A run's result carries its recorded columns: 17-42 MB for a leg-wheel run. Pickled into the pipe
they were copied four times (pickled, written, read, unpickled), about 0.15 s a run on each side.
Here the message is pickled with protocol 5, its arrays left out of band; when they come to
``SHARED_MIN_BYTES`` or more they are written once into an anonymous shared file (Linux
``memfd_create``), whose descriptor follows the message over the pipe (a Unix socket pair), and
the parent maps that file copy-on-write: its arrays are the file's pages, writable, freed with
the last array that uses them. Nothing has a name, so nothing is left behind by a process that
dies half-way. Elsewhere (no ``memfd_create``), or for smaller messages, the message goes
through the pipe as before. The parent gets the same objects either way, bit for bit.
"""

from __future__ import annotations

import mmap
import os
import pickle
from typing import Any

#: bytes: messages whose out-of-band arrays come to less go through the pipe.
SHARED_MIN_BYTES = 1 << 20
#: bytes: each array starts at a multiple of this in the shared file (numpy's alignment).
ALIGNMENT = 64
_SHARED = "rover-cosim shared result"


def send(conn: Any, message: Any) -> None:
    """``conn.send(message)``; a message with ``SHARED_MIN_BYTES`` of arrays or more through an
    anonymous shared file (``conn`` a Unix socket pair's end: ``multiprocessing.Pipe()``)."""
    if not hasattr(os, "memfd_create"):
        conn.send(message)
        return
    buffers: list[pickle.PickleBuffer] = []
    payload = pickle.dumps(message, protocol=5, buffer_callback=buffers.append)
    try:
        views = [buffer.raw() for buffer in buffers]
    except BufferError:  # an array neither C- nor Fortran-contiguous: pickled in band
        views = []
    if not views or sum(view.nbytes for view in views) < SHARED_MIN_BYTES:
        conn.send(message)
        return
    layout, offset = [], 0
    for view in views:
        layout.append((offset, view.nbytes))
        offset += -(-view.nbytes // ALIGNMENT) * ALIGNMENT
    try:
        descriptor = _shared_file(views, layout, offset)
    except OSError:  # no memory for it (a container's limit): through the pipe after all
        conn.send(message)
        return
    try:
        conn.send((_SHARED, payload, layout))
        from multiprocessing.reduction import send_handle

        send_handle(conn, descriptor, os.getppid())
    finally:
        os.close(descriptor)


def _shared_file(views: list[memoryview], layout: list[tuple[int, int]], size: int) -> int:
    """An anonymous shared file of ``size`` bytes holding each view at its offset: its descriptor."""
    descriptor = os.memfd_create("rover-cosim-result", os.MFD_CLOEXEC)
    try:
        os.ftruncate(descriptor, max(size, 1))
        for view, (start, length) in zip(views, layout):
            written = 0
            while written < length:
                written += os.pwrite(descriptor, view[written:], start + written)
    except OSError:
        os.close(descriptor)
        raise
    return descriptor


def receive(conn: Any) -> Any:
    """The next message ``send`` sent on the other end of ``conn``; EOFError when its sender died
    before it had sent all of it."""
    message = conn.recv()
    if not (isinstance(message, tuple) and len(message) == 3 and message[0] == _SHARED):
        return message
    _, payload, layout = message
    from multiprocessing.reduction import recv_handle

    try:
        descriptor = recv_handle(conn)
    except (EOFError, OSError, RuntimeError) as error:  # the sender died between the message and its file
        raise EOFError(f"the result's shared file did not arrive: {error}") from None
    try:
        size = max((start + length for start, length in layout), default=0)
        mapped = mmap.mmap(descriptor, max(size, 1), flags=mmap.MAP_PRIVATE,
                           prot=mmap.PROT_READ | mmap.PROT_WRITE)
    finally:
        os.close(descriptor)
    view = memoryview(mapped)
    return pickle.loads(payload, buffers=[view[start:start + length] for start, length in layout])
