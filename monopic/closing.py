"""The `with` protocol for objects that hold a resource until close().

A world, a renderer, a GL context, a results file and a recording each finish or free
something in close(). `Closing` closes whatever happens inside the `with`;
`WholeOrNothing` is for outputs that must appear whole or not at all (a recording): it
closes (keeps) on success and aborts (drops) on an error.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from types import TracebackType
from typing import Self


class Closing(ABC):
    """Mixin: __enter__ returns the object, __exit__ calls close()."""

    @abstractmethod
    def close(self) -> object:
        """Free or finish the resource (what it returns is the caller's, if anything)."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


class WholeOrNothing(Closing):
    """Mixin: __exit__ closes after a clean exit and aborts after an error."""

    @abstractmethod
    def abort(self) -> None:
        """Drop the partial output."""

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()
