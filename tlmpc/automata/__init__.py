"""automata stage."""
