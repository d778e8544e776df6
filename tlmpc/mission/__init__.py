"""mission stage."""
