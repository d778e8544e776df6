"""Mission templates for ``tlmpc new``: small, valid missions to start from."""
