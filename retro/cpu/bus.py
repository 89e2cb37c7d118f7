"""The bus: plain RAM as a Python list (as fast as bare py65) plus devices mapped onto pages.

The MPU looks up `page_devices[address >> 8]` on every data read and write; None means RAM. A device
that owns only part of a page (the NES $4014 DMA register in the $40xx page) is wrapped in a
dispatcher that sends the rest of the page to RAM. Devices are told the CPU cycle of each access.
"""

from __future__ import annotations

from typing import Protocol

from retro.errors import InputError

MEMORY_SIZE = 0x10000
PAGE_SIZE = 0x100
PAGE_COUNT = MEMORY_SIZE // PAGE_SIZE
NEVER = 1 << 62  # a cycle no clock reaches: "no interrupt can come", "BA stays high"
FIRST_DEVICE_ADDRESS = 0x0200  # zero page and stack stay RAM: their accesses bypass device timing


class Device(Protocol):
    """A chip on the bus. `cycle` is the CPU cycle (machine clock) of the bus access."""

    def read(self, address: int, cycle: int) -> int: ...

    def write(self, address: int, value: int, cycle: int) -> None: ...

    def peek(self, address: int) -> int:
        """The value a read would return now, without its side effects (for the host)."""
        ...


class CpuLines(Protocol):
    """A chip that drives the CPU's RDY (via BA), IRQ and NMI lines, in machine cycles.

    At most one per machine (the VIC-II on a C64, the PPU on a NES); a device says it is one with
    `drives_cpu_lines = True`. `irq_next` / `nmi_next` are cheap lower bounds the CPU compares with
    its poll cycle before asking (a cycle before which the line cannot go low / no edge can come).
    """

    drives_cpu_lines: bool
    irq_next: int
    nmi_next: int

    def ba_wait(self, cycle: int) -> int:
        """Cycles from `cycle` until BA is high (0 while it is high)."""
        ...

    def ba_free(self, cycle: int) -> int:
        """Cycles from `cycle` on during which BA stays high (0 if it is low)."""
        ...

    def irq_low(self, cycle: int) -> bool:
        """Whether the IRQ line is low in `cycle`."""
        ...

    def nmi_edge(self, cycle: int) -> bool:
        """Whether an NMI edge came at or before `cycle` and was not taken yet (taking it consumes it)."""
        ...


class _PartialPage:
    """One page shared by RAM and devices that each own a sub-range of it."""

    def __init__(self, page: int, memory: list[int]):
        self.page = page
        self.memory = memory
        self.ranges: list[tuple[int, int, Device]] = []

    def _owner(self, address: int):
        for start, end, device in self.ranges:
            if start <= address <= end:
                return device
        return None

    def read(self, address: int, cycle: int) -> int:
        device = self._owner(address)
        return self.memory[address] if device is None else device.read(address, cycle)

    def write(self, address: int, value: int, cycle: int) -> None:
        device = self._owner(address)
        if device is None:
            self.memory[address] = value
        else:
            device.write(address, value, cycle)

    def peek(self, address: int) -> int:
        device = self._owner(address)
        return self.memory[address] if device is None else device.peek(address)


class Bus:
    def __init__(self) -> None:
        self.memory: list[int] = [0] * MEMORY_SIZE
        self.page_devices: list = [None] * PAGE_COUNT
        self.devices: list[tuple[int, int, Device]] = []

    def map(self, device: Device, start: int, end: int) -> None:
        """Give device the addresses start..end (inclusive)."""
        if not 0 <= start <= end < MEMORY_SIZE:
            raise InputError(f"device range ${start:04X}-${end:04X} is outside the 64 KiB address space")
        if start < FIRST_DEVICE_ADDRESS:
            raise InputError(f"device range ${start:04X}-${end:04X}: pages $00 and $01 (zero page, stack) are RAM only, "
                             "because pointer and stack accesses are not timed per bus cycle")
        for other_start, other_end, _ in self.devices:
            if start <= other_end and other_start <= end:
                raise InputError(f"device range ${start:04X}-${end:04X} overlaps ${other_start:04X}-${other_end:04X}")
        self.devices.append((start, end, device))
        for page in range(start // PAGE_SIZE, end // PAGE_SIZE + 1):
            page_start, page_end = page * PAGE_SIZE, page * PAGE_SIZE + PAGE_SIZE - 1
            current = self.page_devices[page]
            if start <= page_start and page_end <= end and current is None:
                self.page_devices[page] = device
                continue
            if not isinstance(current, _PartialPage):
                partial = _PartialPage(page, self.memory)
                if current is not None:
                    partial.ranges.append((page_start, page_end, current))
                self.page_devices[page] = current = partial
            current.ranges.append((max(start, page_start), min(end, page_end), device))

    def peek(self, address: int) -> int:
        device = self.page_devices[address >> 8]
        return self.memory[address] if device is None else device.peek(address)

    def poke(self, address: int, value: int) -> None:
        """Host write to RAM underneath any device (loading programs and data)."""
        self.memory[address] = value & 0xFF

    def load(self, origin: int, data: bytes) -> None:
        if origin < 0 or origin + len(data) > MEMORY_SIZE:
            raise InputError(f"{len(data)} bytes at ${origin:04X} do not fit below $10000")
        self.memory[origin:origin + len(data)] = list(data)
