"""VIC-II hardware numbers, each named once (6569 PAL, 6567R8 NTSC, 6567R56A old NTSC).

Sources:
- [Bauer] Christian Bauer, "The MOS 6567/6569 video controller (VIC-II) and its application in the
  Commodore 64" (1996): 3.2 registers and unused bits, 3.4 frame and display window dimensions,
  3.6.1 X coordinates, 3.7 graphics modes and idle state, 3.8 sprites, 3.9 border, 3.12 interrupts.
- [PRG] Commodore 64 Programmer's Reference Guide, p.145 (sprite-sprite / sprite-data collisions).
"""

from __future__ import annotations

from dataclasses import dataclass

# ---- address space [Bauer 3.2] ------------------------------------------------------------------
VIC_BASE = 0xD000
VIC_LAST = 0xD3FF  # the 47 registers repeat every 64 bytes through $D000-$D3FF
REGISTER_COUNT = 47  # $D000-$D02E
MIRROR_SIZE = 64  # address & (MIRROR_SIZE - 1) selects the register
UNUSED_READ = 0xFF  # $D02F-$D03F

# register offsets from $D000
REG_SPRITE_X0 = 0x00  # X of sprite n at 2n, Y at 2n+1
REG_SPRITE_Y0 = 0x01
REG_SPRITE_X_MSB = 0x10  # bit n: bit 8 of sprite n's X
REG_CONTROL1 = 0x11  # $D011: YSCROLL, RSEL, DEN, BMM, ECM, RST8
REG_RASTER = 0x12  # $D012
REG_LIGHTPEN_X = 0x13
REG_LIGHTPEN_Y = 0x14
REG_SPRITE_ENABLE = 0x15  # $D015
REG_CONTROL2 = 0x16  # $D016: XSCROLL, CSEL, MCM
REG_SPRITE_EXPAND_Y = 0x17  # $D017
REG_MEMORY_POINTERS = 0x18  # $D018
REG_IRQ_LATCH = 0x19  # $D019
REG_IRQ_ENABLE = 0x1A  # $D01A
REG_SPRITE_PRIORITY = 0x1B  # $D01B: 1 = behind foreground graphics
REG_SPRITE_MULTICOLOR = 0x1C  # $D01C
REG_SPRITE_EXPAND_X = 0x1D  # $D01D
REG_SPRITE_SPRITE = 0x1E  # $D01E: sprite-sprite collision latch
REG_SPRITE_BACKGROUND = 0x1F  # $D01F: sprite-background collision latch
REG_BORDER_COLOR = 0x20
REG_BACKGROUND0 = 0x21  # $D021-$D024
REG_SPRITE_MC0 = 0x25  # sprite multicolor 0 (pair 01)
REG_SPRITE_MC1 = 0x26  # sprite multicolor 1 (pair 11)
REG_SPRITE_COLOR0 = 0x27  # $D027-$D02E

# Bits that do not exist read as 1 [Bauer 3.2, register table]
UNUSED_BITS = {REG_CONTROL2: 0xC0, REG_MEMORY_POINTERS: 0x01, REG_IRQ_LATCH: 0x70, REG_IRQ_ENABLE: 0xF0,
               **{reg: 0xF0 for reg in range(REG_BORDER_COLOR, REG_SPRITE_COLOR0 + 8)}}
READ_ONLY_LATCHES = (REG_SPRITE_SPRITE, REG_SPRITE_BACKGROUND)

# $D011
CONTROL1_YSCROLL = 0x07
CONTROL1_RSEL = 0x08
CONTROL1_DEN = 0x10
CONTROL1_BMM = 0x20
CONTROL1_ECM = 0x40
CONTROL1_RST8 = 0x80
# $D016
CONTROL2_XSCROLL = 0x07
CONTROL2_CSEL = 0x08
CONTROL2_MCM = 0x10

# $D019 / $D01A [Bauer 3.12]
IRQ_RASTER = 0x01
IRQ_SPRITE_BACKGROUND = 0x02  # IMBC
IRQ_SPRITE_SPRITE = 0x04  # IMMC
IRQ_LIGHTPEN = 0x08
IRQ_SOURCES = 0x0F
IRQ_ANY = 0x80  # reads 1 while a latched source is enabled in $D01A

SPRITE_COUNT = 8
COLOR_MASK = 0x0F

# ---- sprites [Bauer 3.8, PRG p.145] --------------------------------------------------------------
SPRITE_WIDTH = 24
SPRITE_HEIGHT = 21
SPRITE_BYTES = 63
SPRITE_BLOCK = 64  # sprite data sits in 64-byte blocks; the last byte is unused
SPRITE_BYTES_PER_ROW = 3
SPRITE_MC_WIDTH = SPRITE_WIDTH // 2  # multicolor: 12 pairs of bits per row
Y_COMPARE_MASK = 0xFF  # the sprite Y compare sees only the low 8 bits of the raster line
X_BITS_MASK = 0x1FF
SPRITE_X_POSITIONS = X_BITS_MASK + 1  # 9-bit X: 0..511 ($D010 holds bit 8)

