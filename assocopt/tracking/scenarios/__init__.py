"""Seeded scenario simulators, one per paper experiment (measurements + ground truth).

:mod:`.xue1999` (four crossing targets) comes with its Kalman tracker in
:mod:`.xue1999_tracker`; :mod:`.dong2015` (two biased radars with local trackers) with
the methods compared on it in :mod:`.dong2015_assoc`.
"""

from .lu2013 import Lu2013, Truth

__all__ = ["Lu2013", "Truth"]
