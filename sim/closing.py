"""The `with` protocol for the simulator's objects that hold a resource until close().

A world, a renderer, a GL context and a results file each free something (GL objects,
a file lock) in close(); `with X(...) as x:` closes it whatever happens inside.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from types import TracebackType
from typing import Self


class Closing(ABC):
    """Mixin: __enter__ returns the object, __exit__ calls close()."""

    @abstractmethod
    def close(self) -> None:
        """Free the resource; further use is an error, a second close does nothing."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
