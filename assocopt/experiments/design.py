"""What an experiment is: a grid of settings x methods x trials, and its seeds.

See :mod:`assocopt.experiments` for the model of a trial and the determinism rule.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..runtime.errors import AssocoptError

__all__ = ["Experiment", "PerMethod", "trial_seed", "setting_key", "StoreMismatchError",
           "TrialError", "SCHEMA_VERSION"]

SCHEMA_VERSION = 2


class StoreMismatchError(AssocoptError, ValueError):
    """The results store belongs to another experiment, seed or parameter set."""


class TrialError(AssocoptError, RuntimeError):
    """A trial function raised; the message names the setting and trial."""


# --------------------------------------------------------------------------- seeds
def setting_key(setting: Mapping[str, Any]) -> str:
    """Canonical JSON of a setting (sorted keys): its identity in the store.

    >>> setting_key({"b": 1, "a": 0.5})
    '{"a":0.5,"b":1}'
    """
    try:
        return json.dumps(setting, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise AssocoptError(f"setting {setting!r} is not JSON-serialisable: {exc}") from exc


def trial_seed(master: int, setting: Mapping[str, Any] | str, trial: int) -> np.random.SeedSequence:
    """The seed of one trial: independent of workers, scheduling and grid order.

    ``SeedSequence(master, spawn_key=(h0, h1, h2, h3, trial))`` where ``h`` are four
    32-bit words of the SHA-256 of the setting's canonical JSON.

    >>> s1 = trial_seed(7, {"d": 0.5}, 3).generate_state(2).tolist()
    >>> s1 == trial_seed(7, '{"d":0.5}', 3).generate_state(2).tolist()
    True
    """
    key = setting if isinstance(setting, str) else setting_key(setting)
    digest = hashlib.sha256(key.encode("utf-8")).digest()
    words = tuple(int.from_bytes(digest[4 * i:4 * i + 4], "little") for i in range(4))
    return np.random.SeedSequence(int(master), spawn_key=words + (int(trial),))


# ---------------------------------------------------------------------- experiment
@dataclass(frozen=True)
class Experiment:
    """A settings x methods x trials grid and the function that runs one trial.

    Attributes
    ----------
    name : str
        Identifies the experiment in the store (one store, one experiment).
    settings : list of dict
        JSON-ready settings; each must be distinct.
    methods : list of str
    trial : callable
        ``trial(setting, methods, seed) -> {method: {metric: value}}``, picklable.
    runs : int
        Monte Carlo trials per setting.
    seed : int
        Master seed.
    params : dict
        Parameters recorded in the store; a store written with other params is refused.
    volatile : tuple of str
        Metrics that are not deterministic (timings); excluded from :func:`summarise`
        unless asked for, and never compared between runs.
    """

    name: str
    settings: Sequence[Mapping[str, Any]]
    methods: Sequence[str]
    trial: Callable[..., Mapping[str, Mapping[str, float]]]
    runs: int
    seed: int = 0
    params: Mapping[str, Any] = field(default_factory=dict)
    volatile: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.runs, int) or self.runs < 1:
            raise AssocoptError(f"runs must be a positive integer, got {self.runs!r}")
        keys = [setting_key(s) for s in self.settings]
        if len(set(keys)) != len(keys):
            raise AssocoptError("settings must be distinct")
        if not self.methods or len(set(self.methods)) != len(self.methods):
            raise AssocoptError(f"methods must be a non-empty list of distinct names, "
                                f"got {list(self.methods)}")


class PerMethod:
    """Adapt ``f(setting, method, seed) -> metrics`` to the batched trial signature.

    Each method still receives the same seed (paired comparison).
    """

    def __init__(self, fn: Callable[[Mapping, str, np.random.SeedSequence], Mapping[str, float]]):
        self.fn = fn

    def __call__(self, setting, methods, seed):
        return {m: self.fn(setting, m, seed) for m in methods}
