"""Reactive missions: sensors, actions and assumptions, solved as a GR(1) game on the
abstraction (docs/semantics.md, "Reactive missions")."""
