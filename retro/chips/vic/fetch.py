"""What the VIC-II fetches from the C64's memory: sprite data through the sprite pointers, the video
matrix and character set through `$D018` and the bank, colour RAM at `$D800` (docs/vic.md, "The
VIC-II reads memory").

Addressing [Bauer 2.4.2, 3.6, 3.7, 3.8; C64 Programmer's Reference Guide p.102; Mapping the
Commodore 64, $D018 and $DD00]:
- the VIC-II sees one 16K bank, chosen by CIA 2 port A bits 0-1, inverted (`%11` = bank 0 at
  $0000, `%00` = bank 3 at $C000); a pin programmed as an input reads 1 (bank 0 after power-on);
- `$D018` bits 4-7: the video matrix at 1K steps; the 8 sprite pointers are its last bytes
  (+$3F8); sprite n's 63 bytes are at 64 * pointer within the bank;
- `$D018` bits 1-3: the character generator at 2K steps; bit 3 alone: the bitmap at 0 or 8K;
- colour RAM: 1000 nybbles at $D800, the same in every bank;
- in banks 0 and 2 the VIC-II reads the character ROM at $1000-$1FFF ($9000-$9FFF) instead of RAM.

The character ROM is Commodore's and is not shipped: a run gets it from a 4096-byte file the user
names (`RETRO_C64_CHARGEN`); without it the bytes read from that window are unknown, and reading a
collision latch that depends on them is refused (`RunError`), never answered from a guess.

`VicBankPort` is CIA 2 as far as the VIC-II needs it: port A and its data direction register. The
rest of the CIA (timers, serial port, interrupts) is not modelled: writes to it are kept and have
no effect, reads of it are refused with a RunError naming the register.
"""

from __future__ import annotations

import hashlib
from dataclasses import replace
from functools import lru_cache

import numpy as np

from retro.chips.vic.constants import (
    BANK_SIZE,
    BITMAP_BYTES,
    BITMAP_STEP,
    CHAR_ROM_BANKS,
    CHAR_ROM_BYTES,
    CHAR_ROM_OFFSET,
    CHARSET_BYTES,
    CHARSET_STEP,
    CIA2_BANK_BITS,
    CIA2_DDR_A,
    CIA2_KERNAL_DDR_A,
    CIA2_KERNAL_PORT_A,
    CIA2_PORT_A,
    CIA2_REGISTERS,
    COLOR_MASK,
    COLOR_RAM,
    CONTROL1_BMM,
    CONTROL1_ECM,
    CONTROL2_MCM,
    IDLE_ADDRESS,
    IDLE_ADDRESS_ECM,
    MEMORY_BITMAP_BIT,
    MEMORY_CHARSET_MASK,
    MEMORY_SCREEN_MASK,
    MEMORY_SCREEN_SHIFT,
    REG_CONTROL1,
    REG_CONTROL2,
    REG_MEMORY_POINTERS,
    REG_SPRITE_BACKGROUND,
    REG_SPRITE_ENABLE,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_SPRITE,
    REG_SPRITE_X_MSB,
    REG_SPRITE_Y0,
    SCREEN_CELLS,
    SCREEN_STEP,
    SPRITE_BLOCK,
    SPRITE_BYTES,
    SPRITE_COUNT,
    SPRITE_POINTERS,
    VIC_BASE,
    Video,
)
from retro.chips.vic.graphics import VicMemory
from retro.chips.vic.model import VicState, sprite_rows
from retro.errors import InputError, RunError

CHARGEN_ENV = "RETRO_C64_CHARGEN"
_NOTHING_READ = [0] * SCREEN_CELLS  # what stands for bytes the chip's collisions do not depend on
LATCH_SPRITE_SPRITE = VIC_BASE + REG_SPRITE_SPRITE  # $D01E
LATCH_SPRITE_BACKGROUND = VIC_BASE + REG_SPRITE_BACKGROUND  # $D01F
ROM_MISSING_HINT = (f"retro has no character ROM (it is Commodore's): set {CHARGEN_ENV} to a 4096-byte image of "
                    f"it (docs/vic.md \"The VIC-II reads memory\")")


