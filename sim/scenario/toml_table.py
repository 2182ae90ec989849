"""Strict, typed reads from the tables of a TOML file: the one reader of every spec format.

Scenario files (sim.scenario.files), sweep specs (sim.runs.sweep) and dataset specs
(sim.dataset.build) are hand-written, so each value is checked where it is read: a getter of
TomlTable checks the type and the range and knows the dotted field it reads; done()
rejects the keys nobody asked for (typos). A mistake is one FieldError line,
`FILE: FIELD = VALUE: REASON`, so a sweep or a dataset never dies hours in on a typo.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from monopic.errors import UserError

MISSING: Any = object()  # as a default: the key is required; as a value: it is absent


class FieldError(UserError):
    """One bad value in a TOML file: which file, which dotted field, what value, why."""

    def __init__(self, file: Path | str, field: str, value: object, reason: str) -> None:
        self.file, self.field, self.value, self.reason = str(file), field, value, reason
        shown = f" = {show(value)}" if value is not MISSING else ""
        super().__init__(f"{file}: {field}{shown}: {reason}")


def show(value: object) -> str:
    """A value as the file would spell it (tables inline)."""
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {show(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(show(v) for v in value) + "]"
    return repr(value)


def type_name(value: object) -> str:
    """How a TOML value's type reads in an error ("must be a number, not a string")."""
    names = {bool: "a boolean", int: "an integer", float: "a number", str: "a string"}
    if type(value) in names:
        return names[type(value)]
    return "a table" if isinstance(value, dict) else "a list"


