"""ltl stage."""
