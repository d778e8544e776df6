"""abstraction stage."""
