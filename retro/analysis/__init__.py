"""Analyses built on the machine: the routine cross-check and cost report, the speed/accuracy study."""
