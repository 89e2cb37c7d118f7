"""Memory of the batched 6502 (retro.cpu.batch): one shared 64 KiB image, plus a private copy per
lane of every page some lane writes or that holds per-lane inputs; a page written in many places
becomes one dense (256 x lanes) block. Bounded: past `limit` bytes it raises LaneMemoryFull (the
caller splits the batch)."""

from __future__ import annotations

import numpy as np

from retro.errors import InputError

MEMORY_SIZE = 0x10000
PAGE_SIZE = 0x100
PAGES = MEMORY_SIZE // PAGE_SIZE
BYTE = 0xFF
MAX_PRIVATE_BYTES = 512 << 20  # per-lane bytes a batch may hold before it must be split
DENSE_AFTER = 24  # a page with more per-lane bytes than this is held as one block


class LaneMemoryFull(Exception):
    """The per-lane page copies of this batch would pass MAX_PRIVATE_BYTES: run fewer lanes at a time."""


class LaneMemory:
    """A shared 64 KiB image and, per address that differs between lanes, a row of one value per lane.

    Rows are int32 (registers' type, so arithmetic never wraps early) and made on first write. A page
    that gets more than DENSE_AFTER rows (a table the routine writes) becomes one (256 x lanes) block,
    its rows views into it, so accesses with per-lane addresses stay one gather."""

    def __init__(self, image, lanes: int, limit: int = MAX_PRIVATE_BYTES) -> None:
        self.shared = np.frombuffer(bytes(image), dtype=np.uint8).copy()
        if len(self.shared) != MEMORY_SIZE:
            raise InputError(f"a memory image is {MEMORY_SIZE} bytes, got {len(self.shared)}")
        self.lanes = lanes
        self.limit = limit
        self.rows: dict[int, np.ndarray] = {}
        self.page_rows: dict[int, list[int]] = {}  # sparse pages: their addresses with rows
        self.dense: dict[int, np.ndarray] = {}
        self.is_private = np.zeros(PAGES, dtype=bool)  # the page has rows (sparse or dense)
        self.all_lanes = np.arange(lanes)

    def _held(self) -> int:
        return (len(self.rows) + (PAGE_SIZE - 1) * len(self.dense)) * self.lanes * 4

    def row(self, address: int) -> np.ndarray:
        """The per-lane row of an address (made from the shared image on first use)."""
        row = self.rows.get(address)
        if row is None:
            if self._held() + self.lanes * 4 > self.limit:
                raise LaneMemoryFull(f"{self.lanes} lanes with {len(self.rows) + 1} private bytes")
            row = np.full(self.lanes, self.shared[address], dtype=np.int32)
            self.rows[address] = row
            page = address >> 8
            self.is_private[page] = True
            listed = self.page_rows.setdefault(page, [])
            listed.append(address)
            if len(listed) > DENSE_AFTER:
                self._densify(page)
                row = self.rows[address]
        return row

    def _densify(self, page: int) -> None:
        if self._held() + PAGE_SIZE * self.lanes * 4 > self.limit:
            raise LaneMemoryFull(f"{self.lanes} lanes with a page of per-lane bytes more")
        base = page * PAGE_SIZE
        block = np.repeat(self.shared[base:base + PAGE_SIZE].astype(np.int32)[:, None], self.lanes, axis=1)
        for address in self.page_rows.pop(page, []):
            block[address & BYTE] = self.rows[address]
        for offset in range(PAGE_SIZE):
            self.rows[base + offset] = block[offset]
        self.dense[page] = block
        self.is_private[page] = True

    def lanes_of(self, idx) -> np.ndarray:
        return self.all_lanes[idx] if isinstance(idx, slice) else idx

    def read(self, idx, address):
        """The byte at address (an int, or an array aligned with idx) for the lanes idx (an index
        array or slice(None) for every lane)."""
        if isinstance(address, (int, np.integer)):
            row = self.rows.get(int(address))
            if row is None:
                return int(self.shared[address])
            return row.copy() if isinstance(idx, slice) else row[idx]  # never a view: the row may change
        values = self.shared[address].astype(np.int32)
        if self.rows:
            pages = address >> 8
            lanes = None
            for page in np.flatnonzero(self.is_private).tolist():
                hit = pages == page
                if not hit.any():
                    continue
                lanes = self.lanes_of(idx) if lanes is None else lanes
                block = self.dense.get(page)
                if block is not None:
                    values[hit] = block[address[hit] & BYTE, lanes[hit]]
                    continue
                for row_address in self.page_rows[page]:
                    at = hit & (address == row_address)
                    if at.any():
                        values[at] = self.rows[row_address][lanes[at]]
        return values

    def write(self, idx, address, value) -> None:
        """Store value (an int or an array aligned with idx) at address for the lanes idx."""
        if isinstance(address, (int, np.integer)):
            self.row(int(address))[idx] = value
            return
        lanes = self.lanes_of(idx)
        array = not isinstance(value, (int, np.integer))
        targets = np.unique(address)
        if len(targets) == 1:
            self.row(int(targets[0]))[lanes] = value
            return
        for page in np.unique(targets >> 8).tolist():
            in_page = targets[(targets >> 8) == page]
            if page not in self.dense and len(in_page) + len(self.page_rows.get(page, ())) > DENSE_AFTER:
                self._densify(page)
            block = self.dense.get(page)
            if block is not None:
                hit = (address >> 8) == page
                block[address[hit] & BYTE, lanes[hit]] = value[hit] if array else value
                continue
            for target in in_page.tolist():
                at = address == target
                self.row(target)[lanes[at]] = value[at] if array else value

    def fill(self, address: int, values) -> None:
        """Per-lane values (an array of one byte per lane) at one address, for every lane."""
        self.row(address)[:] = values