# ---- screen geometry [Bauer 3.4, 3.7] -------------------------------------------------------------
TEXT_COLUMNS = 40
TEXT_ROWS = 25
CHAR_HEIGHT = 8
CELL_WIDTH = 8
SCREEN_CELLS = TEXT_COLUMNS * TEXT_ROWS  # 1000
CHARSET_BYTES = 256 * CHAR_HEIGHT  # 2048
BITMAP_BYTES = SCREEN_CELLS * CHAR_HEIGHT  # 8000
ECM_CODE_MASK = 0x3F  # ECM: the character shape comes from code & $3F; bits 6-7 pick the background
ECM_BITMAP_ADDRESS_MASK = 0x19FF  # ECM+BMM: the g-access loses address bits 9 and 10 [Bauer 3.7.3.7]
MULTICOLOR_TEXT_FLAG = 0x08  # colour RAM bit 3 makes a character multicolor [Bauer 3.7.3.2]
GRAPHICS_FIRST_X = 24  # column 0 pixel 0 with XSCROLL = 0: X = 24 + 8c + k + XSCROLL
GRAPHICS_FIRST_LINE = 48  # text row r starts on line 48 + YSCROLL + 8r ($30: first bad line possible)
BAD_LINE_LAST = 0xF7
# Display window [Bauer 3.9]: (first line, last line) by RSEL, (first X, last X) by CSEL
WINDOW_LINES = {1: (51, 250), 0: (55, 246)}
WINDOW_X = {1: (24, 343), 0: (31, 334)}


@dataclass(frozen=True, eq=False)  # three instances only: identity hashing keeps the caches cheap
class Video:
    """One chip's raster: lines, cycles and the X coordinates that exist [Bauer 3.4, 3.6.1]."""

    name: str
    chip: str
    lines: int
    cycles_per_line: int
    x_positions: int  # X runs 0 .. x_positions-1 (the 6569 has no $1F8-$1FF)
    first_x: int  # X coordinate drawn first in a raster line (cycle 1, where the raster IRQ fires)
    first_visible_line: int  # after the vertical blank
    visible_lines: int
    first_visible_x: int
    visible_pixels: int  # per line, in drawing order from first_visible_x (through the X wrap)
    # Sprite 0's fetch cycle: its p-access (first phase) and its first s-access (second phase),
    # so the first cycle the VIC takes from the CPU; the other two s-accesses take the next cycle.
    # Sprite n fetches in this cycle + 2n (SPRITE_DMA_CYCLES per sprite) and the next, in the line
    # before the one where the row is shown (numbers past the line's last cycle fall in the next
    # line); BA goes low BA_LEAD cycles before. The same cycle places the sprite gap (see
    # SPRITE_HALT_PIXEL below). Sources, docs/vic.md "Sprite DMA cycle": 6569 58 [Bauer 3.6.3; VICE
    # cycle_tab_pal]; 6567R8 59 [VICE cycle_tab_ntsc; real 6567R8s: VICE-testprogs
    # VICII/spritesteal (spritesteal_ntsc, BA low for sprite 0 in cycles 56-60) and the
    # VICII/spritegap dumps (sprite 0 halts at X $16B, pixel 3 of cycle 59); Bauer's 6567R8
    # diagram puts it one cycle later, in 60]; 6567R56A 59 [Bauer's 6567R56A diagram; VICE
    # cycle_tab_ntsc_old; spritesteal_ntscold's table, no real-machine result recorded].
    sprite0_fetch_cycle: int
    # The cycle whose pixel SPRITE_PENDING_PIXEL copies the display flags to the sprite sequencer,
    # and the cycle that draws the X coordinates of the cycle before it again (0: none). [VICE
    # viciisc/vicii-chip-model.c cycle tables; checked against the real-hardware dumps of
    # VICE-testprogs VICII/spritegap.]
    display_check_cycle: int
    repeated_x_cycle: int = 0

    @property
    def frame_cycles(self) -> int:
        return self.lines * self.cycles_per_line

    @property
    def line_slots(self) -> int:
        """Pixel positions the sprite sequencer steps through in one raster line (8 per cycle)."""
        return self.cycles_per_line * PIXELS_PER_CYCLE


