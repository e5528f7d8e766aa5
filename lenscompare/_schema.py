"""Strict readers for parsed TOML tables: typed values or one clear InputError.

A :class:`Table` wraps one parsed table together with the file it came from
and its dotted key, so every error names the file, the key and what was
expected.  Unknown keys are errors, never silently dropped.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from .errors import InputError

__all__ = ["Table"]

_MISSING = object()


def _describe(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


class Table:
    """One TOML table being read, with the file and key it came from."""

    def __init__(self, data: Any, *, source: str, key: str = ""):
        if not isinstance(data, dict):
            raise InputError(source, f"expected a table, got {_describe(data)}", key=key or None)
        self.data = data
        self.source = source
        self.key = key

    def path(self, name: str) -> str:
        return f"{self.key}.{name}" if self.key else name

    def error(self, name: str, problem: str) -> InputError:
        return InputError(self.source, problem, key=self.path(name))

    def check_keys(self, allowed: Iterable[str]) -> None:
        """Reject any key not in ``allowed``."""
        allowed = list(allowed)
        for name in self.data:
            if name not in allowed:
                raise self.error(name, f"unknown key (expected one of: {', '.join(allowed)})")

    def has(self, name: str) -> bool:
        return name in self.data

    def _get(self, name: str, default: Any) -> Any:
        if name in self.data:
            return self.data[name]
        if default is _MISSING:
            raise self.error(name, "missing (required)")
        return default

    def table(self, name: str, *, required: bool = False) -> Table:
        value = self._get(name, _MISSING if required else {})
        return Table(value, source=self.source, key=self.path(name))

    def tables(self, name: str) -> list[Table]:
        """An array of tables (``[[objects]]``); empty when absent."""
        value = self._get(name, [])
        if not isinstance(value, list):
            raise self.error(name, f"expected an array of tables, got {_describe(value)}")
        return [Table(item, source=self.source, key=f"{self.path(name)}[{i}]") for i, item in enumerate(value)]

    def string(self, name: str, *, default: Any = _MISSING, choices: Iterable[str] | None = None) -> Any:
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, str):
            raise self.error(name, f"expected a string, got {_describe(value)}")
        if choices is not None:
            choices = list(choices)
            if value not in choices:
                raise self.error(name, f"expected one of {', '.join(map(repr, choices))}, got {value!r}")
        return value

    def boolean(self, name: str, *, default: Any = _MISSING) -> Any:
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, bool):
            raise self.error(name, f"expected true or false, got {_describe(value)}")
        return value

    def number(self, name: str, *, default: Any = _MISSING, positive: bool = False,
               non_negative: bool = False) -> Any:
        """A finite real number (TOML integer or float)."""
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        return self._check_number(name, value, positive=positive, non_negative=non_negative)

    def _check_number(self, name: str, value: Any, *, positive: bool = False, non_negative: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(name, f"expected a number, got {_describe(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise self.error(name, f"expected a finite number, got {value}")
        if positive and not value > 0:
            raise self.error(name, f"expected a positive number, got {value:g}")
        if non_negative and value < 0:
            raise self.error(name, f"expected a number >= 0, got {value:g}")
        return value

    def integer(self, name: str, *, default: Any = _MISSING, minimum: int | None = None) -> Any:
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(name, f"expected an integer, got {_describe(value)}")
        if minimum is not None and value < minimum:
            raise self.error(name, f"expected an integer >= {minimum}, got {value}")
        return value

    def vector(self, name: str, length: int, *, default: Any = _MISSING, positive: bool = False,
               non_negative: bool = False, integer: bool = False) -> Any:
        """A fixed-length array of finite numbers, returned as a tuple."""
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, list) or len(value) != length:
            raise self.error(name, f"expected an array of {length} numbers, got {_describe(value)}")
        if integer:
            for item in value:
                if isinstance(item, bool) or not isinstance(item, int) or (positive and item <= 0):
                    raise self.error(name, f"expected {length} positive integers, got {_describe(value)}")
            return tuple(value)
        return tuple(self._check_number(name, item, positive=positive, non_negative=non_negative) for item in value)
