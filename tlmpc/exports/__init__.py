"""Plans out: a compiled plan exported for navigation stacks (waypoints, nav_msgs/Path, GeoJSON).

Each exporter reads the compiler's output directory (``trace.json`` and ``mission.json``)
through :func:`tlmpc.exports.plan.read_plan` and writes one file.
"""
