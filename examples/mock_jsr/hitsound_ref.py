"""The reference of hitsound.toml: what the routine must answer, and the calls it must make."""

HIT_SOUND = 2


def hit(ax, bx, play_sfx):
    """`play_sfx`: the routine's calls of the mocked player in this case, each {"A": value}."""
    touching = abs(ax - bx) < 8
    wrong_sound = any(call["A"] != HIT_SOUND for call in play_sfx)
    # a call with another sound is a wrong answer: the hit is then expected to read as no hit
    return {"hit": int(touching and not wrong_sound), "sounds": int(touching)}
