"""Seeded scenario simulators, one per paper experiment (measurements + ground truth)."""

from .lu2013 import Lu2013, Truth

__all__ = ["Lu2013", "Truth"]
