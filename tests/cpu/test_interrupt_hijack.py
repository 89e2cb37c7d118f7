"""Interrupt hijacking (retro/cpu/mpu.py, HIJACK_POLL; blargg's cpu_interrupts_v2 2-nmi_and_brk):
an NMI seen by cycle 3 of BRK (or of an IRQ sequence) takes its vector, B stays set in the pushed
P; one seen later is taken after the handler's first instruction.

The program: BRK at $C000 (cycles 0-6 of the call), its signature byte, then RTS at $C002.
IRQ/BRK handler at $C100: INC $10, RTI. NMI handler at $C200: PLA, PHA (the pushed P), STA $12,
INC $11, RTI.
"""

from __future__ import annotations

from retro.cpu import Machine

NEVER = 1 << 62


class NmiAt:
    """Drives the NMI line: one edge, seen from cycle `at`; IRQ low from `irq_at`."""

    drives_cpu_lines = True

    def __init__(self, at: int, irq_at: int = NEVER) -> None:
        self.nmi_next, self.irq_next, self.taken = at, irq_at, False

    def nmi_edge(self, cycle):
        if cycle >= self.nmi_next and not self.taken:
            self.taken = True
            self.nmi_next = NEVER
            return True
        return False

    def irq_low(self, cycle):
        return cycle >= self.irq_next and not self.taken_irq()

    def taken_irq(self):
        return False

    def ba_wait(self, cycle):
        return 0

    def ba_free(self, cycle):
        return NEVER

    def read(self, address, cycle):
        return 0

    def write(self, address, value, cycle):
        pass

    def peek(self, address):
        return 0


def machine(lines: NmiAt, body: list[int]) -> Machine:
    m = Machine("2a03")
    m.mpu.stop_on_brk = False
    for address, code in {0xC000: body, 0xC100: [0xE6, 0x10, 0x40],
                          0xC200: [0x68, 0x48, 0x85, 0x12, 0xE6, 0x11, 0x40],
                          0xFFFA: [0x00, 0xC2], 0xFFFE: [0x00, 0xC1]}.items():
        m.poke(address, code)
    m.attach(lines, 0xD000, 0xD0FF)
    return m


def run_brk(nmi_at: int) -> tuple[int, int, int, list[str]]:
    m = machine(NmiAt(nmi_at), [0x00, 0xEA, 0x60])
    result = m.call(0xC000, trace=True)
    irq_count, nmi_count, pushed = m.peek(0x10, 3)
    return irq_count, nmi_count, pushed, [e.mnemonic for e in result.trace]


def test_an_nmi_by_cycle_3_of_brk_takes_its_vector_with_b_set():
    for at in (0, 1, 2, 3):
        irq_count, nmi_count, pushed, _ = run_brk(at)
        assert (irq_count, nmi_count) == (0, 1), at
        assert pushed & 0x10, at                      # B set: the pushed P is BRK's


def test_an_nmi_from_cycle_4_of_brk_comes_after_the_handlers_first_instruction():
    for at in (4, 5, 6):
        irq_count, nmi_count, pushed, names = run_brk(at)
        assert (irq_count, nmi_count) == (1, 1), at
        assert names[:3] == ["BRK", "INC", "NMI"], at  # BRK's sequence does not poll at its end
        assert not pushed & 0x10                       # the NMI's own push: B clear


def test_an_nmi_early_in_an_irq_sequence_takes_it_over():
    # CLI (0-1), NOP (2-3, polls the IRQ at 2): the IRQ sequence runs 4-10; an NMI seen by 7 takes its
    # vector (the NMI handler's PLA runs first; the IRQ, still low, is served after its RTI).
    for at, first_handler in ((7, "PLA"), (8, "INC")):
        lines = NmiAt(at, irq_at=2)
        m = machine(lines, [0x58, 0xEA, 0xEA, 0x60])
        lines.irq_low = lambda cycle: m.memory[0x10] == 0   # low until the IRQ handler counted once
        names = [e.mnemonic for e in m.call(0xC000, p=0x24, trace=True).trace]
        assert names[2:4] == ["IRQ", first_handler], at
        assert m.peek(0x10, 2) == [1, 1], at
