"""Task phrases: plain-English tasks compiled to LTL."""

from tlmpc.tasks.compiler import KNOWN_PHRASES, avoid_scopes, compile_phrase, compile_phrases

__all__ = ["KNOWN_PHRASES", "avoid_scopes", "compile_phrase", "compile_phrases"]
