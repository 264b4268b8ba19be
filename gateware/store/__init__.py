"""The bit-plane store: frame slots in DDR2 through the Spartan-6 MCB, and the plane reader."""
