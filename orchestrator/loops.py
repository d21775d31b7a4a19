"""Algebraic loops: cycles of direct feedthrough through the connections of a system.

A port depends on another when a connection joins them (source output -> target input) or when
a participant's output depends directly on one of its inputs: for an FMU as its ModelStructure
says (``<Outputs>`` dependencies; an output without a dependency list depends on every input),
for a block as its ``feedthrough`` attribute says (``True``, the default for a block with
inputs: every output on every input; ``False``: outputs from the block's state only). A cycle
means the values at a communication point depend on themselves: an explicit master (Jacobi,
Gauss-Seidel) breaks it with a delay of one step, the iterative master solves it.
"""

from __future__ import annotations

from collections.abc import Iterable

from .system import BlockEntry, Connection, FmuEntry, Port


def dependency_graph(fmus: Iterable[FmuEntry], blocks: Iterable[BlockEntry],
                     connections: Iterable[Connection]) -> dict[Port, list[Port]]:
    """port -> the ports that depend on it directly."""
    graph: dict[Port, list[Port]] = {}

    def edge(a: Port, b: Port) -> None:
        graph.setdefault(a, []).append(b)

    for connection in connections:
        edge(connection.source, connection.target)
    for fmu in fmus:
        inputs = [v.name for v in fmu.description.modelVariables if v.causality == "input"]
        for unknown in fmu.description.outputs:
            sources = inputs if unknown.dependencies is None else [d.name for d in unknown.dependencies
                                                                   if d.causality == "input"]
            for name in sources:
                edge(Port(fmu.name, name), Port(fmu.name, unknown.variable.name))
    for entry in blocks:
        block = entry.block
        if getattr(block, "feedthrough", bool(block.inputs)):
            for name in block.inputs:
                for output in block.outputs:
                    edge(Port(entry.name, name), Port(entry.name, output))
    return graph


def find_loop(graph: dict[Port, list[Port]]) -> list[Port] | None:
    """One cycle of ``graph`` (its ports in order, the first repeated at the end), or None."""
    state: dict[Port, int] = {}  # 1: on the current path, 2: done
    for root in list(graph):
        if state.get(root):
            continue
        path: list[Port] = []
        stack: list[tuple[Port, int]] = [(root, 0)]
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


def describe(loop: list[Port]) -> str:
    return " -> ".join(str(port) for port in loop)
