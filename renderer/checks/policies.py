"""Tolerance policies: when a rendered frame counts as its golden image.

    exact       every RGBA byte equal
    threshold   (the default) dEQP's compare, as in `renderer compare`: a pixel fails when no
                pixel within ±deviation of it in the other image matches within `threshold`
                of 255 on every channel, checked both ways; at most `max_failing_pixels` fail
    flip        mean ꟻLIP error (renderer/checks/perceptual.py) at most `max_mean`

Why threshold is the default: it forgives exactly what legitimately differs between two
conformant GL implementations or driver versions (rounding in the last bit, an edge that
moved by one pixel) and nothing else, and it names every pixel that failed. `exact` breaks
on any change of implementation; `flip` averages over the image, so a wrong 16x16 block in
a 256x256 frame passes a bound that an image-wide 1/255 rounding change fails
(docs/goldens.md has the figures).

A policy is named by a string ("threshold"), by a dict as a golden's JSON sidecar stores it
({"name": "threshold", "threshold": 4, ...}) or by an instance (Threshold(threshold=4)).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import ClassVar

import numpy as np

from renderer.checks.compare import DEFAULT_DEVIATION, DEFAULT_THRESHOLD, position_deviation_mismatch, raw_mismatch
from renderer.errors import UserError

DEFAULT_POLICY = "threshold"


class PolicyError(UserError):
    """An unknown policy name or a parameter out of range."""


@dataclass(frozen=True)
class Verdict:
    passed: bool
    summary: str                  # one line: what was measured against what was allowed
    failing_pixels: int | None    # pixels failing under the policy (None for flip)
    mean_flip: float | None       # mean ꟻLIP error, if the policy measured it


class Policy:
    """Base of the three policies: a name, parameters, and evaluate(expected, actual)."""
    name: ClassVar[str]

    def marking(self) -> tuple[int, int]:
        """(threshold, deviation) with which the diff image marks failing pixels."""
        return DEFAULT_THRESHOLD, DEFAULT_DEVIATION

    def evaluate(self, expected: np.ndarray, actual: np.ndarray) -> Verdict:
        raise NotImplementedError

    def as_dict(self) -> dict:
        return {"name": self.name, **asdict(self)}

    def describe(self) -> str:
        params = ", ".join(f"{f.name}={getattr(self, f.name)}" for f in fields(self))
        return f"{self.name}({params})"

    def _check_int(self, key: str, low: int, high: int | None = None) -> None:
        value = getattr(self, key)
        if isinstance(value, bool) or not isinstance(value, int) or value < low or \
                (high is not None and value > high):
            bound = f"{low} to {high}" if high is not None else f"{low} or more"
            raise PolicyError(f"must be a whole number {bound}, got {value!r}", key=f"{self.name}.{key}")


@dataclass(frozen=True)
class Exact(Policy):
    name: ClassVar[str] = "exact"

    def marking(self):
        return 0, 0

    def evaluate(self, expected, actual):
        failing = int(raw_mismatch(actual, expected, threshold=0).sum())
        return Verdict(failing == 0, f"{failing} pixels differ (none may)", failing, None)


@dataclass(frozen=True)
class Threshold(Policy):
    name: ClassVar[str] = "threshold"
    threshold: int = DEFAULT_THRESHOLD        # of 255, per channel
    deviation: int = DEFAULT_DEVIATION        # pixels
    max_failing_pixels: int = 0

    def __post_init__(self):
        self._check_int("threshold", 0, 255)
        self._check_int("deviation", 0, 16)
        self._check_int("max_failing_pixels", 0)

    def marking(self):
        return self.threshold, self.deviation

    def evaluate(self, expected, actual):
        failing = int(position_deviation_mismatch(actual, expected, self.threshold, self.deviation).sum())
        return Verdict(failing <= self.max_failing_pixels,
                       f"{failing} pixels fail within ±{self.deviation} px at {self.threshold}/255 "
                       f"(at most {self.max_failing_pixels} may)", failing, None)


@dataclass(frozen=True)
class Flip(Policy):
    name: ClassVar[str] = "flip"
    max_mean: float = 0.01

    def __post_init__(self):
        value = self.max_mean
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
            raise PolicyError(f"must be a number from 0 to 1, got {value!r}", key="flip.max_mean")

    def evaluate(self, expected, actual):
        from renderer.checks.perceptual import flip_error
        mean, _ = flip_error(expected, actual)
        return Verdict(mean <= self.max_mean, f"mean ꟻLIP {mean:.5f} (at most {self.max_mean:g} may)",
                       None, mean)


POLICIES: dict[str, type[Policy]] = {cls.name: cls for cls in (Exact, Threshold, Flip)}


def policy_from(spec) -> Policy:
    """The policy a test or a sidecar names: None (the default), a name, a dict or a Policy."""
    if spec is None:
        spec = DEFAULT_POLICY
    if isinstance(spec, Policy):
        return spec
    if isinstance(spec, dict):
        params = dict(spec)
        name = params.pop("name", None)
    else:
        name, params = spec, {}
    cls = POLICIES.get(name) if isinstance(name, str) else None
    if cls is None:
        raise PolicyError(f"unknown policy {name!r}; known policies: {', '.join(POLICIES)}", key="policy")
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(params) - known)
    if unknown:
        raise PolicyError(f"unknown parameter {unknown[0]!r}; {name} takes "
                          f"{', '.join(sorted(known)) or 'no parameters'}", key=f"{name}")
    return cls(**params)
