"""Behavioural and reference models (``*_model``), plain Python and numpy, and the stimulus shared
by unit and system tests."""
