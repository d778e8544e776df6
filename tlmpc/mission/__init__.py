"""Mission files: the format, loading with positions, validation."""

from tlmpc.mission.io import mission_from_json
from tlmpc.mission.load import (
    check_file,
    check_text,
    inspect_file,
    load_mission,
    load_mission_text,
)
from tlmpc.mission.model import Component, Mission, Options, Region, Robot, Workspace

__all__ = [
    "Component",
    "Mission",
    "Options",
    "Region",
    "Robot",
    "Workspace",
    "check_file",
    "check_text",
    "inspect_file",
    "load_mission",
    "load_mission_text",
    "mission_from_json",
]
