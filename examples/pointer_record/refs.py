"""The reference of in_span: the record's bytes as plain values, wherever the pointer puts them."""


def in_span(span, coordinate, left, width):
    return coordinate < left or coordinate - left >= width
