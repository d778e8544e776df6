"""Start-up cost of the command line: keep library imports to what a command uses.

scipy's array-API layer (``scipy._lib.array_api_compat.numpy``, imported by every scipy
subpackage) copies numpy's namespace by walking ``dir(numpy)``; numpy creates its lazy
submodules on that walk, so ``numpy.f2py`` (a Fortran wrapper generator), ``numpy.testing``
(which pulls in ``unittest``, ``importlib.metadata`` and ``email``) and ``numpy.ctypeslib``
are imported by a compile that never uses them: about 60 ms of a cold start.  While the
command runs, numpy's listing leaves those three out; the modules stay importable by name.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator

#: numpy submodules that no array namespace needs (none is part of the array API).
UNUSED_SUBMODULES = frozenset({"f2py", "testing", "ctypeslib"})


@contextlib.contextmanager
def lean_numpy_listing() -> Iterator[None]:
    """Leave :data:`UNUSED_SUBMODULES` out of ``dir(numpy)`` and ``numpy.__all__`` inside.

    Nothing changes when scipy's array layer is already loaded (its copy is made) or numpy
    has no such listing; both are restored on exit.
    """
    if "scipy._lib.array_api_compat.numpy" in sys.modules:
        yield
        return
    import numpy

    listing = numpy.__dict__.get("__dir__")
    public = numpy.__dict__.get("__all__")
    if not callable(listing) or not isinstance(public, list):
        yield
        return

    def lean_dir() -> list[str]:
        return [name for name in listing() if name not in UNUSED_SUBMODULES]

    numpy.__dir__ = lean_dir  # type: ignore[method-assign]
    numpy.__all__ = [name for name in public if name not in UNUSED_SUBMODULES]
    try:
        yield
    finally:
        numpy.__dir__ = listing  # type: ignore[method-assign]
        numpy.__all__ = public