PIXELS_PER_CYCLE = 8
# A collision latch bit is set as if the pixel were drawn 4 X coordinates later than Bauer's X
# counter says (the X coordinate at the beginning of each clock phase [Bauer 3.6.3]). Measured:
# the VICE test programs VICII/spritecollisions/sprite-sprite-collision-cycle and
# sprite-gfx-collision-cycle (readme: "CC@@@@@" / "CCBBBBB" on C64 and C64C) read $D01E/$D01F in
# PAL cycle 25 of the line that shows a one-pixel overlap: X 86 and 87 are seen, X 88-92 are not.
# Cycle 25 covers X 92-99 by Bauer's counter, so without a delay X 84-91 would all be seen; with
# this delay a read in cycle c sees X up to 8(c-1) + first_x - 5, i.e. 87 (docs/vic.md, timing).
# The NTSC versions of those programs are unverified; the same delay is assumed for the 6567R8
# and the 6567R56A.
COLLISION_LATCH_DELAY = 4
PAL = Video("pal", "6569", lines=312, cycles_per_line=63, x_positions=0x1F8, first_x=0x194,
            first_visible_line=16, visible_lines=284, first_visible_x=0x1E0, visible_pixels=403,
            sprite0_fetch_cycle=58, display_check_cycle=58)
# 65 cycles draw 520 pixels but only 512 X coordinates exist. For collision times the model gives
# the 65th cycle no X coordinate (see docs/vic.md, timing model); the sprite sequencer draws X
# $180-$187 twice, in cycles 62 and 63 (VICE cycle_tab_ntsc; the spritegap dumps of a 6567R8 show
# sprite 0 at X $187 and sprite 1 at $188 not meeting).
NTSC = Video("ntsc", "6567R8", lines=263, cycles_per_line=65, x_positions=0x200, first_x=0x19C,
             first_visible_line=41, visible_lines=235, first_visible_x=0x1E9, visible_pixels=418,
             sprite0_fetch_cycle=59, display_check_cycle=59, repeated_x_cycle=63)
# The 6567R56A, the first NTSC chip [Bauer 3.4 tables, 3.6.3 6567R56A diagram]: 262 lines, 64
# cycles a line, so its 512 X coordinates ($19C at cycle 1, 8 a cycle) fill the line exactly and no
# X is drawn twice; vertical blank in lines 13-40 as on the 6567R8; sprites 3-7 fetch in cycles 1-10
# as on the 6569. Its sequencer around the fetches (display check, gap) is taken to be the 6567R8's,
# which is the same up to cycle 61 in Bauer's X row and in VICE's cycle_tab_ntsc_old: no
# real-hardware dump of an R56A was found (docs/vic.md).
NTSC_OLD = Video("ntsc-old", "6567R56A", lines=262, cycles_per_line=64, x_positions=0x200, first_x=0x19C,
                 first_visible_line=41, visible_lines=234, first_visible_x=0x1E8, visible_pixels=411,
                 sprite0_fetch_cycle=59, display_check_cycle=59)
VIDEOS = {"pal": PAL, "ntsc": NTSC, "ntsc-old": NTSC_OLD}

# ---- the sprite gap: each sprite's pixel sequencer around its own fetches -------------------------
# [VICE viciisc/vicii-draw-cycle.c draw_sprites8, checked against the real-hardware results of the
# VICE test programs VICII/spritegap/spritegap2 and spritegap3 (dumps from 6569R1, 6569R3, 8565R2
# and 6567R8 machines): tests/vic/test_sprite_gap.py replays them.]
# The sequencer steps through 8 positions per cycle; cycle 1's first position draws X
# first_x - COLLISION_LATCH_DELAY (the sprite X compare runs 4 X behind Bauer's counter: VICE draws
# the X of each cycle's first phase rounded down to 8, the same 4 the collision latch measurements
# give). Pixel SPRITE_HALT_PIXEL of the cycle of sprite n's p-access (sprite0_fetch_cycle + 2n,
# counted on into the next line) halts that sprite's shift register: it repeats the pixel it showed
# last; pixel SPRITE_DROP_PIXEL of the next cycle drops the rest of the row, pixel SPRITE_LOAD_PIXEL
# loads the row just fetched (anywhere inside the halt gives the same pixels), and from pixel
# SPRITE_RESUME_PIXEL on the sprite may start again. A sprite whose X falls while it is halted
# never starts. The sequencer starts a sprite at its X only while its copy of the display flag is
# set; that copy is taken at pixel SPRITE_PENDING_PIXEL of display_check_cycle, so the last row of a
# sprite whose X comes after that point in the line (and before its own load) is never shown, and
# one whose X comes after its own load shows each row in the line it is fetched.
SPRITE_HALT_PIXEL = 3
SPRITE_DROP_PIXEL = 2
SPRITE_LOAD_PIXEL = 4
SPRITE_RESUME_PIXEL = 7
SPRITE_PENDING_PIXEL = 4
# A $D01D or $D01C write within a row [VICE-src viciisc/vicii-draw-cycle.c draw_sprites8,
# draw_sprites, update_sprite_mc_bits_6569; Bauer 3.8.1 does not cover it]: the sequencer takes the
# X-expansion bits at pixel EXPAND_X_SWITCH_PIXEL and (6569, 6567: the chips with colour latency)
# the multicolour bits at pixel MULTICOLOR_SWITCH_PIXEL of the write's cycle. The row goes on from
# where its shift register stands: expansion decides only whether the register shifts every pixel
# or every other one from there (a flip-flop, not a re-placement), and a multicolour change clears
# the sprite's pair flip-flop, so the next pair starts one shift later wherever the register stands.
EXPAND_X_SWITCH_PIXEL = 6
MULTICOLOR_SWITCH_PIXEL = 7

