"""Optional dependencies: imported where a command needs them, named by their extra when absent.

``pip install tlmpc`` brings what ``check``, ``compile`` and ``verify`` need.  Robot-data
formats (ROS bags, MCAP) and PNG figures need heavier packages, declared as the extras of
:data:`EXTRAS`; a command that needs one imports it through :func:`require`, which turns a
missing package into a diagnostic that names the extra to install instead of a traceback.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from tlmpc.base.errors import UsageError, error

#: Each extra and the import packages it provides (as ``pyproject.toml`` declares them).
EXTRAS: dict[str, tuple[str, ...]] = {
    "ros": ("rosbags", "mcap"),
    "png": ("matplotlib",),
    "fleet": ("distributed", "pyarrow"),  # fleet verification names it itself (F001, F006)
}


def require(module: str, purpose: str, file: str | None = None) -> ModuleType:
    """Import ``module`` (``"rosbags.highlevel"``) for ``purpose`` (``"reading a ROS bag"``).

    Raises :class:`UsageError` (U060, exit 2, at ``file`` when the command was reading one)
    naming the extra that provides it when the package is not installed.
    """
    package = module.partition(".")[0]
    extra = next((name for name, packages in EXTRAS.items() if package in packages), None)
    if extra is None:
        raise ValueError(f"{package} is not an optional dependency of tlmpc")
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is None or exc.name.partition(".")[0] != package:
            raise  # the package is there but broken: an internal error, not a missing extra
        raise UsageError(
            error(
                "U060",
                f"{purpose} needs the optional package {package!r}, which is not installed",
                hint=f"install tlmpc with the {extra!r} extra: pip install 'tlmpc[{extra}]'",
                file=file,
            )
        ) from None
