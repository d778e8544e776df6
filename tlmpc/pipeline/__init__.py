"""The compiler's stage list and its driver (``stages``): what ``tlmpc compile`` walks."""
