"""Strict readers for parsed TOML tables: typed values or one clear InputError.

A :class:`Table` wraps one parsed table together with the file it came from
and its dotted key, so every error names the file, the key and what was
expected.  Unknown keys are errors, never silently dropped.  :func:`load_toml`
is the one way a TOML input file is read: at most
:data:`~lenscompare.limits.MAX_FILE_BYTES`, UTF-8, nested at most
:data:`~lenscompare.limits.MAX_TOML_DEPTH` deep.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Iterable
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from .errors import InputError
from .limits import MAX_FILE_BYTES, MAX_TOML_DEPTH, read_input_bytes

__all__ = ["Table", "load_toml", "read_toml_text", "parse_toml"]


def load_toml(path: str | os.PathLike, *, what: str) -> dict:
    """Read and parse a TOML input file (``what``: "scene file", "check config"...).

    Raises
    ------
    InputError
        Missing, a folder or device, larger than MAX_FILE_BYTES, not UTF-8,
        not TOML, or nested deeper than MAX_TOML_DEPTH.
    """
    source = os.fspath(path)
    return parse_toml(read_toml_text(source, what=what), source=source)


def read_toml_text(path: str | os.PathLike, *, what: str) -> str:
    """The text of a TOML input file (capped and UTF-8 checked, see :func:`load_toml`)."""
    source = os.fspath(path)
    data = read_input_bytes(source, what=what, max_bytes=MAX_FILE_BYTES)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError(source, f"not a text file: byte {error.start} is not UTF-8 (expected a TOML {what})") from None


def parse_toml(text: str, *, source: str) -> dict:
    """Parse TOML text; every failure is an InputError naming ``source``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise InputError(source, f"not valid TOML ({error})") from None
    except RecursionError:
        raise InputError(source, f"arrays or tables nested too deeply (at most {MAX_TOML_DEPTH} levels)") from None
    except ValueError as error:  # e.g. Python's limit on the digits of an integer
        raise InputError(source, f"not valid TOML ({error})") from None
    depth = _depth(data)
    if depth > MAX_TOML_DEPTH:
        raise InputError(source, f"arrays or tables nested more than {MAX_TOML_DEPTH} levels deep")
    return data


def _depth(data: Any) -> int:
    """Nesting depth of parsed TOML (a table of numbers is 2), without recursion;
    stops counting past MAX_TOML_DEPTH."""
    deepest, stack = 0, [(data, 1)]
    while stack:
        value, depth = stack.pop()
        if not isinstance(value, (dict, list)):
            continue
        deepest = max(deepest, depth)
        if depth > MAX_TOML_DEPTH:
            break
        stack.extend((child, depth + 1) for child in (value.values() if isinstance(value, dict) else value))
    return deepest

_MISSING = object()


def _describe(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


class Table:
    """One TOML table being read, with the file and key it came from."""

    def __init__(self, data: Any, *, source: str, key: str = "", max_abs: float | None = None):
        if not isinstance(data, dict):
            raise InputError(source, f"expected a table, got {_describe(data)}", key=key or None)
        self.data = data
        self.source = source
        self.key = key
        self.max_abs = max_abs  # the default bound on every number read, inherited by sub-tables

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
        return Table(value, source=self.source, key=self.path(name), max_abs=self.max_abs)

    def tables(self, name: str) -> list[Table]:
        """An array of tables (``[[objects]]``); empty when absent."""
        value = self._get(name, [])
        if not isinstance(value, list):
            raise self.error(name, f"expected an array of tables, got {_describe(value)}")
        return [Table(item, source=self.source, key=f"{self.path(name)}[{i}]", max_abs=self.max_abs)
                for i, item in enumerate(value)]

    def string(self, name: str, *, default: Any = _MISSING, choices: Iterable[str] | None = None,
               max_chars: int | None = None) -> Any:
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, str):
            raise self.error(name, f"expected a string, got {_describe(value)}")
        if max_chars is not None and len(value) > max_chars:
            raise self.error(name, f"expected at most {max_chars} characters, got {len(value)}")
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
               non_negative: bool = False, minimum: float | None = None, maximum: float | None = None,
               max_abs: float | None = None) -> Any:
        """A finite real number (TOML integer or float), optionally bounded
        (``minimum <= value <= maximum``, ``|value| <= max_abs``)."""
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        return self._check_number(name, value, positive=positive, non_negative=non_negative, minimum=minimum,
                                  maximum=maximum, max_abs=max_abs)

    def _check_number(self, name: str, value: Any, *, positive: bool = False, non_negative: bool = False,
                      minimum: float | None = None, maximum: float | None = None,
                      max_abs: float | None = None) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(name, f"expected a number, got {_describe(value)}")
        try:
            value = float(value)
        except OverflowError:  # a TOML integer has any number of digits
            raise self.error(name, f"expected a finite number, got an integer of about "
                             f"{int(value.bit_length() * math.log10(2)) + 1} digits") from None
        if not math.isfinite(value):
            raise self.error(name, f"expected a finite number, got {value}")
        if positive and not value > 0:
            raise self.error(name, f"expected a positive number, got {value:g}")
        if non_negative and value < 0:
            raise self.error(name, f"expected a number >= 0, got {value:g}")
        if minimum is not None and value < minimum:
            raise self.error(name, f"expected a number >= {minimum:g}, got {value:g}")
        if maximum is not None and value > maximum:
            raise self.error(name, f"expected a number <= {maximum:g}, got {value:g}")
        max_abs = self.max_abs if max_abs is None else max_abs
        if max_abs is not None and abs(value) > max_abs:
            raise self.error(name, f"expected a number between {-max_abs:g} and {max_abs:g}, got {value:g}")
        return value

    def integer(self, name: str, *, default: Any = _MISSING, minimum: int | None = None,
                maximum: int | None = None) -> Any:
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        return self._check_integer(name, value, minimum=minimum, maximum=maximum)

    def _check_integer(self, name: str, value: Any, *, minimum: int | None = None, maximum: int | None = None,
                       what: str = "an integer") -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(name, f"expected {what}, got {_describe(value)}")
        if minimum is not None and value < minimum:
            raise self.error(name, f"expected an integer >= {minimum}, got {_describe(value)}")
        if maximum is not None and value > maximum:
            raise self.error(name, f"expected an integer <= {maximum:,}, got {_describe(value)}")
        return value

    def vector(self, name: str, length: int, *, default: Any = _MISSING, positive: bool = False,
               non_negative: bool = False, integer: bool = False, minimum: float | None = None,
               maximum: float | None = None, max_abs: float | None = None) -> Any:
        """A fixed-length array of finite numbers, returned as a tuple; the
        bounds apply to every component."""
        value = self._get(name, default)
        if value is default and default is not _MISSING:
            return value
        if not isinstance(value, list) or len(value) != length:
            raise self.error(name, f"expected an array of {length} numbers, got {_describe(value)}")
        if integer:
            what = f"{length} positive integers" if positive else f"{length} integers"
            return tuple(self._check_integer(name, item, minimum=1 if positive else minimum, maximum=maximum,
                                             what=what) for item in value)
        return tuple(self._check_number(name, item, positive=positive, non_negative=non_negative, minimum=minimum,
                                        maximum=maximum, max_abs=max_abs) for item in value)