class VicBankPort:
    """CIA 2 at $DD00-$DDFF as the VIC-II needs it: port A bits 0-1 pick its bank (module docstring)."""

    def __init__(self, port_a: int = CIA2_KERNAL_PORT_A, ddr_a: int = CIA2_KERNAL_DDR_A) -> None:
        self.registers = bytearray(CIA2_REGISTERS)
        self.registers[CIA2_PORT_A] = port_a
        self.registers[CIA2_DDR_A] = ddr_a

    @property
    def bank(self) -> int:
        """The VIC-II's bank 0-3: the pins of port A bits 0-1 inverted; an input pin reads 1."""
        return CIA2_BANK_BITS - (self._pins() & CIA2_BANK_BITS)

    def _pins(self) -> int:
        """Port A's pins: the outputs as written, the inputs pulled up to 1."""
        return (self.registers[CIA2_PORT_A] | ~self.registers[CIA2_DDR_A]) & 0xFF

    def set_bank(self, bank: int) -> None:
        """Program bits 0-1 as outputs selecting `bank` (what `lda #$3x; sta $dd00` does)."""
        self.registers[CIA2_DDR_A] |= CIA2_BANK_BITS
        self.registers[CIA2_PORT_A] = (self.registers[CIA2_PORT_A] & ~CIA2_BANK_BITS) | (CIA2_BANK_BITS - bank)

    def read(self, address: int, cycle: int) -> int:
        register = address % CIA2_REGISTERS
        if register == CIA2_PORT_A:
            return self._pins()
        if register == CIA2_DDR_A:
            return self.registers[CIA2_DDR_A]
        raise RunError(f"the program read CIA 2 at ${address:04X}: retro models only CIA 2's port A and its data "
                       f"direction ($DD00, $DD02: the VIC-II's bank), no timers, serial port or interrupts")

    def write(self, address: int, value: int, cycle: int) -> None:
        self.registers[address % CIA2_REGISTERS] = value & 0xFF

    def peek(self, address: int) -> int:
        return self.registers[address % CIA2_REGISTERS]


def vic_bases(registers: bytes, bank: int) -> tuple[int, int, int]:
    """(video matrix, character set, bitmap) as 16-bit addresses of the VIC-II's view for `$D018`."""
    d018 = registers[REG_MEMORY_POINTERS]
    base = bank * BANK_SIZE
    return (base + ((d018 & MEMORY_SCREEN_MASK) >> MEMORY_SCREEN_SHIFT) * SCREEN_STEP,
            base + ((d018 & MEMORY_CHARSET_MASK) >> 1) * CHARSET_STEP,
            base + (BITMAP_STEP if d018 & MEMORY_BITMAP_BIT else 0))


def in_char_rom(address: int) -> bool:
    """Whether the VIC-II reads the character ROM at this address of its 64K view."""
    return address // BANK_SIZE in CHAR_ROM_BANKS and CHAR_ROM_OFFSET <= address % BANK_SIZE < CHAR_ROM_OFFSET + \
        CHAR_ROM_BYTES


