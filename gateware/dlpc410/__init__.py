"""The DLPC410 side: datasheet facts, DMD geometries, the data-beat map and the sequencer."""
