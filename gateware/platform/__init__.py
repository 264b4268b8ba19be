"""The platform layer: vendor primitives and instances, kept out of the simulated core."""
