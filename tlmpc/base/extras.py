"""Optional dependencies: imported where a command needs them, named by their extra when absent.

``pip install tlmpc`` brings what ``check``, ``compile`` and ``verify`` need.  Robot-data
formats (ROS bags, MCAP) and PNG figures need heavier packages, declared as the extras of
:data:`EXTRAS`; a command that needs one imports it through :func:`require`, which turns a
missing package into a diagnostic that names the extra to install instead of a traceback.
The same holds for the core packages of :data:`LIGHT_INSTALL_LACKS`, which the light install
the README gives for a pre-commit hook (``pip install --no-deps`` and a few packages) may lack.
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

#: Core dependencies (import name: the name to pip-install) that only some commands use, so
#: that an install without them still runs the others: Pillow reads map images.
LIGHT_INSTALL_LACKS: dict[str, str] = {"PIL": "pillow"}


def require(module: str, purpose: str, file: str | None = None) -> ModuleType:
    """Import ``module`` (``"rosbags.highlevel"``) for ``purpose`` (``"reading a ROS bag"``).

    Raises :class:`UsageError` (U060, exit 2, at ``file`` when the command was reading one)
    naming the extra that provides it when the package is not installed.
    """
    package = module.partition(".")[0]
    extra = next((name for name, packages in EXTRAS.items() if package in packages), None)
    if extra is None and package not in LIGHT_INSTALL_LACKS:
        raise ValueError(f"{package} is not an optional dependency of tlmpc")
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is None or exc.name.partition(".")[0] != package:
            raise  # the package is there but broken: an internal error, not a missing extra
        if extra is None:
            kind = "package"
            hint = (
                "it is one of tlmpc's own dependencies, missing from this install: pip install "
                f"{LIGHT_INSTALL_LACKS[package]}"
            )
        else:
            kind = "optional package"
            hint = f"install tlmpc with the {extra!r} extra: pip install 'tlmpc[{extra}]'"
        raise UsageError(
            error(
                "U060",
                f"{purpose} needs the {kind} {package!r}, which is not installed",
                hint=hint,
                file=file,
            )
        ) from None