class VicFetcher:
    """Reads what the VIC-II fetches from `ram` (the bus's 64K list; colour RAM is its $D800-$DBE7)
    and hands the device a VicState holding it. `char_rom`: 4096 bytes, or None when not available."""

    def __init__(self, ram: list[int], bank_port: VicBankPort, char_rom: bytes | None = None) -> None:
        if char_rom is not None and len(char_rom) != CHAR_ROM_BYTES:
            raise ValueError("a character ROM image is 4096 bytes")
        self.ram = ram
        self.bank_port = bank_port
        self.char_rom = None if char_rom is None else list(char_rom)
        self._raw: tuple | None = None
        self._key = b""
        self._built: tuple = ((bytes(SPRITE_BYTES),) * SPRITE_COUNT, VicMemory.blank())
        self.missing_sprites = 0  # bit n: sprite n's data came from the absent character ROM
        self.missing_graphics = False  # the screen, character set or bitmap did
        self._counts: tuple | None = None  # (registers, sprite_line_counts) of the last registers asked about
        self._line = -1  # the raster line (counted from the device's start) in which `due` last said yes

    def due(self, video: Video, registers: bytearray, lo: int, hi: int) -> bool:
        """Whether the device drawing frame time [lo, hi) reads memory first: an enabled sprite may
        draw in it (sprites_drawn_between) and memory was not read yet in the raster line of `hi`
        (the VIC-II fetches a sprite's row once a line, in the line before it is shown)."""
        line = hi // video.cycles_per_line
        if line == self._line:
            return False
        if self._counts is None or self._counts[0] != registers:
            self._counts = (bytes(registers), sprite_line_counts(video, registers))
        if not sprites_drawn_between(video, self._counts[1], lo, hi):
            return False
        self._line = line
        return True

    def _read(self, address: int, length: int) -> tuple[list[int], bool]:
        """`length` bytes of the VIC-II's view from `address` (within one bank), and whether any came
        from the character ROM when it is absent (those read as 0)."""
        end = address + length
        bank_base = address - address % BANK_SIZE
        if bank_base // BANK_SIZE not in CHAR_ROM_BANKS:
            return self.ram[address:end], False
        rom_lo, rom_hi = bank_base + CHAR_ROM_OFFSET, bank_base + CHAR_ROM_OFFSET + CHAR_ROM_BYTES
        if end <= rom_lo or address >= rom_hi:
            return self.ram[address:end], False
        lo, hi = max(address, rom_lo), min(end, rom_hi)
        rom = [0] * (hi - lo) if self.char_rom is None else self.char_rom[lo - rom_lo:hi - rom_lo]
        return self.ram[address:lo] + rom + self.ram[hi:end], self.char_rom is None

    def state_for(self, state: VicState, registers: bytes) -> VicState:
        """`state` with the sprite data and memory the VIC-II fetches now with `registers` (the
        device's, as written) (the same object when nothing it fetches changed)."""
        bank = self.bank_port.bank
        screen_at, charset_at, bitmap_at = vic_bases(registers, bank)
        control1 = registers[REG_CONTROL1]
        enabled = registers[REG_SPRITE_ENABLE]
        pointers, missing_pointers = self._read(screen_at + SPRITE_POINTERS, SPRITE_COUNT)
        sprites = []
        missing_sprites = 0
        for n, pointer in enumerate(pointers):  # a disabled sprite collides with nothing: not read
            data, missing = (self._read(bank * BANK_SIZE + pointer * SPRITE_BLOCK, SPRITE_BYTES) if enabled >> n & 1
                             else (_NOTHING_READ[:SPRITE_BYTES], False))
            sprites.append(data)
            missing_sprites |= (1 << n) if missing or missing_pointers else 0
        # only what decides the foreground is read: no video matrix in bitmap modes, no colour RAM
        # unless multicolor text (its bit 3) [graphics.py]
        bitmap_mode = bool(control1 & CONTROL1_BMM)
        screen, missing_screen = (_NOTHING_READ[:SCREEN_CELLS], False) if bitmap_mode else self._read(screen_at,
                                                                                                    SCREEN_CELLS)
        colour = (self.ram[COLOR_RAM:COLOR_RAM + SCREEN_CELLS] if registers[REG_CONTROL2] & CONTROL2_MCM
                  and not bitmap_mode else _NOTHING_READ[:SCREEN_CELLS])
        shapes, missing_shapes = self._read(bitmap_at, BITMAP_BYTES) if bitmap_mode else self._read(charset_at,
                                                                                                   CHARSET_BYTES)
        idle, missing_idle = self._read(bank * BANK_SIZE + (IDLE_ADDRESS_ECM if control1 & CONTROL1_ECM
                                                            else IDLE_ADDRESS), 1)
        raw = (bitmap_mode, pointers, sprites, screen, colour, shapes, idle)
        self.missing_sprites = missing_sprites
        self.missing_graphics = missing_screen or missing_shapes or missing_idle
        if raw != self._raw:
            self._raw = raw
            sprite_data = tuple(bytes(data) for data in sprites)
            blank = VicMemory.blank()
            shape_array = np.array(shapes, np.uint8)
            memory = VicMemory(np.array(screen, np.uint8), np.array(colour, np.uint8) & COLOR_MASK,
                               blank.charset if bitmap_mode else shape_array,
                               shape_array if bitmap_mode else blank.bitmap, idle[0])
            digest = hashlib.sha1(bytes([bitmap_mode, idle[0]]) + b"".join(sprite_data) + bytes(screen)
                                  + bytes(colour) + bytes(shapes))
            self._key = digest.digest()
            self._built = (sprite_data, memory)
        if state.view_key == self._key:
            return state
        sprite_data, memory = self._built
        return replace(state, sprite_data=sprite_data, memory=memory, view_key=self._key)

    def unknown_latches(self, sprites: int) -> list[str]:
        """The latches whose value, with `sprites` enabled, depends on the absent character ROM."""
        unknown = []
        if self.missing_sprites & sprites:
            unknown.append(f"${LATCH_SPRITE_SPRITE:04X}")
        if sprites and (self.missing_graphics or self.missing_sprites & sprites):
            unknown.append(f"${LATCH_SPRITE_BACKGROUND:04X}")
        return unknown

    def check_latch(self, register: int, sprites: int) -> None:
        """RunError when the program reads a latch ($D01E, $D01F: `register`) whose value, with
        `sprites` enabled, depends on bytes of the absent character ROM."""
        what = f"${register:04X}"
        if what in self.unknown_latches(sprites):
            fetched = "sprite data" if register == LATCH_SPRITE_SPRITE else "sprite data, screen, character set or bitmap"
            raise RunError(f"the program read {what}, whose value depends on {fetched} the VIC-II fetches from the "
                           f"character ROM ($1000-$1FFF of bank 0 or 2): {ROM_MISSING_HINT}")


