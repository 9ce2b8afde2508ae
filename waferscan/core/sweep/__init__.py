"""Sweeps (SPEC §12): layouts drawn from a tolerance file, scanned in blocks over arrays, and the
partitions' results reduced to one summary."""
