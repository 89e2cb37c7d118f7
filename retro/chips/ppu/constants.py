"""The NES PPU's numbers, each named once (2C02 NTSC, 2C07 PAL).

Sources:
- nesdev wiki "PPU frame timing" and "PPU rendering": 341 dots a line, 262 lines (NTSC) or 312
  (PAL); vblank flag set at dot 1 of line 241; flags cleared at dot 1 of the pre-render line; with
  rendering on, odd NTSC frames jump from dot 339 of the pre-render line to dot 0 of line 0.
- nesdev wiki "Cycle reference chart": 3 PPU dots per CPU cycle on NTSC, 3.2 on PAL.
- nesdev wiki "PPU registers": register addresses and bit meanings, the 8-byte mirrors.
- nesdev wiki "PPU scrolling": the internal v/t/x/w registers and how $2000/$2005/$2006 load them.
- nesdev wiki "PPU OAM": sprite Y is one less than the first line drawn; attribute bits.
- nesdev wiki "Mirroring" and "PPU memory map": nametables at $2000/$2400/$2800/$2C00, palette at $3F00.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

# ---- frame geometry -----------------------------------------------------------------------------
DOTS_PER_LINE = 341
SCREEN_WIDTH = 256
SCREEN_HEIGHT = 240             # visible lines 0-239
VBLANK_LINE = 241
VBLANK_DOT = 1                  # the vblank flag is set at dot 1 of line 241
FLAG_CLEAR_DOT = 1              # vblank, sprite-0 hit and overflow are cleared at dot 1 of the pre-render line
# With rendering on, odd NTSC frames jump from dot 339 of the pre-render line to (0, 0): one dot shorter.
# Whether rendering is on is decided with $2001 as written up to dot 338 of that line (a write the CPU
# makes at dot 339 is too late): blargg's ppu_vbl_nmi 10-even_odd_timing, tests 2-5, in the convention
# that a CPU access in cycle c sees the PPU at dot 3c (retro.chips.ppu.clock).
ODD_FRAME_DECISION_DOT = 338
# The CPU samples its NMI input one dot after the dot its reads see (a read in CPU cycle c sees the PPU
# at dot 3c, the NMI input is sampled at 3c + 1): fitted to blargg's ppu_vbl_nmi 05 (NMI timing), 07
# (NMI enabled near the vblank clear), 08 and vbl_nmi_timing 6 (NMI disabled near the vblank set).
NMI_SAMPLE_DOT_OFFSET = 1
# A $2002 read this many dots before the vblank dot reads the flag clear and keeps it from being set
# for the frame (no NMI either): nesdev wiki "PPU frame timing", blargg's vbl_nmi_timing 2 and 5.
VBLANK_SUPPRESSING_READ = 1
HIT_DOT_OFFSET = 1              # the hit flag for pixel x is set at dot x + 1 of its line
NO_HIT_X = SCREEN_WIDTH - 1     # x = 255 never hits (the pixel pipeline, per "PPU OAM")
LEFT_COLUMN_WIDTH = 8           # x = 0-7: hidden when either left-column bit of $2001 is clear


@dataclass(frozen=True)
class VideoStandard:
    name: str
    lines_per_frame: int
    dots_per_cpu_cycle: Fraction
    skips_odd_frame_dot: bool

    @property
    def pre_render_line(self) -> int:
        return self.lines_per_frame - 1

    @property
    def dots_per_frame(self) -> int:
        """Dots in a full frame (the odd-frame skip not applied)."""
        return self.lines_per_frame * DOTS_PER_LINE


NTSC = VideoStandard("ntsc", lines_per_frame=262, dots_per_cpu_cycle=Fraction(3), skips_odd_frame_dot=True)
PAL = VideoStandard("pal", lines_per_frame=312, dots_per_cpu_cycle=Fraction(16, 5), skips_odd_frame_dot=False)
VIDEO_STANDARDS = {standard.name: standard for standard in (NTSC, PAL)}

# ---- CPU-visible registers ------------------------------------------------------------------------
PPU_REGISTER_BASE = 0x2000
PPU_REGISTER_END = 0x3FFF       # $2008-$3FFF mirror $2000-$2007 every 8 bytes
PPU_REGISTER_MASK = 0x0007
PPUCTRL = 0x2000
PPUMASK = 0x2001
PPUSTATUS = 0x2002
OAMADDR = 0x2003
OAMDATA = 0x2004
PPUSCROLL = 0x2005
PPUADDR = 0x2006
PPUDATA = 0x2007
OAMDMA = 0x4014

# $2000 PPUCTRL
CTRL_NAMETABLE = 0x03           # base nametable (bit 0: +256 in X, bit 1: +240 in Y)
CTRL_INCREMENT_32 = 0x04        # $2007 address step 32 instead of 1
CTRL_SPRITE_TABLE = 0x08        # 8x8 sprite pattern table at $1000
CTRL_BACKGROUND_TABLE = 0x10    # background pattern table at $1000
CTRL_SPRITE_8X16 = 0x20
CTRL_NMI = 0x80

# $2001 PPUMASK
MASK_GREYSCALE = 0x01
MASK_BACKGROUND_LEFT = 0x02     # show background in x = 0-7
MASK_SPRITES_LEFT = 0x04        # show sprites in x = 0-7
MASK_BACKGROUND = 0x08
MASK_SPRITES = 0x10
MASK_RENDERING = MASK_BACKGROUND | MASK_SPRITES
MASK_LEFT_COLUMN = MASK_BACKGROUND_LEFT | MASK_SPRITES_LEFT

# $2002 PPUSTATUS
STATUS_VBLANK = 0x80
STATUS_SPRITE0_HIT = 0x40
STATUS_OVERFLOW = 0x20
STATUS_OPEN_BUS = 0x1F          # the low bits read back the PPU's I/O latch

# OAM attribute byte
ATTR_PALETTE = 0x03
ATTR_BEHIND_BACKGROUND = 0x20   # priority: irrelevant to the hit
ATTR_FLIP_H = 0x40
ATTR_FLIP_V = 0x80

# ---- memories -------------------------------------------------------------------------------------
OAM_SIZE = 256
OAM_ENTRY_SIZE = 4              # Y, tile, attributes, X
SPRITE_Y_OFFSET = 1             # a sprite at OAM Y is drawn from line Y + 1
SPRITE_WIDTH = 8
SPRITE_HEIGHT_8X8 = 8
SPRITE_HEIGHT_8X16 = 16
SPRITES_PER_LINE = 8            # sprite evaluation copies at most 8 sprites per line, then looks for overflow
SPRITE_EVALUATION_DOT = 65      # evaluation reads sprite 0's Y on this dot of each visible line
TILE_SIZE = 8
TILE_BYTES = 16                 # plane 0 rows, then plane 1 rows
PLANE_OFFSET = 8
TILES_PER_TABLE = 256
PATTERN_TABLE_SIZE = TILES_PER_TABLE * TILE_BYTES       # $1000
CHR_SIZE = 2 * PATTERN_TABLE_SIZE                       # 8 KiB
NAMETABLE_COLUMNS = 32
NAMETABLE_ROWS = 30             # rows 30 and 31 of the 32x32 array are the attribute table
NAMETABLE_ROW_SLOTS = 32
NAMETABLE_SIZE = 0x400
NAMETABLE_COUNT = 4             # logical nametables at $2000, $2400, $2800, $2C00
CIRAM_SIZE = 0x800              # 2 KiB of nametable RAM in the console
NAMETABLE_BASE = 0x2000
NAMETABLE_SPACE_END = 0x3EFF    # $3000-$3EFF mirror $2000-$2EFF
NAMETABLE_SPACE_MASK = 0x0FFF
PALETTE_BASE = 0x3F00
PALETTE_SIZE = 0x20
VRAM_ADDRESS_MASK = 0x3FFF

# ---- internal scroll registers (nesdev "PPU scrolling") -------------------------------------------
V_COARSE_X = 0x001F
V_COARSE_Y = 0x03E0
V_NAMETABLE = 0x0C00
V_FINE_Y = 0x7000
V_COARSE_Y_SHIFT = 5
V_NAMETABLE_SHIFT = 10
V_FINE_Y_SHIFT = 12
V_BITS = 0x7FFF                 # v and t are 15 bits
PPUADDR_HIGH_BITS = 0x3F        # the first $2006 write supplies address bits 8-13 (bit 14 cleared)
PALETTE_SHADOW_OFFSET = 0x1000  # a palette read through $2007 buffers the nametable byte $1000 below
TALL_SPRITE_TILE_MASK = 0xFE    # 8x16: the top tile is the index with bit 0 cleared
FINE_SCROLL = 0x07
COARSE_SHIFT = 3

# Logical nametable (0-3) -> physical 1 KiB page of CIRAM, per mirroring ("Mirroring" page).
MIRRORING = {
    "horizontal": (0, 0, 1, 1),     # $2000=$2400, $2800=$2C00 (vertical arrangement, for vertical scrolling)
    "vertical": (0, 1, 0, 1),       # $2000=$2800, $2400=$2C00
    "single": (0, 0, 0, 0),         # one-screen, lower bank
}

# ---- OAM DMA (nesdev "PPU registers", OAMDMA) -----------------------------------------------------
OAM_DMA_CYCLES = 513            # 1 wait cycle + 256 read/write pairs
OAM_DMA_ODD_EXTRA = 1           # +1 when the $4014 write lands on an odd CPU cycle