FIRST_FREE_ADDRESS = 0x0200  # zero page and stack are the CPU's: nothing the VIC-II shows is put there


def memory_parts(state: VicState, bank: int) -> list[tuple[str, int, list[int]]]:
    """Where a VIC-II view given directly (a scene's `[memory]` and sprite data) goes in the C64's
    memory so that the chip fetches it back: (part, address, bytes) for every part that is not all
    zero (zeros are what RAM holds already). The screen goes to the video matrix `$D018` names, the
    character set and bitmap to theirs, colour RAM to $D800, and the sprites' data to 8 free 64-byte
    blocks at the top of the bank with the pointers (screen + $3F8) set to them. InputError when two
    parts overlap, a part lands on the character ROM's window or on pages $00-$01."""
    screen_at, charset_at, bitmap_at = vic_bases(state.registers, bank)
    memory = state.memory
    parts = [(name, at, values.tolist()) for name, at, values in
             (("screen", screen_at, memory.screen), ("charset", charset_at, memory.charset),
              ("bitmap", bitmap_at, memory.bitmap)) if values.any()]
    taken = [(at, at + len(values)) for _, at, values in parts]
    data = [n for n in range(SPRITE_COUNT) if any(state.sprite_data[n])]
    if data:
        pointers = screen_at + SPRITE_POINTERS
        taken.append((screen_at, pointers + SPRITE_COUNT))
        block = _free_blocks(bank, taken, len(data))
        pointer_bytes = [0] * SPRITE_COUNT
        for i, n in enumerate(data):
            pointer_bytes[n] = block + i
            parts.append((f"sprite {n} data", bank * BANK_SIZE + (block + i) * SPRITE_BLOCK,
                          list(state.sprite_data[n][:SPRITE_BYTES])))
        parts.append(("sprite pointers", pointers, pointer_bytes))
    for i, (name, at, values) in enumerate(parts):
        end = at + len(values)
        if at < FIRST_FREE_ADDRESS:
            raise _placement_error(name, at, end, state, "is on the zero page or the stack")
        if any(in_char_rom(a) for a in range(at, end)):
            raise _placement_error(name, at, end, state, "is where the VIC-II reads the character ROM")
        for other, other_at, other_values in parts[:i]:
            if at < other_at + len(other_values) and other_at < end:
                raise _placement_error(name, at, end, state, f"overlaps the {other} at ${other_at:04X}")
    if memory.color.any():
        parts.append(("color", COLOR_RAM, memory.color.tolist()))
    return parts