# Raster compare [Bauer 3.12]: the IRQ for line 0 comes one cycle later than for the other lines.
RASTER_IRQ_LINE0_DELAY = 1

# ---- bus arbitration: BA and AEC [Bauer 3.5, 3.6.3, 3.8.1] --------------------------------------
# BA goes low BA_LEAD cycles before the first cycle the VIC takes (sprite n: BA low from cycle
# sprite0_fetch_cycle + 2n - BA_LEAD through sprite0_fetch_cycle + 2n + 1); the CPU goes on through
# write cycles and stops at its first read cycle while BA is low, until BA is high again.
BA_LEAD = 3
# A Bad Line's c-accesses take cycles 15-54 (all three chips), so BA is low from cycle 12 to 54.
BAD_LINE_FIRST_STOLEN = 15
BAD_LINE_LAST_STOLEN = 54
# Sprite DMA is switched on in the two cycles from sprite0_fetch_cycle - BA_LEAD (6569: 55 and 56)
# when $D015's bit is set and Y matches the line [Bauer 3.8.1; VICE-src cycle tables, check_spr_dma]
SPRITE_DMA_CHECK_CYCLES = 2
SPRITE_DMA_CYCLES = 2  # two s-accesses fall in the CPU's half of the cycles taken per sprite and line
# Bad Line condition [Bauer 3.5]: a line in GRAPHICS_FIRST_LINE ($30) .. BAD_LINE_LAST ($F7) whose
# low 3 bits equal YSCROLL, while DEN was set in some cycle of line $30 (the device samples it there:
# device.VicDevice._latch; dma.ba_low takes the DEN it is given).


# ---- what the VIC-II fetches from the C64's memory [Bauer 2.4.2, 3.6; PRG p.102 "Memory management";
# Mapping the Commodore 64, $D018 and $DD00] --------------------------------------------------------
BANK_SIZE = 0x4000  # the VIC-II sees 16K at a time (14 address bits)
BANK_COUNT = 4
CIA2_BASE = 0xDD00  # CIA 2: port A bits 0-1 are VIC address bits 14-15, inverted
CIA2_LAST = 0xDDFF  # its 16 registers repeat through $DD00-$DDFF
CIA2_REGISTERS = 16
CIA2_PORT_A = 0x00  # $DD00
CIA2_DDR_A = 0x02  # $DD02: 1 = output
CIA2_BANK_BITS = 0x03
CIA2_KERNAL_PORT_A = 0x97  # $DD00 after the KERNAL's IOINIT: bank 0 [Mapping the Commodore 64, $FDA3]
CIA2_KERNAL_DDR_A = 0x3F
MEMORY_SCREEN_SHIFT = 4  # $D018 bits 4-7: video matrix at 1K * value within the bank
MEMORY_SCREEN_MASK = 0xF0
MEMORY_CHARSET_MASK = 0x0E  # $D018 bits 1-3: character generator at 2K * (value >> 1)
MEMORY_BITMAP_BIT = 0x08  # $D018 bit 3: bitmap at 8K * bit
SCREEN_STEP = 0x0400
CHARSET_STEP = 0x0800  # $D018 bits 1-3 times 2K: (d018 & $0E) << 10
BITMAP_STEP = 0x2000
SPRITE_POINTERS = 0x03F8  # the 8 sprite pointers follow the video matrix (screen + $3F8) [Bauer 3.8]
COLOR_RAM = 0xD800  # colour RAM: 1000 nybbles, fixed, outside the bank [Bauer 2.4.2]
IDLE_ADDRESS = 0x3FFF  # the idle-state g-access (bank + $3FFF; $39FF with ECM) [Bauer 3.7.3.9]
IDLE_ADDRESS_ECM = 0x39FF
CHAR_ROM_BANKS = (0, 2)  # banks whose $1000-$1FFF the VIC-II reads from the character ROM [Bauer 2.4.2]
CHAR_ROM_OFFSET = 0x1000
CHAR_ROM_BYTES = 0x1000
