"""Named palettes: C64 (VIC-II colour numbers 0-15) and NES (PPU colour numbers $00-$3F).

Each palette is a list of (r, g, b) tuples indexed by the chip's colour number. Sources are named
next to each entry.
"""

from __future__ import annotations

from retro.errors import InputError

RGB = tuple[int, int, int]

PALETTES: dict[str, list[RGB]] = {}


def _hex_colours(text: str) -> list[RGB]:
    """'RRGGBB RRGGBB ...' -> [(r, g, b), ...]"""
    return [(int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)) for c in text.split()]


def palette(name: str) -> list[RGB]:
    try:
        return PALETTES[name]
    except KeyError:
        raise InputError(f"unknown palette {name!r} (known: {', '.join(sorted(PALETTES))})") from None


# NES: the 2C02 palette as listed on the nesdev wiki page "PPU palettes" (section "2C02"), colour
# numbers $00-$3F. Real colours depend on the TV's decoding of the composite signal; this is one
# commonly used rendering of them.
_NES_2C02_ROWS = [
    "545454 001E74 081090 300088 440064 5C0030 540400 3C1800 202A00 083A00 004000 003C00 00323C 000000 000000 000000",
    "989698 084CC4 3032EC 5C1EE4 8814B0 A01464 982220 783C00 545A00 287200 087C00 007628 006678 000000 000000 000000",
    "ECEEEC 4C9AEC 787CEC B062EC E454EC EC58B4 EC6A64 D48820 A0AA00 74C400 4CD020 38CC6C 38B4CC 3C3C3C 000000 000000",
    "ECEEEC A8CCEC BCBCEC D4B2EC ECAEEC ECAED4 ECB4B0 E4C490 CCD278 B4DE78 A8E290 98E2B4 A0D6E4 A0A2A0 000000 000000",
]
PALETTES["nes"] = _hex_colours(" ".join(_NES_2C02_ROWS))


# C64 (VIC-II colour numbers 0-15), two measured palettes:
# - "c64-pepto": Philip "Pepto" Timmermann, "Calculating the color palette of the VIC II" (2001,
#   pepto.de/projects/colorvic), the values VICE ships as pepto-pal (checked against public copies).
# - "c64-colodore": Pepto's revised model "colodore" (2017, www.colodore.com, default settings).
_C64_PEPTO = "000000 FFFFFF 68372B 70A4B2 6F3D86 588D43 352879 B8C76F 6F4F25 433900 9A6759 444444 6C6C6C 9AD284 6C5EB5 959595"
_C64_COLODORE = "000000 FFFFFF 813338 75CEC8 8E3C97 56AC4D 2E2C9B EDF171 8E5029 553800 C46C71 4A4A4A 7B7B7B A9FF9F 706DEB B2B2B2"
PALETTES["c64-pepto"] = _hex_colours(_C64_PEPTO)
PALETTES["c64-colodore"] = _hex_colours(_C64_COLODORE)
C64_DEFAULT_PALETTE = "c64-pepto"
