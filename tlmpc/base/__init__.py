"""The bottom layer every stage stands on: diagnostics, the version, progress lines.

Nothing here imports another part of tlmpc.
"""
