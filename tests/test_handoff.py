"""A worker's result reaches its parent through shared memory when it is large (common.handoff):
the same objects bit for bit, arrays the parent may write to, small messages through the pipe,
and a sender that dies half-way is an end of file, not a hang."""

from __future__ import annotations

import multiprocessing
import os
import pickle
import threading

import numpy as np
import pandas as pd
import pytest

from rover_cosim.common import handoff
from rover_cosim.common.parallel import parallel_map

FORK = "fork" in multiprocessing.get_all_start_methods()
pytestmark = pytest.mark.skipif(not hasattr(os, "memfd_create") or not FORK,
                                reason="shared results need Linux's memfd_create and fork")


def _table(rows: int, seed: int) -> tuple[str, pd.DataFrame, np.ndarray]:
    rng = np.random.default_rng(seed)
    table = pd.DataFrame(rng.standard_normal((rows, 40)), columns=[f"c{k}" for k in range(40)])
    table["flag"] = rng.integers(0, 2, rows).astype(bool)
    return f"run {seed}", table, np.asfortranarray(rng.standard_normal((rows // 10, 7)))


def _exchange(message_rows: int) -> tuple[str, pd.DataFrame, np.ndarray]:
    """``_table(message_rows, 3)`` sent from a forked child by ``handoff.send``: what arrived."""
    parent, child = multiprocessing.get_context("fork").Pipe()

    def sender() -> None:
        handoff.send(child, _table(message_rows, 3))
        child.close()

    process = multiprocessing.get_context("fork").Process(target=sender)
    process.start()
    child.close()
    received: tuple[str, pd.DataFrame, np.ndarray] = handoff.receive(parent)
    process.join(10)
    return received


@pytest.mark.parametrize("rows", [100, 20_000])
def test_a_message_arrives_equal_and_writable_either_way(rows):
    name, table, matrix = _exchange(rows)
    expected = _table(rows, 3)
    assert name == expected[0]
    pd.testing.assert_frame_equal(table, expected[1], check_exact=True)
    np.testing.assert_array_equal(matrix, expected[2])
    assert matrix.flags.f_contiguous and matrix.flags.writeable
    table.iloc[0, 0] = 1.5  # the parent's own copy of the page
    assert table.iloc[0, 0] == 1.5


def test_only_large_arrays_travel_through_shared_memory():
    sent: list[bytes] = []

    class Recorder:
        def send_bytes(self, payload: bytes) -> None:
            sent.append(payload)

    handoff.send(Recorder(), _table(100, 1))  # 32 kB of arrays: the message, pickled once
    name, table, _ = pickle.loads(sent[0])
    assert name == "run 1" and table.equals(_table(100, 1)[1])
    parent, child = multiprocessing.Pipe()
    handoff.send(child, _table(20_000, 1))  # 6.4 MB: a shared file's layout, then its descriptor
    kind, payload, layout = parent.recv()
    assert kind == handoff._SHARED and len(payload) < 100_000
    assert layout and all(size >= handoff.LARGE for _, size in layout)
    assert all(start % handoff.ALIGNMENT == 0 for start, _ in layout)
    from multiprocessing.reduction import recv_handle

    os.close(recv_handle(parent))


def test_a_shared_file_the_system_refuses_sends_the_message_through_the_pipe(monkeypatch):
    def refused(*arguments: object) -> int:
        raise OSError(12, "Cannot allocate memory")

    monkeypatch.setattr(os, "pwrite", refused)
    parent, child = multiprocessing.Pipe()
    sender = threading.Thread(target=handoff.send, args=(child, _table(20_000, 2)))  # 6.4 MB: more than
    sender.start()  # the socket holds, so it is read while it is sent
    assert parent.poll(10), "nothing arrived: the sender gave up instead of using the pipe"
    name, table, matrix = parent.recv()  # the message itself, not a shared file's layout
    sender.join(10)
    expected = _table(20_000, 2)
    assert name == expected[0] and table.equals(expected[1]) and np.array_equal(matrix, expected[2])


def test_a_sender_that_dies_between_the_message_and_its_file_is_an_end_of_file():
    parent, child = multiprocessing.Pipe()
    child.send((handoff._SHARED, b"", [(0, 8)]))
    child.close()  # no descriptor follows
    with pytest.raises(EOFError, match="shared file did not arrive"):
        handoff.receive(parent)


def _large(seed: int) -> pd.DataFrame:
    return _table(20_000, seed)[1]


def test_the_pool_hands_large_results_over_unchanged():
    results = list(parallel_map(_large, [(1,), (2,), (3,)], workers=2, lost=lambda a, r: r))
    assert len(results) == 3
    for table in results:
        matches = [seed for seed in (1, 2, 3) if table.equals(_large(seed))]
        assert len(matches) == 1
