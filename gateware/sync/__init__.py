"""Tiled projectors: the sync master that starts every board's frame together."""
