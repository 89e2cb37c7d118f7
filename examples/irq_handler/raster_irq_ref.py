"""The reference of raster_irq.toml."""

COLOURS = (0, 11, 12, 15, 1, 15, 12, 11)


def irq(frame):
    following = (frame + 1) & 0xFF
    return {"next_frame": following, "acks": [1], "ack_writes": 1, "colour": [COLOURS[following & 7]]}