def read_toml(path: Path, what: str) -> tuple[str, dict[str, Any]]:
    """The text and the data of a TOML file; a UserError naming the file (a `what`) if not."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise UserError(f"{path}: is a folder, not a {what}") from None
    except (OSError, UnicodeDecodeError) as err:
        raise UserError(f"{path}: cannot read: {err}") from None
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise UserError(f"{path}: not valid TOML: {err}") from None


def _unit(unit: str) -> str:
    return f" {unit}" if unit else ""


class TomlTable:
    """One TOML table being read: typed getters naming the dotted field; leftovers are unknown.

    Every getter takes a default (MISSING: the key is required; None: optional, the getter
    then returns None when the key is absent). `doc` names the file documenting the keys,
    for the unknown-key error.
    """

    def __init__(self, file: Path, prefix: str, data: Mapping[str, Any], doc: str = "") -> None:
        self.file, self.prefix, self.data, self.doc = file, prefix, dict(data), doc
        self.seen: set[str] = set()

    def field(self, key: str) -> str:
        """The dotted name of `key` in the file (e.g. robot.camera.width)."""
        return f"{self.prefix}.{key}" if self.prefix else key

    def error(self, key: str, value: object, reason: str) -> FieldError:
        return FieldError(self.file, self.field(key), value, reason)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default: Any = MISSING, expected: str = "") -> Any:
        """The value unchecked (or the default); marks the key as known."""
        self.seen.add(key)
        if key not in self.data:
            if default is MISSING:
                typo = self._misspelt(key)
                if typo is not None:  # name the real mistake, not only its consequence
                    raise self.error(
                        typo,
                        self.data[typo],
                        f"unknown key, and {self.field(key)} is missing: did you mean {key!r}?",
                    )
                need = f"required: {expected}" if expected else "required"
                raise FieldError(self.file, self.field(key), MISSING, f"missing ({need})")
            return default
        return self.data[key]

    def _misspelt(self, key: str) -> str | None:
        """A key of the table nobody asked for that looks like `key` (e.g. file for files)."""
        unseen = [k for k in self.data if k not in self.seen]
        close = difflib.get_close_matches(key, unseen, n=1, cutoff=0.6)
        return close[0] if close else None

    def number(
        self,
        key: str,
        default: Any = MISSING,
        *,
        low: float | None = None,
        high: float | None = None,
        positive: bool = False,
        unit: str = "",
    ) -> float:
        """A finite float (integers accepted) in [low, high]; `positive` excludes zero."""
        value = self.raw(key, default, "a number")
        if value is None:
            return value
        return self._number(self.field(key), value, low, high, positive, unit)

    def _number(
        self,
        field: str,
        value: object,
        low: float | None,
        high: float | None,
        positive: bool,
        unit: str,
    ) -> float:
        def bad(reason: str) -> FieldError:
            return FieldError(self.file, field, value, reason)

        if isinstance(value, bool) or not isinstance(value, int | float):
            raise bad(f"must be a number{_unit(unit)}, not {type_name(value)}")
        number = float(value)
        if not math.isfinite(number):
            raise bad("must be a finite number")
        if positive and not number > 0:
            raise bad(f"must be > 0{_unit(unit)}")
        if low is not None and number < low:
            raise bad(f"must be >= {low:g}{_unit(unit)}")
        if high is not None and number > high:
            raise bad(f"must be <= {high:g}{_unit(unit)}")
        return number

    def numbers(
        self,
        key: str,
        default: Any = MISSING,
        *,
        low: float | None = None,
        high: float | None = None,
        nonempty: bool = False,
        distinct: bool = False,
        unit: str = "",
    ) -> tuple[float, ...]:
        """A list of numbers, each checked as number() does (the error names its index)."""
        kind = "a non-empty list of numbers" if nonempty else "a list of numbers"
        value = self.raw(key, default, kind)
        if value is None:
            return value
        if not isinstance(value, list | tuple):
            raise self.error(key, value, f"must be {kind}, not {type_name(value)}")
        if nonempty and not value:
            raise self.error(key, value, f"must be {kind}")
        field = self.field(key)
        out = tuple(
            self._number(f"{field}[{k}]", v, low, high, False, unit) for k, v in enumerate(value)
        )
        if distinct and len(set(out)) != len(out):
            raise self.error(key, value, "lists a value twice")
        return out

    def integer(
        self, key: str, default: Any = MISSING, *, low: int = 0, high: int | None = None
    ) -> int:
        value = self.raw(key, default, "an integer")
        if value is None:
            return value
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, value, f"must be an integer, not {type_name(value)}")
        if value < low or (high is not None and value > high):
            span = f"in [{low}, {high}]" if high is not None else f">= {low}"
            raise self.error(key, value, f"must be an integer {span}")
        return value

    def text(
        self,
        key: str,
        default: Any = MISSING,
        choices: tuple[str, ...] = (),
        *,
        nonempty: bool = False,
    ) -> str:
        value = self.raw(key, default, "a string")
        if value is None:
            return value
        if not isinstance(value, str):
            raise self.error(key, value, f"must be a string, not {type_name(value)}")
        if choices and value not in choices:
            raise self.error(key, value, f"must be one of {', '.join(choices)}")
        if nonempty and not value.strip():
            raise self.error(key, value, "must not be empty")
        return value

    def slug(self, key: str, default: Any = MISSING) -> str:
        """A name that also names files and folders: non-empty, no spaces or slashes."""
        value = self.text(key, default)
        if not value or any(c.isspace() or c in "/\\" for c in value):
            raise self.error(key, value, "must be a non-empty name without spaces or slashes")
        return value

    def flag(self, key: str, default: Any = MISSING) -> bool:
        value = self.raw(key, default, "true or false")
        if not isinstance(value, bool):
            raise self.error(key, value, f"must be true or false, not {type_name(value)}")
        return value

    def table(self, key: str) -> TomlTable:
        """A sub-table (empty when absent), read with the same file and doc."""
        value = self.raw(key, {})
        if not isinstance(value, dict):
            raise self.error(key, value, f"must be a table, not {type_name(value)}")
        return TomlTable(self.file, self.field(key), value, self.doc)

    def tables(self, key: str) -> list[TomlTable]:
        """An array of tables ([[key]]), each named key[k] in errors."""
        value = self.raw(key, [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.error(key, value, "must be a list of tables ([[...]] or [{...}, ...])")
        field = self.field(key)
        return [TomlTable(self.file, f"{field}[{k}]", v, self.doc) for k, v in enumerate(value)]

    def free_keys(self) -> list[str]:
        """Every key of a table whose keys are the user's own (e.g. sweep parameters)."""
        self.seen.update(self.data)
        return list(self.data)

    def done(self) -> None:
        """Reject keys nobody asked for (typos, keys of another kind of table)."""
        for key in self.data:
            if key not in self.seen:
                known = ", ".join(sorted(self.seen)) or "none"
                see = f"; see {self.doc}" if self.doc else ""
                close = difflib.get_close_matches(key, sorted(self.seen), n=1, cutoff=0.6)
                hint = f"did you mean {close[0]!r}? " if close else ""
                raise self.error(
                    key, self.data[key], f"unknown key ({hint}known here: {known}{see})"
                )
