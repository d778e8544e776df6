"""Artifacts at the edges: JSON encoding, schemas, the atomic output folder, the CLI report."""
