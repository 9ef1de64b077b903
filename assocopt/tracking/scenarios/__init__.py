"""Seeded scenario simulators, one per paper experiment (measurements + ground truth).

:mod:`.xue1999` (four crossing targets) comes with its Kalman tracker in
:mod:`.xue1999_tracker`.
"""

from .lu2013 import Lu2013, Truth

__all__ = ["Lu2013", "Truth"]
