"""Algebraic loops: cycles of direct feedthrough through the connections of a system (the graph
is built by ``system.dependency_graph``; this module only searches it).

A port depends on another when a connection joins them (source output -> target input) or when
a participant's output depends directly on one of its inputs: for an FMU as its ModelStructure
says (``<Outputs>`` dependencies; an output without a dependency list depends on every input),
for a block as its ``feedthrough`` attribute says (``True``, the default for a block with
inputs: every output on every input; ``False``: outputs from the block's state only). A cycle
means the values at a communication point depend on themselves: an explicit master (Jacobi,
Gauss-Seidel) breaks it with a delay of one step, the iterative master solves it.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from typing import TypeVar

Node = TypeVar("Node", bound=Hashable)


def find_loop(graph: dict[Node, list[Node]]) -> list[Node] | None:
    """One cycle of ``graph`` (node -> the nodes that depend on it), its nodes in order with the
    first repeated at the end, or None."""
    state: dict[Node, int] = {}  # 1: on the current path, 2: done
    for root in list(graph):
        if state.get(root):
            continue
        path: list[Node] = []
        stack: list[tuple[Node, int]] = [(root, 0)]
        while stack:
            node, index = stack.pop()
            if index == 0:
                state[node] = 1
                path.append(node)
            successors = graph.get(node, [])
            if index < len(successors):
                stack.append((node, index + 1))
                following = successors[index]
                if state.get(following) == 1:
                    return path[path.index(following):] + [following]
                if not state.get(following):
                    stack.append((following, 0))
            else:
                state[node] = 2
                path.pop()
    return None


def describe(loop: Sequence[object]) -> str:
    return " -> ".join(str(node) for node in loop)
