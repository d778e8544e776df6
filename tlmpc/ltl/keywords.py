"""Words that cannot name a region: they are operators or constants of the LTL language.

Kept apart from the parser so that checking names does not import the parser (and lark).
"""

KEYWORDS = frozenset({"F", "G", "X", "N", "U", "R", "W", "M", "V", "true", "false"})
