"""A worker process's result handed to its parent without copying its arrays through the pipe.

A run's result carries its recorded columns: 17-42 MB for a leg-wheel run. Pickled into the pipe
they were copied four times (pickled, written, read, unpickled), about 0.15 s a run on each side.
Here the message is pickled once, with protocol 5: its arrays of ``LARGE`` bytes or more are left
out of band and written once into an anonymous shared file (Linux ``memfd_create``), whose
descriptor follows the message over the pipe (a Unix socket pair), and the parent maps that file
copy-on-write: its arrays are the file's pages, writable, freed with the last array that uses
them. Nothing has a name, so nothing is left behind by a process that dies half-way. A message
without large arrays goes through the pipe as that one pickle; elsewhere (no ``memfd_create``),
or where the system refuses the file, the message goes through the pipe as before. The parent gets
the same objects either way, bit for bit.
"""

from __future__ import annotations

import mmap
import os
import pickle
from typing import Any

#: bytes: an array this large or larger travels in the shared file, a smaller one in the pickle.
LARGE = 1 << 16
#: bytes: each array starts at a multiple of this in the shared file (numpy's alignment).
ALIGNMENT = 64
_SHARED = "rover-cosim shared result"


def send(conn: Any, message: Any) -> None:
    """``conn.send(message)``, its arrays of ``LARGE`` bytes or more through an anonymous shared
    file (``conn`` a Unix socket pair's end: ``multiprocessing.Pipe()``)."""
    if not hasattr(os, "memfd_create"):
        conn.send(message)
        return
    large: list[memoryview] = []

    def in_band(buffer: pickle.PickleBuffer) -> bool:
        try:
            view = buffer.raw()
        except BufferError:  # neither C- nor Fortran-contiguous
            return True
        if view.nbytes < LARGE:
            return True
        large.append(view)
        return False

    payload = pickle.dumps(message, protocol=5, buffer_callback=in_band)
    if not large:  # the whole message is in the pickle, which conn.recv() reads as its own
        conn.send_bytes(payload)
        return
    layout, offset = [], 0
    for view in large:
        layout.append((offset, view.nbytes))
        offset += -(-view.nbytes // ALIGNMENT) * ALIGNMENT
    try:
        descriptor = _shared_file(large, layout, offset)
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
