"""Tops: the simulated core and the Spartan-6 platform tops that wrap it."""
