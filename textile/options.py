"""Option records: dataclasses built from user dicts, checked field by field."""
from __future__ import annotations

import dataclasses
import math


class Options:
    """Mixin for option dataclasses: ``from_dict`` refuses unknown names."""

    #: what the options are of, for error messages ("solver", "contact", ...)
    kind = "option"

    @classmethod
    def from_dict(cls, d: dict | None):
        d = dict(d or {})
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ValueError(f"unknown {cls.kind} option(s) {unknown}; valid: {sorted(names)}")
        return cls(**d)

    def require_positive(self, *names: str) -> None:
        """ValueError naming the field unless each is a positive finite number."""
        for name in names:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                    or v <= 0:
                raise ValueError(f"{type(self).__name__}.{name} must be a positive number, "
                                 f"got {v!r}")
