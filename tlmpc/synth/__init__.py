"""GR(1) reactive synthesis: the spec IR, the symbolic solver, strategies, cores.

``tlmpc synth SPEC`` exposes it on gr1c, slugs and TLSF files (docs/synthesis.md).
"""