def _free_blocks(bank: int, taken: list[tuple[int, int]], count: int) -> int:
    """The first of `count` consecutive sprite blocks (numbers within the bank), from the top down,
    clear of `taken`, of the character ROM and of pages $00-$01."""
    base = bank * BANK_SIZE
    blocks = BANK_SIZE // SPRITE_BLOCK
    for first in range(blocks - count, -1, -1):
        lo, hi = base + first * SPRITE_BLOCK, base + (first + count) * SPRITE_BLOCK
        if lo < FIRST_FREE_ADDRESS or any(in_char_rom(a) for a in range(lo, hi, SPRITE_BLOCK)):
            continue
        if all(hi <= a or b <= lo for a, b in taken):
            return first
    raise InputError(f"no room for {count} sprites' data in VIC-II bank {bank}")


def _placement_error(name: str, at: int, end: int, state: VicState, why: str) -> InputError:
    return InputError(f"the {name} (${at:04X}-${end - 1:04X}, from $D018 = ${state.registers[REG_MEMORY_POINTERS]:02X} "
                      f"and the bank) {why}: set registers.\"$d018\" so that the parts the VIC-II reads lie apart")


SPRITE_LINE_MARGIN = 2  # lines either side of a sprite's rows: a row spills into the next line's first cycles


@lru_cache(maxsize=256)
def _sprite_line_counts(video: Video, enabled: int, ys: bytes, expand_y: int) -> np.ndarray:
    """Cumulative count of the lines (two frames long) where an enabled sprite may draw a pixel."""
    near = np.zeros(video.lines, bool)
    for n in range(SPRITE_COUNT):
        if enabled >> n & 1:
            rows = sprite_rows(video, ys[n], bool(expand_y >> n & 1)) >= 0
            for shift in range(-SPRITE_LINE_MARGIN, SPRITE_LINE_MARGIN + 1):
                near |= np.roll(rows, shift)
    counts = np.concatenate(([0], np.cumsum(np.concatenate([near, near]))))
    counts.flags.writeable = False
    return counts


def sprite_line_counts(video: Video, registers: bytes) -> np.ndarray | None:
    """Cumulative count of the lines (two frames long) where an enabled sprite may draw, or None
    when no sprite is enabled."""
    enabled = registers[REG_SPRITE_ENABLE]
    if not enabled:
        return None
    return _sprite_line_counts(video, enabled, bytes(registers[REG_SPRITE_Y0:REG_SPRITE_X_MSB:2]),
                               registers[REG_SPRITE_EXPAND_Y])


def sprites_drawn_between(video: Video, counts: np.ndarray | None, lo: int, hi: int) -> bool:
    """Whether an enabled sprite may draw a pixel in frame time [lo, hi) (times counted from a frame's
    start, repeating every frame; `counts` from sprite_line_counts): outside those times what the
    VIC-II fetches changes no collision."""
    if counts is None or hi <= lo:
        return False
    frame_cycles = video.frame_cycles
    if hi - lo >= frame_cycles:
        return True
    within = lo % frame_cycles
    first = within // video.cycles_per_line
    last = first + (hi - 1 - lo + within % video.cycles_per_line) // video.cycles_per_line
    return counts[last + 1] != counts[first]
