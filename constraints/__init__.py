"""Pin and clock constraints of the boards the projector builds for (see README.md here)."""
