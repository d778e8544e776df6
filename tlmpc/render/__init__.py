"""Figures: one scene model (``scene``) drawn as SVG (``svg``) or, through matplotlib, PNG."""
