"""Whole-finger campaigns for ``rjcad identify``: data, catalogue, fitting, bench, result (issue #18, part 2)."""
