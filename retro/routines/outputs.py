"""A call's outputs read back, one value per port in the spec's order, with the same code for one
call on Machine (ints) and for the lanes of a batched or compiled block (arrays); how a value is
written in reports."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from retro.routines.spec import Port
from retro.routines.world import WORLD_PLACES


def port_values(ports: Sequence[Port], registers: dict, p, read: Callable, widen: Callable, table: Callable,
                world: Callable | None = None, located: dict | None = None, read_at: Callable | None = None) -> list:
    """The outputs of a call, one value per port in the spec's order, read from the registers, P and
    memory (`read(address)`): the same code for one call (ints) and for lanes of the batched core
    (arrays), which differ only in `widen` (a byte or a flag as the output's number type) and
    `table` (bytes of a table output together). An output placed by the case is read from the
    addresses `located` gives it (output index -> addresses of its bytes) with `read_at`; `world(place)`:
    a world output's byte (retro.routines.world)."""
    values = []
    for k, port in enumerate(ports):
        read_place = world if port.places[0].kind in WORLD_PLACES else None
        if port.via is not None:
            data = [read_at(address) for address in located[k]]
            values.append(table(data) if port.table else
                          sum((widen(byte) << (8 * i) for i, byte in enumerate(data)), widen(0)))
        elif port.flag:
            values.append(widen((p & port.places[0].bit) != 0))
        elif port.table:
            values.append(table([read(place.address) if read_place is None else read_place(place)
                                 for place in port.places]))
        else:
            value = widen(0)
            for shift, place in enumerate(port.places):
                byte = (read_place(place) if read_place is not None else
                        registers[place.register] if place.kind == "register" else read(place.address))
                value = value | widen(byte) << (8 * shift)
            values.append(value)
    return values


def describe_value(port: Port, value) -> str:
    if port.table:
        return "[" + " ".join(f"{v:02x}" for v in value) + "]"
    if port.address:  # a pointer or S: an address, as a 6502 programmer writes it
        return f"${value:0{2 if port.bits == 8 else 4}X}"
    return str(value)


def row_of(arrays: list, i: int) -> tuple:
    """Case i of per-output arrays ((n,) numbers or (n, bytes) tables) as the tuple a scalar run gives."""
    return tuple(tuple(a[i].tolist()) if a.ndim == 2 else int(a[i]) for a in arrays)
