"""Task phrases: plain-English tasks compiled to LTL."""

from tlmpc.tasks.compiler import KNOWN_PHRASES, compile_phrase, compile_phrases

__all__ = ["KNOWN_PHRASES", "compile_phrase", "compile_phrases"]
