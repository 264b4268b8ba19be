"""Behavioural and reference models, plain Python and numpy, shared by unit and system tests."""
