"""Robot data in: occupancy-grid maps and nav2 masks (maps), logs and ROS bags (logs).

Nothing here imports the planning stages; image and bag libraries are imported only by the
functions that read those formats, so ``tlmpc check`` on a plain mission never loads them.
"""
